"""Views from the way in (`pipeline.recall`): frames kept while the scooter drives, carried
into the frame where it stands by the odometry.

The first tests use depth frames computed here by casting rays at a wall, so what each camera
saw is known exactly; the last drives the simulated scooter and asks its real cameras."""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np
import pytest
from driving import drive_back_and_in
from scipy.spatial import cKDTree

from laserpick.bench.referee import Referee
from laserpick.pipeline.cloud import fuse
from laserpick.pipeline.collision import (
    CARRIED_PADDING,
    CollisionChecker,
    self_filter,
    within_reach,
)
from laserpick.pipeline.free_space import hidden, seen_free
from laserpick.pipeline.recall import (
    NOW_TOLERANCE,
    VIEW_VOXEL,
    Recalled,
    ViewMemory,
    motion,
    on_target,
)
from laserpick.robot.sim.robot import SimRobot
from laserpick.robot.sim.scenes import load_scene
from laserpick.server.session import Actor, Session, TaskState
from laserpick.transforms import invert, planar_pose
from laserpick.types import DepthFrame

WALL_X = 2.0  #: m, in the odometry's frame: a wall facing the scooter's start, in part
#: within the arm's reach
TOL = 0.006


def _camera_at(pose: np.ndarray, height: float = 1.0, yaw: float = 0.0) -> np.ndarray:
    """T_base_cam of a camera 1 m ahead of the axle at `height`, looking along base +x turned
    by `yaw` (rad), level; optical x right, y down, z forward."""
    c, s = math.cos(yaw), math.sin(yaw)
    forward, left = np.array([c, s, 0.0]), np.array([-s, c, 0.0])
    T = np.eye(4)
    T[:3, :3] = np.column_stack([-left, [0.0, 0.0, -1.0], forward])
    T[:3, 3] = [1.0, 0.0, height]
    return T


def _wall_frame(pose: np.ndarray, *, yaw: float = 0.0, stamp: float = 0.0) -> DepthFrame:
    """What a camera on the scooter at odometry `pose` (x, y, yaw) reads of the wall at
    x = WALL_X: each pixel's depth along the optical axis, 0 where its ray misses the wall."""
    w, h, f = 120, 90, 100.0
    K = np.array([[f, 0.0, w / 2], [0.0, f, h / 2], [0.0, 0.0, 1.0]])
    T_base_cam = _camera_at(pose, yaw=yaw)
    T_world_cam = planar_pose(*pose) @ T_base_cam
    v, u = np.mgrid[0:h, 0:w]
    rays = np.stack([(u - K[0, 2]) / f, (v - K[1, 2]) / f, np.ones((h, w))], -1).reshape(-1, 3)
    dirs = rays @ T_world_cam[:3, :3].T  # world; optical z component 1
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (WALL_X - T_world_cam[0, 3]) / dirs[:, 0]
    depth = np.where(np.isfinite(t) & (t > 0), t, 0.0).reshape(h, w).astype(np.float32)
    return DepthFrame(depth, np.zeros((h, w), np.uint8), K, T_base_cam, "front", stamp)


def _in_base(world: np.ndarray, pose: np.ndarray) -> np.ndarray:
    T = invert(planar_pose(*pose))
    return world @ T[:3, :3].T + T[:3, 3]


def test_a_recalled_frame_says_of_each_point_what_it_said_where_it_was_taken():
    """Points in the world are seen free (or not) through a frame taken at one pose, asked in
    that pose's `base`, exactly as through the recalled frame, asked in the `base` of the
    pose the scooter drove and turned to."""
    then, now = np.array([0.0, 0.0, 0.0]), np.array([0.9, 0.4, 0.35])
    frame = _wall_frame(then)
    memory = ViewMemory(0.1, 0.1, 4, 60.0)
    memory.add([frame], then)
    recalled = memory.recall(now, now=1.0)
    rng = np.random.default_rng(0)
    world = np.column_stack(
        [rng.uniform(1.5, 4.0, 500), rng.uniform(-1.0, 1.0, 500), rng.uniform(0.3, 1.7, 500)]
    )
    asked_then = seen_free(_in_base(world, then), [frame], TOL)
    asked_now = seen_free(_in_base(world, now), list(recalled.frames), TOL)
    assert asked_then.any() and not asked_then.all()  # the wall splits them
    np.testing.assert_array_equal(asked_now, asked_then)
    assert not seen_free(_in_base(world, now), [], TOL).any()
    # The motion is the odometry's: the camera stands where the scooter's drive left it.
    T = motion(then, now)
    np.testing.assert_allclose(recalled.frames[0].T_base_cam, T @ frame.T_base_cam)
    np.testing.assert_allclose(
        (planar_pose(*now) @ recalled.frames[0].T_base_cam)[:3, 3],
        (planar_pose(*then) @ frame.T_base_cam)[:3, 3],
        atol=1e-12,
    )


