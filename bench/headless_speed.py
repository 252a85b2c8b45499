"""How much faster than real time the headless (benchmark) mode steps a scene.

MUJOCO_GL=egl .venv/bin/python bench/headless_speed.py [--scene isolation] [--seconds 20]
"""

from __future__ import annotations

import argparse
import time

from laserpick.robot.sim.loop import Simulation
from laserpick.robot.sim.scenes import load_scene


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="isolation", help="built-in name or YAML path")
    parser.add_argument("--seconds", type=float, default=20.0, help="sim time to step (s)")
    args = parser.parse_args()
    sim = Simulation(load_scene(args.scene), realtime=False)
    t0 = time.perf_counter()
    sim.settle(args.seconds)
    wall = time.perf_counter() - t0
    print(f"scene {args.scene}: {args.seconds:.1f} s of sim in {wall:.2f} s wall")
    print(f"headless speed-up  {args.seconds / wall:6.1f}x real time")


if __name__ == "__main__":
    main()
