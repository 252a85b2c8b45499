"""What the views from the way in cost the grasp decision, with and without their crop to the
arm's reach (`collision.within_reach`, applied in `ViewMemory.recall`).

The scooter on `isolation` (seed 1) drives 1 m back and in again (tests/driving.py), so
that the session keeps its views of the way in; then, for every object marked at its
visible top, it times the recall and `find_grasps` (detect and filter) with those views,
best of `--repeats`, once as the code does it and once with every recalled point kept.
Nothing is executed.

    MUJOCO_GL=egl .venv/bin/python bench/recall_cost.py [--repeats 3]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import laserpick.pipeline.recall as recall
from laserpick.description import dims
from laserpick.pipeline.cloud import fuse
from laserpick.pipeline.grasp_choice import GraspSet, find_grasps
from laserpick.pipeline.perceive import perceive
from laserpick.robot.sim.robot import SimRobot
from laserpick.robot.sim.scenes import load_scene
from laserpick.robot.sim.truth import capture
from laserpick.server.session import Actor, Session

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from driving import drive_back_and_in


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    truth = capture("isolation", seed=1)
    truth_cloud = fuse(truth.frames)
    session = Session(SimRobot(load_scene("isolation", seed=1), realtime=False))
    cropped = recall.within_reach
    try:
        session.robot.sim.settle(0.3)
        drive_back_and_in(session, Actor("bench"))
        frames = session.robot.capture()
        q = session.robot.joint_state().q
        totals = {}
        for label, reach in (("cropped", cropped), ("all kept", lambda p: np.ones(len(p), bool))):
            recall.within_reach = reach
            print(f"{label}: {len(session.recalled().points)} recalled points")
            totals[label] = 0.0
            for p in truth.scene.placements:
                aim = truth.visible_top(truth_cloud, p.instance)
                perception = perceive(frames, point=aim) if aim is not None else None
                if perception is None or not perception.ok:
                    continue
                best: tuple[float, dict[str, float]] | None = None
                for r in range(args.repeats):
                    t0 = time.perf_counter()
                    found = find_grasps(
                        perception,
                        dims.UR5_READY_Q,
                        q_capture=q,
                        rng=np.random.default_rng(r),
                        recalled=session.recalled(),
                    )
                    took = time.perf_counter() - t0
                    if isinstance(found, GraspSet) and (best is None or took < best[0]):
                        best = (took, found.timings)
                if best is None:
                    print(f"  {p.instance:<18} no grasp set")
                    continue
                totals[label] += best[0]
                took, t = best
                print(
                    f"  {p.instance:<18} recall + decision {1000 * took:4.0f} ms"
                    f"  (detect {1000 * t['detect']:4.0f}, filter {1000 * t['filter']:4.0f})"
                )
        print(
            f"\nsum over the objects: {1000 * totals['cropped']:.0f} ms cropped,"
            f" {1000 * totals['all kept']:.0f} ms with every recalled point"
        )
    finally:
        recall.within_reach = cropped
        session.close()


if __name__ == "__main__":
    main()
