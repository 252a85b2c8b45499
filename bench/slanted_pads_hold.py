"""How far a held box turns in the pads when they meet its sides at a slant about the approach.

For each object, the grasp of tests/test_grasp_physics.py (from above, across its narrow
side, on the 46 cm table) is turned about its approach by each `--slants` angle, closed,
lifted 10 cm, and held still for `--hold` s of simulated time, the hand pointing down as
it is carried. Prints how far the object moved and turned in the hand over that time (its
pose relative to the TCP: ground truth, read for scoring only) and the finger gap.

    MUJOCO_GL=egl .venv/bin/python bench/slanted_pads_hold.py [--hold 60] [--slants 0 3 6 9]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import test_grasp_physics as scripted  # the tests' scripted grasp

from laserpick.transforms import rotation_angle


def held_drift(name: str, slant_deg: float, hold: float) -> tuple[float, float, float, bool]:
    """(finger gap mm, moved mm, turned deg, still holding) of `name` held `hold` s with the
    pads `slant_deg` off its sides."""
    sim, body, q_grasp, q_lift = scripted._at_grasp(name, turn=math.radians(slant_deg))
    scripted._close_and_lift(sim, q_grasp, q_lift)
    d, tcp = sim.data, sim.info.tcp_site

    def in_hand() -> tuple[np.ndarray, np.ndarray]:
        R = d.site_xmat[tcp].reshape(3, 3)
        return R.T @ (d.xpos[body] - d.site_xpos[tcp]), R.T @ d.xmat[body].reshape(3, 3)

    p0, R0 = in_hand()
    gap = sim.snapshot().gripper_width
    sim.settle(hold)
    p1, R1 = in_hand()
    turned = math.degrees(rotation_angle(R0, R1))
    return gap * 1000, float(np.linalg.norm(p1 - p0)) * 1000, turned, sim.snapshot().holding


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--objects", nargs="+", default=["tv_remote", "tissue_packet", "tea_box"])
    parser.add_argument("--slants", nargs="+", type=float, default=[0.0, 3.0, 6.0, 9.0])
    parser.add_argument("--hold", type=float, default=60.0, help="s of simulated time held")
    args = parser.parse_args()
    print(f"held {args.hold:.0f} s, the hand pointing down")
    print(
        f"{'object':15} {'slant deg':>9} {'gap mm':>7} {'moved mm':>9} {'turned deg':>10}  holding"
    )
    for name in args.objects:
        for slant in args.slants:
            gap, moved, turned, holding = held_drift(name, slant, args.hold)
            print(f"{name:15} {slant:9.0f} {gap:7.1f} {moved:9.2f} {turned:10.2f}  {holding}")


if __name__ == "__main__":
    main()
