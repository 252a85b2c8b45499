"""The other papers' grasping strategies, each in its own scene.

- EL-E's overhead grasp (000 sections 4.4 and 5.1) on the `surfaces` scene: the user drives
  up to each of the twelve surfaces and marks its cordless phone and its pill; the robot
  picks each with the overhead strategy and drops it in the basket.
- Jeeves' centroid approach (003 sections IV and V) on the `jeeves` table: the soda can stands
  on one of the six marked locations and the scooter starts 40 cm farther back; the user
  marks the can, the base drives until its centroid is at the arm's grasping spot, and the
  robot grasps it vertically and drops it in the basket.

Prints each attempt and each strategy's success rate.

    MUJOCO_GL=egl .venv/bin/python bench/strategies.py [elee|jeeves|both] [--trials 2]
"""

from __future__ import annotations

import argparse

import numpy as np
import yaml

from laserpick.behaviours import Behaviours
from laserpick.bench.operator import Referee, drive_to, scene_config_backed
from laserpick.bench.picking import mark_target, pick_and_drop, stow
from laserpick.description import dims
from laserpick.pipeline.grasping import find_grasps
from laserpick.pipeline.types import Failure
from laserpick.robot.scenes import load_scene, parse_scene
from laserpick.robot.sim_robot import SimRobot


def elee(log=print) -> list[bool]:
    """Every phone and pill of the `surfaces` scene, picked with EL-E's overhead grasp."""
    scene = load_scene("surfaces")
    robot = SimRobot(scene, realtime=False)
    rng = np.random.default_rng(0)
    results = []
    try:
        robot.sim.settle(0.5)
        referee = Referee(robot)
        behaviours = Behaviours(robot, rng=rng, progress=lambda _m: None)
        start = robot.base_pose().copy()
        first = scene.surfaces[0]
        for surface in scene.surfaces:
            # The surfaces stand in a row along +y, each set out like the first one.
            goal = start + [0.0, surface.xy[1] - first.xy[1], 0.0]
            if np.linalg.norm(robot.base_pose()[:2] - goal[:2]) > 0.03:
                drive_to(robot, goal, reverse_first=0.6)
            for p in scene.placements:
                if p.surface != surface.name:
                    continue
                rec = pick_and_drop(
                    robot, behaviours, referee, p.instance, rng, strategy="overhead"
                )
                stow(robot, behaviours)
                results.append(rec.success)
                verdict = "ok" if rec.success else f"{rec.failure}: {rec.message}"
                log(f"  {surface.name} ({surface.height:.3f} m) {p.instance:<12} {verdict}")
    finally:
        robot.close()
    return results


def jeeves_scene(location: str, back: float) -> str:
    """The `jeeves` scene with the can on `location` and the scooter `back` m farther away."""
    config = scene_config_backed("jeeves", back)
    config["objects"][0]["at"] = location
    return yaml.safe_dump(config, sort_keys=False)


def jeeves(trials: int, back: float = 0.4, log=print) -> list[bool]:
    """The can on each of the six locations `trials` times: approach, vertical grasp, drop."""
    results = []
    for trial in range(trials):
        for k in range(1, 7):
            location = f"loc{k}"
            robot = SimRobot(parse_scene(jeeves_scene(location, back)), realtime=False)
            rng = np.random.default_rng(100 * trial + k)
            try:
                robot.sim.settle(0.5)
                referee = Referee(robot)
                behaviours = Behaviours(robot, rng=rng, progress=lambda _m: None)
                ok, why = _jeeves_once(robot, referee, behaviours, rng)
            finally:
                robot.close()
            results.append(ok)
            log(f"  trial {trial + 1} {location}: {'ok' if ok else why}")
    return results


def _jeeves_once(
    robot: SimRobot, referee: Referee, behaviours: Behaviours, rng: np.random.Generator
) -> tuple[bool, str]:
    marked = mark_target(robot, referee, "can", rng)
    if isinstance(marked, Failure):
        return False, f"mark: {marked.message}"
    perception = behaviours.approach(marked)
    if isinstance(perception, Failure):
        return False, f"approach: {perception.message}"
    if not perception.ok:
        return False, f"approach: {perception.failure}"
    found = find_grasps(
        perception, dims.UR5_READY_Q, q_capture=robot.joint_state().q, strategy="vertical"
    )
    if isinstance(found, Failure):
        return False, f"grasp: {found.message}"
    picked = behaviours.pick(found)
    if not picked.ok:
        return False, f"pick: {picked.failure}"
    dropped = behaviours.drop_in_basket()
    robot.sleep(1.0)
    if not referee.in_basket("can"):
        return False, f"drop: {dropped.failure or 'the can missed the basket'}"
    return True, ""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("which", nargs="?", choices=["elee", "jeeves", "both"], default="both")
    parser.add_argument("--trials", type=int, default=2, help="Jeeves: trials per location")
    args = parser.parse_args()
    if args.which in ("elee", "both"):
        print("EL-E overhead grasp, `surfaces` (000 section 5.1: 12 surfaces x phone + pill)")
        r = elee()
        print(f"EL-E overhead: {sum(r)}/{len(r)} picked ({np.mean(r):.0%})\n")
    if args.which in ("jeeves", "both"):
        print("Jeeves centroid approach, `jeeves` (003 section V: six locations)")
        r = jeeves(args.trials)
        print(f"Jeeves centroid approach: {sum(r)}/{len(r)} picked ({np.mean(r):.0%})")


if __name__ == "__main__":
    main()
