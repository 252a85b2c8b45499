"""Pick-and-place between the `kitchen` scene's surfaces (004 sections 7.3 and 8.3).

Each task starts fresh at the 73 cm table: the scripted user marks one of its objects, the
robot picks it; the user backs out, drives to another surface, marks a free spot on it, and
the robot places the object there. A task succeeds when the object rests upright (tilted
under 15 deg) within 3 cm of where it should be: the place point plus the object's offset
from the grasp, both in `base`.

    MUJOCO_GL=egl .venv/bin/python bench/kitchen_places.py [--tasks 10]
"""

from __future__ import annotations

import argparse
import math

import numpy as np
import yaml

from laserpick.behaviours import Behaviours
from laserpick.bench.operator import (
    Referee,
    aim_with_tremor,
    creep,
    drive_to,
    parking_pose,
    scene_config_backed,
)
from laserpick.bench.picking import mark_and_pick, stow
from laserpick.description import dims
from laserpick.description.kinematics import tcp_pose
from laserpick.pipeline.cloud import fuse
from laserpick.pipeline.collision import CollisionChecker
from laserpick.pipeline.laser import detect_mark
from laserpick.pipeline.types import Failure
from laserpick.robot.scenes import Surface, parse_scene
from laserpick.robot.sim_robot import SimRobot
from laserpick.transforms import invert, matrix_from_quat, planar_pose

START_BACK = 0.5  #: m the scooter starts behind its place at the 73 cm table
EMPTY = np.zeros((0, 3))
SOURCES = ("soda_can", "tea_box", "mug")  #: on the 73 cm table, in reach from the start
#: Destination surfaces (name, level index) and how far (m) the spot may lie from the
#: surface's middle across its width.
DESTINATIONS = (("table_31", 0), ("counter", 0), ("high_table", 0), ("floor_area", 0))
UPRIGHT_TILT = math.radians(15.0)
PLACE_TOLERANCE = 0.03  #: m


def free_spot(
    surface: Surface, referee: Referee, rng: np.random.Generator
) -> tuple[float, np.ndarray]:
    """A spot on `surface`, 25 cm behind its front edge and at least 15 cm from any object:
    (local y, world xyz)."""
    c, s = math.cos(surface.yaw), math.sin(surface.yaw)
    half_w = surface.size[1] / 2 - 0.15
    objects = [referee.world_position(n) for n in referee.instances()]
    for _ in range(100):
        ly = float(rng.uniform(-half_w, half_w)) if half_w > 0 else 0.0
        local = np.array([-surface.size[0] / 2 + 0.25, ly])
        xy = np.asarray(surface.xy) + [c * local[0] - s * local[1], s * local[0] + c * local[1]]
        if all(np.linalg.norm(o[:2] - xy) > 0.15 for o in objects):
            return ly, np.array([xy[0], xy[1], surface.levels[0]])
    raise RuntimeError(f"no free spot on {surface.name}")


def run_task(seed: int, sources: tuple[str, ...] = SOURCES) -> tuple[bool, str]:
    rng = np.random.default_rng(seed)
    # The user starts half a metre back from the 73 cm table, raises the arm and drives up:
    # a stowed arm cannot rise past a table edge that high and that near (see the README).
    scene = parse_scene(yaml.safe_dump(scene_config_backed("kitchen", START_BACK)))
    robot = SimRobot(scene, realtime=False)
    try:
        robot.sim.settle(0.5)
        referee = Referee(robot)
        behaviours = Behaviours(robot, rng=rng, progress=lambda _m: None)
        raised = behaviours.go_to(dims.UR5_HIGH_READY_Q, CollisionChecker(EMPTY), "raising")
        if not raised.ok:
            return False, f"could not raise the arm: {raised.failure}"
        creep(robot, START_BACK)
        name = str(rng.choice(sources))
        dest_name, _ = DESTINATIONS[int(rng.integers(len(DESTINATIONS)))]
        dest = scene.surface(dest_name)
        q0 = referee.world_quat(name)
        picked = mark_and_pick(robot, behaviours, referee, name, rng)
        if picked.failure is not None:
            return False, f"{name} -> {dest_name}: pick failed: {picked.message}"
        # Where the object sits relative to the TCP, in `base`, as it will when placed.
        tcp = tcp_pose(robot.joint_state().q)[:3, 3]
        offset = (referee.position(name) - tcp)[:2]
        # Raise what it holds before driving, as the user would.
        held = behaviours.held
        assert held is not None
        lifted = behaviours.go_to(
            dims.UR5_HIGH_READY_Q, held.surroundings, "raising", payload=held.points_tcp
        )
        if not lifted.ok:
            return False, f"{name} -> {dest_name}: could not raise the object: {lifted.failure}"
        local_y, spot_world = free_spot(dest, referee, rng)
        if not drive_to(robot, parking_pose(dest, local_y), reverse_first=0.6):
            return False, f"{name} -> {dest_name}: could not park"
        T_base_world = invert(planar_pose(*robot.base_pose()))
        spot = (T_base_world @ np.append(spot_world, 1.0))[:3]
        aim_with_tremor(robot, spot, rng)
        frames = robot.capture()
        robot.laser.off()
        mark = detect_mark(frames)
        if isinstance(mark, Failure):
            return False, f"{name} -> {dest_name}: place mark: {mark.message}"
        placed = behaviours.place(fuse(frames), mark.point)
        if not placed.ok:
            return False, f"{name} -> {dest_name}: place failed: {placed.failure}"
        stow(robot, behaviours)
        robot.sleep(1.0)
        assert placed.spot is not None
        expected = placed.spot[:2] + offset
        error = float(np.linalg.norm(referee.position(name)[:2] - expected))
        up0 = matrix_from_quat(q0).T @ np.array([0.0, 0.0, 1.0])  # the object's own "up"
        tilt = math.acos(np.clip((matrix_from_quat(referee.world_quat(name)) @ up0)[2], -1, 1))
        ok = error <= PLACE_TOLERANCE and tilt <= UPRIGHT_TILT
        return ok, (
            f"{name} -> {dest_name}: {error * 100:.1f} cm from the spot,"
            f" tilted {math.degrees(tilt):.0f} deg"
        )
    finally:
        robot.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tasks", type=int, default=10)
    parser.add_argument("--first-seed", type=int, default=1)
    parser.add_argument(
        "--sources", nargs="+", default=list(SOURCES), help="objects of the 73 cm table to move"
    )
    args = parser.parse_args()
    results = []
    for k in range(args.tasks):
        ok, what = run_task(args.first_seed + k, tuple(args.sources))
        results.append(ok)
        print(f"task {k + 1}/{args.tasks}: {'ok ' if ok else 'FAIL'} {what}", flush=True)
    print(
        f"\n{sum(results)}/{len(results)} place tasks succeeded ({np.mean(results):.0%});"
        " the issue asks for >= 90 %"
    )


if __name__ == "__main__":
    main()