def test_the_memory_keeps_a_view_each_spacing_or_turn_the_last_few_and_only_for_a_while():
    memory = ViewMemory(spacing=0.15, turn=math.radians(15), size=3, max_age=60.0)
    assert memory.due(np.zeros(3))  # before the first
    for k, x in enumerate((0.0, 0.15, 0.30, 0.45)):
        pose = np.array([x, 0.0, 0.0])
        memory.add([_wall_frame(pose, stamp=10.0 * k)], pose)
    assert len(memory) == 3  # the oldest went
    assert not memory.due(np.array([0.55, 0.0, 0.0]))
    assert memory.due(np.array([0.61, 0.0, 0.0]))
    assert memory.due(np.array([0.45, 0.0, math.radians(16)]))
    assert not memory.due(np.array([0.45, 0.0, math.radians(14)]))
    # Stamps 10, 20 and 30 s: at 85 s, the view of 20 s is past a minute and forgotten.
    assert len(memory.recall(np.array([0.45, 0.0, 0.0]), now=85.0).frames) == 1
    assert len(memory.recall(np.array([0.45, 0.0, 0.0]), now=0.0).frames) == 3
    assert not ViewMemory(0.15, 0.3, 0, 60.0).due(np.zeros(3))
    with pytest.raises(ValueError, match="positive"):
        ViewMemory(0.0, 0.3, 4, 60.0)


def test_only_what_the_arm_could_touch_is_recalled():
    """The wall's points out of the arm's reach are left out; every part of it within reach
    is kept, to the views' thinning."""
    then = np.array([0.0, 0.0, 0.0])
    view = _wall_frame(then)
    memory = ViewMemory(0.1, 0.1, 4, 60.0)
    memory.add([view], then)
    kept = memory.recall(then, now=0.0).points
    seen = fuse([view]).points
    assert within_reach(kept).all()
    assert (~within_reach(seen)).sum() > 100  # the crop had something to leave out
    near = seen[within_reach(seen)]
    d, _ = cKDTree(kept).query(near)
    assert d.max() <= VIEW_VOXEL * math.sqrt(3)


def test_the_memory_forgets_what_was_picked_up_where_it_stood():
    """Forgotten (picked up since, the scooter 0.4 m on and turned), a patch of the wall goes
    from every view, to CARRIED_PADDING around it, and the rest of the wall stays."""
    then, now = np.array([0.0, 0.0, 0.0]), np.array([0.4, 0.1, 0.2])
    memory = ViewMemory(0.1, 0.1, 4, 60.0)
    memory.add([_wall_frame(then)], then)
    wall = memory.recall(then, now=0.0).points
    # The patch given in `base` as the scooter now stands.
    patch = wall[(wall[:, 1] > -0.3) & (wall[:, 1] < -0.2)]
    T = motion(then, now)
    memory.forget(patch @ T[:3, :3].T + T[:3, 3], now)
    left = memory.recall(then, now=0.0).points
    d, _ = cKDTree(patch).query(left)
    assert d.min() >= CARRIED_PADDING - 1e-4
    beyond = wall[cKDTree(patch).query(wall)[0] > 0.05]
    d, _ = cKDTree(left).query(beyond)
    assert len(beyond) > 100 and d.max() < 1e-6  # the wall beyond the padding is all there
    # What lies lower than `above` stays: the patch's lower half, as a surface would.
    memory = ViewMemory(0.1, 0.1, 4, 60.0)
    memory.add([_wall_frame(then)], then)
    middle = float(np.median(patch[:, 2]))
    memory.forget(patch @ T[:3, :3].T + T[:3, 3], now, above=middle)
    left = memory.recall(then, now=0.0).points
    d, _ = cKDTree(patch).query(left)
    assert (left[d < 0.01][:, 2] <= middle + 1e-6).all() and (d < 0.01).sum() > 20


