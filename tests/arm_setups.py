"""Shared setups for the behaviour tests: the isolation scene's robot, hand poses, and a
pick as a session makes it."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from laserpick.behaviours import Behaviours
from laserpick.bench.referee import Referee
from laserpick.description import dims
from laserpick.description.kinematics import ik_tcp
from laserpick.pipeline.collision import CollisionChecker
from laserpick.pipeline.grasp_choice import GraspSet, find_grasps
from laserpick.pipeline.lines import cartesian_line
from laserpick.pipeline.perceive import perceive
from laserpick.robot.sim.robot import SimRobot
from laserpick.robot.sim.scenes import load_scene
from laserpick.settings import get_settings

TABLE_TOP = 0.46  # the isolation scene's table (m)
TABLE_FRONT = 1.30  # its front edge's x (m, `world`)
RAIL_TOP = 0.60  # tests/data/rail.yaml
DATA = Path(__file__).parent / "data"
#: The settings, and their behaviours' group, as `Behaviours(robot)` reads them.
SETTINGS = get_settings()
BEHAVIOUR = SETTINGS.behaviour


@contextlib.contextmanager
def scene_robot(scene: str) -> Iterator[SimRobot]:
    """A robot in `scene` (a built-in scene's name or a scene file's path, seed 1), settled,
    run as fast as it goes; closed after."""
    r = SimRobot(load_scene(scene, seed=1), realtime=False)
    try:
        r.sim.settle(0.5)
        yield r
    finally:
        r.close()


def isolation_robot() -> Iterator[SimRobot]:
    """The isolation scene (seed 1), settled, run as fast as it goes; closed after. For a
    fixture: `yield from isolation_robot()`."""
    with scene_robot("isolation") as r:
        yield r


def top_down(x: float, y: float, z: float) -> np.ndarray:
    """A TCP pose at (x, y, z) in `base`, the gripper pointing down."""
    pose = np.eye(4)
    pose[:3, :3] = np.diag([1.0, -1.0, -1.0])
    pose[:3, 3] = [x, y, z]
    return pose


def side_pose(x: float, y: float, z: float) -> np.ndarray:
    """A TCP pose at (x, y, z) (m, `base`) with the hand level, approaching along +x and
    closing across y."""
    T = np.eye(4)
    T[:3, :3] = np.column_stack([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
    T[:3, 3] = x, y, z
    return T


def box_points(size: tuple[float, float, float], step: float = 0.01) -> np.ndarray:
    """Points (m) filling a box of `size` whose top face's middle is the origin, reaching
    down along +z: a box held at its top by a downward hand, in the TCP frame."""
    axes = [np.arange(-s / 2, s / 2 + 1e-9, step) for s in size[:2]]
    axes.append(np.arange(0.0, size[2] + 1e-9, step))
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


def pick_object(robot: SimRobot, name: str, from_above: bool = False) -> tuple[Behaviours, Referee]:
    """Perceive the object at its aim point, find its grasps and pick it, as a session does.
    from_above: try the grasps from above first (each group in score order), for scenes
    built around a hand above the object."""
    referee = Referee(robot)
    perception = perceive(robot.capture(), point=referee.aim_point(name))
    found = find_grasps(perception, dims.UR5_READY_Q, q_capture=robot.joint_state().q)
    assert isinstance(found, GraspSet), found
    b = Behaviours(robot)
    order = found.ordered()
    if from_above:
        order.sort(key=lambda g: g.approach[2] > -0.9)  # stable: score order within each
    out = b.pick(found, order)
    assert out.ok, out.failure
    return b, referee


def post_behind(q_side: np.ndarray, payload: np.ndarray | None = None) -> CollisionChecker:
    """A post behind the hand at `side_pose(1.70, -0.30, 0.80)` (joint angles q_side),
    clear of it where it stands but in the way of 5 cm back."""
    half = cartesian_line(q_side, side_pose(1.65, -0.30, 0.80))
    for x in np.arange(1.55, 1.2, -0.01):
        post = CollisionChecker(np.array([[x, -0.30, z] for z in np.arange(0.6, 1.0, 0.01)]))
        if post.clearance_ok(q_side, payload=payload)[0] and not post.clearance_ok(half).all():
            return post
    pytest.fail("no post position blocks the way back but not the hand")


def hand_at(b: Behaviours, pose: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Move the arm to TCP pose `pose` (4, 4, `base`); its joint angles and the pose 10 cm
    above it."""
    free = CollisionChecker(np.zeros((0, 3)))
    q = next(q for q in ik_tcp(pose, dims.UR5_READY_Q) if free.clearance_ok(q)[0])
    assert b.go_to(q, free, "test").ok
    above = pose.copy()
    above[2, 3] += 0.10
    return q, above
