"""What the basket screen costs a pick: `holds_over_basket` on held shapes that fit and that
do not, with the verdict and the median seconds of each.

The shapes are boxes of points 1 cm apart in the TCP frame, hanging below a downward hand as
`tests/arm_setups.box_points` builds them: a mug held at its middle, the cereal box held at
its middle and by its end (17 cm off), and a 40 cm cube. The drop postures are worked out
once, before the timed runs (a server does so at its first pick for the basket).

    MUJOCO_GL=egl .venv/bin/python bench/basket_screen.py [--repeats 5]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from laserpick.behaviours import drop_candidates, holds_over_basket
from laserpick.settings import get_settings


def box(size: tuple[float, float, float], step: float = 0.01) -> np.ndarray:
    """Points (m, TCP frame) filling a box of `size` (m) whose top face's middle is the TCP,
    reaching down along +z (the approach)."""
    axes = [np.arange(-s / 2, s / 2 + 1e-9, step) for s in size[:2]]
    axes.append(np.arange(0.0, size[2] + 1e-9, step))
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


SHAPES = {
    "mug, 8 x 8 x 10 cm, at its middle": box((0.08, 0.08, 0.10)),
    "cereal box, 25 x 6 x 19 cm, at its middle": box((0.25, 0.06, 0.19)),
    "cereal box, held 17 cm off its middle": box((0.25, 0.06, 0.19)) + [0.17, 0.0, 0.0],
    "a 40 cm cube about the hand": box((0.4, 0.4, 0.4), 0.05) - [0.0, 0.0, 0.2],
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    s = get_settings()
    margin, b = s.motion.clearance, s.behaviour
    drop_candidates(heights=b.drop_heights)
    drop_candidates(tilted=True, heights=b.drop_heights)
    print(f"{'held shape':45s} {'points':>6s} {'fits':>5s} {'median s':>9s}")
    for name, payload in SHAPES.items():
        times, fits = [], None
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            fits = holds_over_basket(payload, margin=margin, settings=b)
            times.append(time.perf_counter() - t0)
        print(f"{name:45s} {len(payload):6d} {fits!s:>5s} {statistics.median(times):9.3f}")


if __name__ == "__main__":
    main()
