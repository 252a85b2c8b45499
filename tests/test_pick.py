"""The pick on the simulated robot: a guarded approach that meets an unseen obstacle stops
and backs off, the object's own leftovers leave with it, and a grasp from the side is drawn
back out level."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from arm_setups import (
    BEHAVIOUR,
    TABLE_TOP,
    hand_at,
    isolation_robot,
    post_behind,
    side_pose,
    top_down,
)

from laserpick.behaviours import Behaviours, without_leftovers
from laserpick.bench.referee import Referee
from laserpick.description import dims
from laserpick.description.kinematics import ik_tcp, tcp_pose
from laserpick.pipeline.collision import CARRIED_PADDING, CollisionChecker, carried_shape
from laserpick.pipeline.grasp_choice import GraspSet, find_grasps
from laserpick.pipeline.lines import cartesian_line
from laserpick.pipeline.perceive import perceive
from laserpick.pipeline.selection import group, score
from laserpick.types import Grasp, Trajectory


@pytest.fixture
def robot():
    yield from isolation_robot()


def grasp_set_at(pose: np.ndarray, checker: CollisionChecker) -> GraspSet:
    """A one-grasp set, as the pipeline would hand it over."""
    q = ik_tcp(pose, dims.UR5_READY_Q)[0]
    g = score(
        Grasp(pose=pose, width=0.05, ik=q),
        q_now=dims.UR5_READY_Q,
        sample=pose[:3, 3][None],
        mark=pose[:3, 3],
    )
    target = pose[:3, 3][None]
    return GraspSet(group([g]), (), checker, checker, target, "vertical")


def withdraw(
    b: Behaviours,
    approach: np.ndarray,
    checker: CollisionChecker,
    payload: np.ndarray | None = None,
) -> None:
    """Draw the hand back level the way `withdrawal_path` finds, as the pick does after a
    lift from the side (at the lift's speed holding `payload`); stay where it finds none."""
    path = b.withdrawal_path(approach, checker, payload)
    if path is not None:
        s = b.settings.motion
        speed = s.lift_speed if payload is not None else s.approach_speed
        assert b.run_withdrawal(path, speed) is None


def point_ahead(q_side: np.ndarray) -> CollisionChecker:
    """A point 5-10 mm ahead of the fingers of the hand at `side_pose(1.70, -0.30, 0.80)`
    (joint angles q_side): inside the 1 cm margin, short of touching."""
    for x in np.arange(1.70, 1.90, 0.001):
        near = CollisionChecker(np.array([[x, -0.30, 0.80]]))
        if near.clearance_ok(q_side, margin=0.005)[0] and not near.clearance_ok(q_side)[0]:
            return near
    pytest.fail("no point ahead of the hand lies 5-10 mm from it")


def test_pick_into_an_unseen_obstacle_stops_and_backs_off(robot):
    # The planner sees nothing (an empty cloud); the grasp is 4 cm into the table top.
    pose = top_down(1.5, -0.3, TABLE_TOP - 0.04 + 0.011)
    b = Behaviours(robot)
    out = b.pick(grasp_set_at(pose, CollisionChecker(np.zeros((0, 3)))))
    assert not out.ok and out.failure.kind == "execute"
    assert "touched something" in out.failure.message
    robot.sleep(0.3)
    s = robot.sim.snapshot()
    assert np.abs(s.arm_qd).max() < 0.05
    assert tcp_pose(s.arm_q)[2, 3] > TABLE_TOP + 0.03, "it backed off upward"
    assert not s.gripper_closed
    assert b.ahead is None and b.held is None, "the carry searched for it is dropped"


def test_an_object_that_leaves_the_hand_as_the_lift_ends_is_said_to_have_slipped(robot):
    """The mug is taken from the closed hand 50 ms before the full lift ends: the pick
    judges the hold as the lift ends and says the object slipped out."""
    name = "mug_1"
    referee = Referee(robot)
    perception = perceive(robot.capture(), point=referee.aim_point(name))
    found = find_grasps(perception, dims.UR5_READY_Q, q_capture=robot.joint_state().q)
    assert isinstance(found, GraspSet), found
    b = Behaviours(robot)
    lifts: list[Trajectory] = []
    run, wait = b.run, robot.wait

    def counting_lifts(traj: Trajectory, what: str):
        if what == "lifting":
            lifts.append(traj)
        return run(traj, what)

    def away(m, d) -> None:
        j = m.joint(f"obj/{name}")
        d.qpos[j.qposadr[0] : j.qposadr[0] + 3] = [5.0, 5.0, 0.1]
        d.qvel[j.dofadr[0] : j.dofadr[0] + 6] = 0.0

    def taken_near_the_end(handle, timeout: float) -> str:
        if len(lifts) == 2 and lifts[1] is not None:  # the full lift, after the re-grip's
            full, lifts[1] = lifts[1], None
            wait(handle, full.duration - 0.05)
            robot.sim.call(away)
        return wait(handle, timeout)

    b.run = counting_lifts  # type: ignore[method-assign]
    robot.wait = taken_near_the_end  # type: ignore[method-assign]
    out = b.pick(found)
    assert len(lifts) == 2 and lifts[1] is None, "taken during the full lift"
    assert not out.ok and "slipped out of the hand while lifting" in out.failure.message
    assert referee.position(name)[0] > 4.0


def test_parts_of_the_object_the_segmentation_missed_leave_with_it():
    """Points beside the picked target, above its support, are parts of it the segmentation
    left out; they are not obstacles for the carry. The support and farther objects are."""
    target = np.array([[1.5, -0.3, z] for z in np.arange(0.47, 0.70, 0.01)])
    trigger = np.array([[1.52, -0.3, 0.68], [1.51, -0.29, 0.69]])  # within 3 cm of its top
    table = np.array([[1.5 + dx, -0.3, 0.46] for dx in (-0.02, 0.0, 0.02)])
    neighbour = np.array([[1.5, -0.2, 0.55]])  # 10 cm away
    around = CollisionChecker(np.vstack([trigger, table, neighbour]), voxel=0.0)
    kept = without_leftovers(around, target, 0.46, BEHAVIOUR.support_scatter).points
    assert {tuple(p) for p in np.round(kept, 3)} == {
        tuple(p) for p in np.round(np.vstack([table, neighbour]), 3)
    }


def test_the_objects_own_points_low_behind_it_leave_with_it():
    """A point of a pill bottle's back low down, 2.7 cm above the 69 cm board, outside the
    segmented target (the cameras see its front and cap). It is the bottle's own, inside its
    carried shape (the guessed back, filled down to the board), and leaves with it; kept, it
    would stand where the lifted bottle hangs, and no tuck could start. The board's points
    stay, and so does a point 6 cm behind the bottle's back."""
    board, r, axis = 0.69, 0.02, np.array([1.51, -0.295])
    turns = np.radians(np.arange(90, 271, 15))  # the half facing the cameras (-x)
    heights = np.arange(board + 0.005, board + 0.08, 0.01)
    side = [[*(axis + r * np.array([np.cos(t), np.sin(t)])), z] for t in turns for z in heights]
    cap = [[*(axis + [dx, dy]), board + 0.08] for dx in (-0.01, 0, 0.01) for dy in (-0.01, 0, 0.01)]
    seen = np.array(side + cap)
    back = np.array([[axis[0] + r, axis[1], board + 0.027]])
    floor = np.array([[axis[0] + dx, axis[1], board + 0.002] for dx in (-0.04, 0.0, 0.04)])
    neighbour = np.array([[axis[0] + 0.08, axis[1], board + 0.03]])
    around = CollisionChecker(np.vstack([back, floor, neighbour]), voxel=0.0)
    scatter = BEHAVIOUR.support_scatter
    assert scatter < back[0, 2] - board < CARRIED_PADDING  # low, yet off the board
    kept = without_leftovers(around, carried_shape(seen, board), board, scatter).points
    expected = np.vstack([floor, neighbour])
    assert {tuple(p) for p in np.round(kept, 3)} == {tuple(p) for p in np.round(expected, 3)}


def test_a_grasp_from_the_side_is_drawn_back_out_level_after_the_lift(robot):
    """Out of a shelf's gap before the arm swings anywhere: the lifted hand goes straight
    back along its approach, level, 10 cm; not where a post stands in the way (the arm
    stays, and the planner takes over); not from a grasp from above, which has risen out
    already."""
    b = Behaviours(robot)
    free = CollisionChecker(np.zeros((0, 3)))
    side = side_pose(1.70, -0.30, 0.80)
    q_side = next(q for q in ik_tcp(side, dims.UR5_READY_Q) if free.clearance_ok(q)[0])
    assert b.go_to(q_side, free, "test").ok
    payload = np.zeros((1, 3))
    withdraw(b, side[:3, 2], free, payload)
    np.testing.assert_allclose(
        tcp_pose(robot.joint_state().q)[:3, 3], [1.60, -0.30, 0.80], atol=0.005
    )
    assert b.go_to(q_side, free, "test").ok
    post = post_behind(q_side, payload)
    stood = robot.joint_state().q
    withdraw(b, side[:3, 2], post, payload)
    np.testing.assert_allclose(robot.joint_state().q, stood, atol=2e-3)
    withdraw(b, top_down(1.6, -0.3, 0.8)[:3, 2], free, payload)
    np.testing.assert_allclose(robot.joint_state().q, stood, atol=2e-3)


def test_a_side_grasp_blocked_straight_back_draws_back_level_a_little_turned(robot):
    """A post beside the way straight back (as the scooter's sensor post stands beside an
    elbow drawn back out of the 69 cm shelf): the hand backs out level, turned from the
    approach by at most 30 deg, rather than staying in the gap."""
    b = Behaviours(robot)
    side = side_pose(1.70, -0.30, 0.80)
    hand_at(b, side)
    robot.sleep(0.5)
    # Where the arm stands (the servos settle a few mrad off the IK solution): the post is
    # clear of it and blocks the way straight back from it, as the withdrawal sees them.
    q_side = robot.joint_state().q
    straight = [cartesian_line(q_side, side_pose(x, -0.30, 0.80)) for x in (1.60, 1.65)]
    post = None
    for x, y in itertools.product(np.arange(1.58, 1.40, -0.02), np.arange(-0.33, -0.45, -0.01)):
        near = CollisionChecker(np.array([[x, y, z] for z in np.arange(0.6, 1.0, 0.01)]))
        if near.clearance_ok(q_side)[0] and not any(near.clearance_ok(p).all() for p in straight):
            post = near
            break
    assert post is not None, "no post beside the way back blocks it"
    withdraw(b, side[:3, 2], post)
    moved = tcp_pose(robot.joint_state().q)[:3, 3] - side[:3, 3]
    assert abs(moved[2]) < 0.005 and np.linalg.norm(moved) > 0.045, "backed out level"
    turn = np.degrees(np.arccos(-moved[0] / np.linalg.norm(moved)))
    assert 10 < turn < 35, f"turned {turn:.0f} deg from straight back"
    assert post.clearance_ok(robot.joint_state().q)[0]


def test_a_hand_that_starts_within_the_margin_still_draws_back_if_the_way_keeps_clear(robot):
    """Something 5-10 mm ahead of the fingers (inside the 1 cm margin) does not keep the hand
    from drawing back away from it; something the way back comes closer to does."""
    b = Behaviours(robot)
    side = side_pose(1.70, -0.30, 0.80)
    q_side, _ = hand_at(b, side)
    ahead = point_ahead(q_side)
    withdraw(b, side[:3, 2], ahead)
    np.testing.assert_allclose(
        tcp_pose(robot.joint_state().q)[:3, 3], [1.60, -0.30, 0.80], atol=0.005
    )
    # Inside the margin already, and a post behind: it stays.
    hand_at(b, side)
    both = CollisionChecker(np.vstack([ahead.points, post_behind(q_side).points]))
    stood = robot.joint_state().q
    withdraw(b, side[:3, 2], both)
    np.testing.assert_allclose(robot.joint_state().q, stood, atol=2e-3)


def test_a_hand_that_starts_within_the_margin_leaves_the_arm_its_own(robot):
    """The fingers start 5-10 mm from something (the surface an object was set down on);
    the arm, clear by the full margin where it starts, keeps it on the way back: it may not
    end within the margin of a post behind, where no planner could start."""
    b = Behaviours(robot)
    side = side_pose(1.70, -0.30, 0.80)
    q_side, _ = hand_at(b, side)
    ahead = point_ahead(q_side)
    back = cartesian_line(q_side, side_pose(1.60, -0.30, 0.80))
    margin = ahead.margin
    post = None
    for x, y, z in itertools.product(
        np.arange(1.20, 1.60, 0.01), np.arange(-0.45, -0.15, 0.01), (0.70, 0.90, 1.10)
    ):
        near = CollisionChecker(np.array([[x, y, z]]))
        if (
            near.clearance_ok(q_side, hand=False)[0]
            and near.clearance_ok(back, margin=margin / 2).all()
            and not near.clearance_ok(back[-1:], hand=False)[0]
        ):
            post = near
            break
    assert post is not None, "no point comes within the margin of the arm drawn back"
    both = CollisionChecker(np.vstack([ahead.points, post.points]))
    withdraw(b, side[:3, 2], both)
    assert post.clearance_ok(robot.joint_state().q, hand=False)[0]
