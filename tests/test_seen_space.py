"""The way out of the stowed pose, and transits that keep the hand where the cameras saw.

Real frames rendered by the simulated depth cameras in the isolation scene (a table before
the scooter, nothing beside it): the space right of the scooter is beyond every camera's
view, so a planned transit may not swing the hand through it, though no point of the cloud
lies there."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from arm_poses import table

from laserpick.description import dims
from laserpick.description.kinematics import ik_tcp, tcp_pose
from laserpick.pipeline.cloud import fuse
from laserpick.pipeline.collision import UNSTOW_BOX, CollisionChecker
from laserpick.pipeline.first_plan import plan_first
from laserpick.pipeline.grasp_choice import GraspSet
from laserpick.pipeline.joint_search import Searches, joint_path
from laserpick.pipeline.parking_advice import ASIDE_STEP, UNSEEN_WAYS, park_aside_sentence
from laserpick.pipeline.plan import plan_pick, transit_path
from laserpick.pipeline.selection import group
from laserpick.robot.sim.robot import SimRobot
from laserpick.robot.sim.scenes import load_scene
from laserpick.settings import get_settings
from laserpick.types import Failure, Grasp

HOME, UNSTOW, READY = dims.UR5_HOME_Q, dims.UR5_UNSTOW_Q, dims.UR5_READY_Q


@pytest.fixture(scope="module")
def world() -> CollisionChecker:
    robot = SimRobot(load_scene("isolation", seed=1), realtime=False)
    try:
        robot.sim.settle(0.5)
        frames = robot.capture()
        q = robot.joint_state().q
    finally:
        robot.close()
    cloud = fuse(frames)
    return CollisionChecker(cloud.points, q_self=q, frames=frames)


def _hand_at(x: float, y: float, z: float) -> np.ndarray:
    """The arm with the TCP at (x, y, z) (m, `base`), gripper down as at ready."""
    T = tcp_pose(READY)
    T[:3, 3] = x, y, z
    return ik_tcp(T, READY)[0]


def test_the_way_out_of_the_stowed_pose_stays_beside_the_scooter():
    """Home to the unstow pose, and on to either ready pose, in straight joint lines: clear
    of the scooter, its rider and the floor; on the first, the hand never more than 0.35 m
    out from the scooter's side (y = -0.3) or 0.3 m ahead of its front, where the move
    straight to ready went 0.57 m out and 0.68 m ahead."""
    free = CollisionChecker(np.zeros((0, 3)))
    assert free.segment_ok(HOME, UNSTOW)
    assert free.segment_ok(UNSTOW, READY) and free.segment_ok(UNSTOW, dims.UR5_HIGH_READY_Q)
    tcp = np.array([tcp_pose(q)[:3, 3] for q in np.linspace(HOME, UNSTOW, 50)])
    assert tcp[:, 1].min() > -0.65
    assert tcp[:, 0].max() < 1.35
    to_ready = np.array([tcp_pose(q)[:3, 3] for q in np.linspace(HOME, READY, 50)])
    assert to_ready[:, 1].min() < -0.8 and to_ready[:, 0].max() > 1.65  # what it replaces


def test_the_hand_may_not_go_where_no_camera_saw(world):
    right = _hand_at(1.40, -0.75, 0.90)  # beside the table, right of every camera's view
    ahead = _hand_at(1.45, 0.0, 0.90)  # above the table, in front of the cameras
    assert world.clearance_ok(right)[0], "no point of the cloud lies there"
    assert not world.clearance_ok(right, seen=True)[0]
    assert world.clearance_ok(ahead, seen=True)[0]


def test_where_the_arm_stood_and_the_way_out_count_as_seen(world):
    """Home and the unstow pose are beyond the cameras' view, on the arm's way out; and
    where the arm stood as the frames were taken, nothing else stood."""
    assert world.clearance_ok(np.array([HOME, UNSTOW]), seen=True).all()
    lo, hi = UNSTOW_BOX
    assert lo[1] > -0.75 and hi[0] < 1.3  # beside the scooter's front, not out in the room
    right = _hand_at(1.40, -0.75, 0.90)
    stood = CollisionChecker(world.points, filtered=True, frames=world.frames, q_self=right)
    assert stood.clearance_ok(right, seen=True)[0]
    assert not stood.clearance_ok(_hand_at(1.40, -0.65, 0.80), seen=True)[0]


def test_from_standing_by_the_way_to_ready_is_a_fixed_way_beside_the_scooter(world):
    """Standing by (`UR5_STANDBY_Q`) beside the scooter, the hand rises to the ready pose
    through space no camera sees, as it does on the way out of the stowed pose: that leg
    is not held to seen space, and the pick plans; the leg on to the grasp still is."""
    s = get_settings().motion
    standby = dims.UR5_STANDBY_Q
    way = np.linspace(standby, READY, 30)
    assert not world.knowing(standby, READY).clearance_ok(way, hand=True, seen=True).all()
    q_grasp = _hand_at(1.55, -0.20, 0.55)
    plan = plan_pick(
        standby, q_grasp, world, world, np.random.default_rng(0), s, via=(READY,), standby=True
    )
    assert not isinstance(plan, Failure), plan
    held = plan_pick(standby, q_grasp, world, world, np.random.default_rng(0), s, via=(READY,))
    assert isinstance(held, Failure), "held to seen space, no way leads out from beside"


def test_from_standing_by_under_a_board_the_way_out_passes_its_exit(world):
    """Where a board fills both ready poses (a shelf's, a high table's), the way out of
    standing by passes its exit (`UR5_STANDBY_EXIT_Q`): elbow up, the hand ahead of the
    scooter's front right corner, in space that counts as seen, where the way out of the
    stowed pose passes, so that the leg on, held to seen space, starts where the one from
    the unstow pose does. Where a ready pose is clear, the way is direct."""
    s = get_settings().motion
    standby, exit_ = dims.UR5_STANDBY_Q, dims.UR5_STANDBY_EXIT_Q
    board = table(1.06, x=(1.35, 1.95), y=(-0.6, 0.0))
    boarded = world.with_points(board)
    via = (READY, dims.UR5_HIGH_READY_Q)
    assert not boarded.clearance_ok(np.array(via)).any()
    assert exit_[2] > 0.3 and boarded.clearance_ok(exit_, seen=True)[0]
    q_pre = _hand_at(1.55, -0.20, 0.65)
    blind = CollisionChecker(boarded.points, filtered=True)  # the routing, not the seen test
    for checker, passes in (
        (blind, [standby, exit_]),
        (CollisionChecker(world.points, filtered=True), [standby, READY]),
    ):
        route = transit_path(
            standby, q_pre, checker, np.random.default_rng(0), s, Searches(6), via, exit_, True
        )
        assert route is not None
        np.testing.assert_allclose(route[0][:2], passes)


def _route_passes(
    q_now: np.ndarray,
    q_pre: np.ndarray,
    checker: CollisionChecker,
    passes: list[np.ndarray],
    unstow: np.ndarray,
    standby: bool = False,
    turn: np.ndarray | None = None,
) -> np.ndarray:
    """The transit from q_now to q_pre (`transit_path`, through the ready poses where clear),
    asserted to pass through each of `passes` in order, then on to q_pre; its waypoints."""
    via = (READY, dims.UR5_HIGH_READY_Q)
    rng, s = np.random.default_rng(0), get_settings().motion
    route = transit_path(q_now, q_pre, checker, rng, s, Searches(6), via, unstow, standby, turn)
    assert route is not None
    at = [int(np.argmin(np.abs(route[0] - q).max(axis=1))) for q in passes]
    pairs = zip(at, passes, strict=True)
    assert all(np.allclose(route[0][k], q) for k, q in pairs), "passes them"
    assert at == sorted(at) and np.allclose(route[0][-1], q_pre), "in order, then on"
    return route[0]


def test_from_standing_by_to_a_grasp_on_the_other_elbow_branch_the_elbow_turns_on_the_way_out(
    world,
):
    """A pre-grasp on the stowed pose's elbow branch (elbow down): from standing by (elbow
    up) the way out ends at the unstow pose, through a ready pose where one is clear, as the
    stow goes, so that the elbow turns over there and not on the leg held to seen space."""
    standby = dims.UR5_STANDBY_Q
    T = tcp_pose(READY)
    T[:3, 3] = 1.40, -0.45, 0.75
    q_pre = ik_tcp(T, UNSTOW)[0]
    assert q_pre[2] < 0, "elbow down"
    board = table(1.06, x=(1.35, 1.95), y=(-0.6, 0.0))
    for points, passes in ((world.points, [standby, READY, UNSTOW]), (board, [standby, UNSTOW])):
        checker = CollisionChecker(points, filtered=True)
        _route_passes(standby, q_pre, checker, passes, dims.UR5_STANDBY_EXIT_Q, True, UNSTOW)


def test_from_the_stowed_pose_under_a_board_the_elbow_turns_on_the_way_to_the_exit(world):
    """From the stowed pose (elbow down), where a board fills both ready poses, a pre-grasp
    with the elbow up is reached through the unstow pose and standing by's exit: the elbow
    turns over on the straight way between them, beside the scooter, and the leg held to
    seen space starts at the exit, on the pre-grasp's branch. A pre-grasp with the elbow
    down goes on from the unstow pose, as before."""
    exit_ = dims.UR5_STANDBY_EXIT_Q
    board = CollisionChecker(table(1.06, x=(1.35, 1.95), y=(-0.6, 0.0)), filtered=True)
    assert not board.clearance_ok(np.array([READY, dims.UR5_HIGH_READY_Q])).any()
    up = _hand_at(1.55, -0.20, 0.65)
    T = tcp_pose(READY)
    T[:3, 3] = 1.40, -0.45, 0.75
    down = ik_tcp(T, UNSTOW)[0]
    assert up[2] > 0 > down[2]
    for q_pre, passes in ((up, [HOME, UNSTOW, exit_]), (down, [HOME, UNSTOW])):
        route = _route_passes(HOME, q_pre, board, passes, UNSTOW, turn=exit_)
        if q_pre is down:
            assert not np.isclose(route, exit_).all(axis=1).any()


def test_a_planned_transit_keeps_the_hand_in_seen_space(world):
    """From the ready pose to a hand beside the table's right edge: the path found keeps
    the hand out of the blind space beside the scooter at every step between. The ends may
    lie beyond the cameras' view: the arm stands at one and must stand at the other."""
    rng = np.random.default_rng(0)
    goal = _hand_at(1.50, -0.55, 0.70)
    assert not world.clearance_ok(goal, seen=True)[0]
    checker = world.knowing(READY, goal)
    path = joint_path(READY, goal, checker, rng, get_settings().motion, seen=True)
    assert path is not None
    Q = np.vstack([np.linspace(a, b, 20) for a, b in itertools.pairwise(path)])
    assert checker.clearance_ok(Q, seen=True).all()