def test_a_view_adds_its_points_only_where_no_camera_sees_now():
    """Of the points a view saw of the wall, those a camera sees now are the current
    capture's to say; those now outside every camera's view, and those hidden behind
    something nearer, are kept; those near the target are taken for the target."""
    then = np.array([0.0, 0.0, 0.0])
    view = _wall_frame(then)
    memory = ViewMemory(0.1, 0.1, 4, 60.0)
    memory.add([view], then)
    recalled = memory.recall(then, now=0.0)
    wall = recalled.points
    assert len(wall) > 100 and np.allclose(wall[:, 0], WALL_X - 0.0, atol=0.006)
    # Now: a camera turned 40 degrees left sees the left part of the wall only.
    left = _wall_frame(then, yaw=math.radians(40))
    blind = recalled.blind_points([left])
    assert 0 < len(blind) < len(wall)
    assert hidden(blind, [left], NOW_TOLERANCE).all()
    assert blind[:, 1].max() < wall[:, 1].max()  # the left part went: it is seen now
    # Something 0.5 m before the camera, filling its view, now hides every point.
    screened = replace(view, depth=np.full_like(view.depth, 0.5))
    assert len(recalled.blind_points([screened])) == len(wall)
    # The same camera, reading the wall as the view did, sees every point: none is added.
    assert len(recalled.blind_points([view])) == 0
    # The target's own points are not obstacles (`on_target`): a strip of the wall as the
    # target takes its points with it, and the wall's points beyond stay.
    strip = np.abs(wall[:, 1]) < 0.1
    kept = recalled.blind_points([], wall[strip], support=0.0)
    assert len(kept) == len(wall) - strip.sum() and np.min(np.abs(kept[:, 1])) >= 0.1 - 1e-6
    assert len(Recalled().blind_points([left])) == 0


def test_the_blind_spot_beside_the_parked_scooter_was_seen_on_the_way_in():
    """Driven 1 m back and in again, the scooter stands where it started: the space right of
    its front, where no camera looks, was in view a metre back. With the views of the way
    in, it counts as seen, and what they saw there is in the planner's cloud; the current
    capture alone knows nothing of it. A view is kept only with the arm stowed."""
    session = Session(SimRobot(load_scene("isolation", seed=1), realtime=False))
    try:
        robot, actor = session.robot, Actor("bench")
        robot.sim.settle(0.3)
        drive_back_and_in(session, actor)
        kept = len(session.views)
        assert kept == session.settings.perception.recall_views
        frames = robot.capture()
        recalled = session.recalled()
        assert len(recalled.frames) == 5 * kept
        blind_spot = np.array([[1.40, -0.75, 0.90], [1.30, -0.55, 0.80]])
        assert not seen_free(blind_spot, frames, TOL).any()
        assert seen_free(blind_spot, list(recalled.frames), TOL).all()
        # The table's far right corner region, hidden now, came back as points.
        blind = recalled.blind_points(frames)
        assert len(blind) and hidden(blind, frames, NOW_TOLERANCE).all()
        # The planner: the hand may now pass through that space.
        q_home = robot.joint_state().q
        now_only = CollisionChecker(fuse(frames).points, q_self=q_home, frames=frames)
        with_views = CollisionChecker(
            np.vstack([fuse(frames).points, blind]),
            q_self=q_home,
            frames=(*frames, *recalled.frames),
        )
        centres = blind_spot
        radii = np.full(len(centres), 0.04)
        assert now_only.unseen(centres, radii).all()
        assert not with_views.unseen(centres, radii).any()
        # The cameras see part of the stowed arm, but the views keep none of it: raised to
        # ready, the arm finds the place it folds into free in what the stow plans around.
        assert not self_filter(fuse(frames).points, q_home).all()
        assert session.behaviours.go_ready().ok
        around = session.surroundings(session.capture_or_none())
        assert around is not None and around.clearance_ok(q_home)[0]
        # With the arm away from its stowed pose, driving keeps no view.
        session.views.clear()
        session.drive(actor, 0.4, 0.0, 0.3)
        robot.sleep(0.1)
        assert len(session.views) == 0
    finally:
        session.close()