def test_a_leg_kept_from_unseen_space_says_a_way_led_through_it(world):
    """The only ways from ready to beside the table pass space no camera saw: held to seen
    space the search finds none, and the pick can say that a way through unseen space was
    there. A leg that ends inside something has no way at all, seen or not."""
    s = get_settings().motion.model_copy(update={"rrt_max_samples": 300})
    rng = np.random.default_rng(0)
    beside = _hand_at(1.40, -0.75, 0.90)  # right of the table, of every camera's view
    searches = Searches(max_failed=6)
    assert searches.path(READY, beside, world, rng, s) is None
    assert searches.unseen_only(s)
    table_top = world.points[np.argmax(world.points[:, 2])]
    inside = _hand_at(*table_top)  # the hand in the table's top
    walled = Searches(max_failed=6)
    assert walled.path(READY, inside, world, rng, s) is None
    assert not walled.unseen_only(s)
    # Without the frames nothing counts as unseen, and the same leg has a way: the cameras'
    # view, not what they saw, blocked it.
    blind = CollisionChecker(world.points, filtered=True)
    assert Searches(6).path(READY, beside, blind, rng, s) is not None


def test_a_pick_whose_ways_all_pass_unseen_space_says_so(world):
    """Planned from ready, a grasp beside the table fails for want of a way through seen
    space, and the failure says that ways through unseen space were left untaken, and asks
    the user to park to their right, with the object
    nearer the middle of the cameras' view."""
    s = get_settings().motion.model_copy(update={"rrt_max_samples": 300})
    pose = tcp_pose(READY)
    pose[:3, 3] = 1.40, -0.75, 0.80
    q = ik_tcp(pose, READY)[0]
    grasp = Grasp(pose=pose, width=0.05, ik=q)
    found = GraspSet(group([grasp]), (), world, world, pose[:3, 3][None], "gpd")
    plan, chosen, tried = plan_first(found, READY, np.random.default_rng(0), settings=s)
    assert isinstance(plan, Failure) and chosen is None and tried == 1
    assert plan.message.startswith("No collision-free path to this grasp was found")
    assert plan.message.endswith(UNSEEN_WAYS)
    assert plan.park_left == -ASIDE_STEP
    asked = park_aside_sentence(plan.park_left)
    assert asked.startswith(f" Park about {ASIDE_STEP * 100:.0f} cm farther to your right")