def _between(points: np.ndarray, low: float, high: float) -> np.ndarray:
    return points[(points[:, 2] > low) & (points[:, 2] < high)]


def _settle(session: Session, timeout: float = 120.0) -> None:
    deadline = time.monotonic() + timeout
    while session.busy:
        assert time.monotonic() < deadline, session.message
        time.sleep(0.01)


def test_a_picked_object_is_forgotten_where_it_stood_and_no_view_is_kept_holding_it():
    """The pick takes the mug out of the views of the way in (`ViewMemory.forget`): it is
    no longer where they saw it, and the stow or the drop after it must not go around its
    ghost there. Holding it, tucked in, a drive keeps no view: the arm is not stowed and
    the hand is not empty."""
    session = Session(SimRobot(load_scene("isolation", seed=1), realtime=False))
    try:
        robot, actor = session.robot, Actor("bench")
        referee = Referee(robot)
        robot.sim.settle(0.3)
        drive_back_and_in(session, actor)
        mug = referee.object_points("mug_1")
        # Above the table top (0.46 m): the table under the mug stays.
        above = (mug[:, 2].min() + 0.01, np.inf)
        d, _ = cKDTree(mug).query(_between(session.recalled().points, *above))
        assert (d < 0.01).sum() > 20  # the views saw the mug where it stands
        session.set_mode(actor, mode="pick_and_place")
        centre = (mug.min(axis=0) + mug.max(axis=0)) / 2
        session.aim_at(actor, centre, "base")
        session.confirm(actor, point=centre)
        _settle(session)
        assert session.state == TaskState.GRASPS_READY, session.message
        session.execute(actor)
        _settle(session)
        assert session.state == TaskState.AWAITING_PLACE, session.message
        d, _ = cKDTree(mug).query(_between(session.recalled().points, *above))
        # No ghost: nothing where the mug's surface was. A stray pixel of table and handle
        # mixed (1.6 cm off the mug, 1.2 cm over the table) lies outside CARRIED_PADDING of
        # what was seen of it, or inside, as the scooter's odometry ends the pick a fraction
        # of a millimetre apart.
        assert (d < 0.01).sum() == 0, "the views still hold the mug where it stood"
        assert (d < 0.02).sum() <= 2, "the views still hold the mug where it stood"
        session.views.clear()
        drive_back_and_in(session, actor)
        assert len(session.views) == 0
    finally:
        session.close()


def test_what_a_view_saw_of_the_target_hidden_now_is_the_target_not_an_obstacle():
    """A box 10 cm wide standing on a shelf at 1.0 m, its front face seen now only up to a
    diagonal (a corner hidden behind something nearer): the view's points on the hidden
    corner hang together with the seen face and belong to it. A neighbour 4 cm beside it,
    and the shelf it stands on, are not the box."""
    step = 0.01
    ys, zs = np.meshgrid(np.arange(-0.05, 0.05 + 1e-9, step), np.arange(1.0, 1.25 + 1e-9, step))
    face = np.column_stack([np.full(ys.size, 1.5), ys.ravel(), zs.ravel()])
    seen = face[face[:, 1] > -0.05 + 0.4 * (face[:, 2] - 1.0)]  # the lower right is hidden
    corner = face[face[:, 1] <= -0.05 + 0.4 * (face[:, 2] - 1.0)]
    neighbour = corner + [0.0, -0.14, 0.0]  # 4 cm beyond the box's right side
    sx, sy = np.meshgrid(np.arange(1.40, 1.70, step), np.arange(-0.30, 0.20, step))
    shelf = np.column_stack([sx.ravel(), sy.ravel(), np.full(sx.size, 1.0)])
    views = np.vstack([corner, neighbour, shelf])
    part = on_target(views, seen, support=1.0)
    n, m = len(corner), len(neighbour)
    # All of it above the shelf's height, where a box's bottom edge and the shelf are one.
    assert part[:n][corner[:, 2] > 1.005].all()
    assert not part[n : n + m].any()
    assert not part[n + m :].any()
    deeper = corner + [0.015, 0.0, 0.0]  # its unseen depth too
    assert on_target(deeper, seen, 1.0)[deeper[:, 2] > 1.005].all()
