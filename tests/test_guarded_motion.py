"""Guarded motion on the simulated robot: a guarded trajectory stops on contact, a protective
stop backs the arm away, a motion waits for the arm to reach its start; going to ready and
stowing where the ready poses are filled."""

from __future__ import annotations

import numpy as np
import pytest
from arm_poses import table
from arm_setups import TABLE_FRONT, TABLE_TOP, isolation_robot, top_down

from laserpick.behaviours import Behaviours
from laserpick.description import dims
from laserpick.description.kinematics import ik_tcp, tcp_pose
from laserpick.pipeline.collision import CollisionChecker
from laserpick.pipeline.lines import cartesian_line
from laserpick.pipeline.motion_limits import motion_limits, timed
from laserpick.pipeline.timing import excess
from laserpick.robot.sim.loop import DRIVE_STOP
from laserpick.types import Trajectory


@pytest.fixture
def robot():
    yield from isolation_robot()


def test_guarded_trajectory_stops_on_contact(robot):
    T_low = tcp_pose(dims.UR5_READY_Q)
    T_low[:3, 3] = [1.5, -0.3, TABLE_TOP - 0.05]  # 5 cm into the table
    b = Behaviours(robot)
    assert b.go_ready().ok
    path = cartesian_line(robot.joint_state().q, T_low)
    assert path is not None
    traj = timed(path, b.settings.motion, tcp_speed=0.05)
    guarded = Trajectory(traj.times, traj.q, guard_force=25.0)
    handle = robot.execute(guarded)
    status = robot.wait(handle, traj.duration + 2.0)
    assert status == "failed" and "unexpected contact" in handle.message
    assert "finger_" in handle.message and " met " in handle.message  # says what touched
    robot.sleep(0.2)
    s = robot.sim.snapshot()
    assert np.abs(s.arm_qd).max() < 0.05, "the arm must be at rest after the stop"
    tcp_z = tcp_pose(s.arm_q)[2, 3]
    assert tcp_z > TABLE_TOP - 0.03, "it stopped at the table, not inside it"


def _through_the_table(robot) -> tuple[Behaviours, Trajectory]:
    """The arm at ready, and an unguarded joint move that drives its hand 15 cm into the
    table."""
    b = Behaviours(robot)
    assert b.go_ready().ok
    T_low = tcp_pose(dims.UR5_READY_Q)
    T_low[:3, 3] = [1.5, -0.3, TABLE_TOP - 0.15]
    q_low = ik_tcp(T_low, dims.UR5_READY_Q)[0]
    return b, timed(np.stack([robot.joint_state().q, q_low]), b.settings.motion)


def test_any_motion_pushed_back_hard_makes_a_protective_stop_and_backs_away(robot):
    """An unguarded joint move that drives the hand down through the table (as a transit
    planned through unseen furniture would) is stopped by the protective stop; the arm goes
    back the way it came, and the behaviour says so in words."""
    b, move = _through_the_table(robot)
    lowest = []
    robot.sim.on_snapshot(lambda snap: lowest.append(tcp_pose(snap.arm_q)[2, 3]))
    failure = b.run(move, "testing")
    assert failure is not None and failure.kind == "execute"
    assert failure.message.startswith("The arm was pushed back while testing (")
    assert " met surface/table" in failure.message
    assert failure.message.endswith("stopped and backed away.")
    assert min(lowest) > TABLE_TOP - 0.03, "it stopped at the table, not inside it"
    robot.sleep(0.3)
    s = robot.sim.snapshot()
    assert np.abs(s.arm_qd).max() < 0.05, "the arm must be at rest after backing away"
    assert np.max(np.abs(s.arm_q - dims.UR5_READY_Q)) < 0.05, "back where the move started"
    # It stops on the push, not before: the same move above the table finishes.
    T_high = tcp_pose(dims.UR5_READY_Q)
    T_high[:3, 3] = [1.5, -0.3, TABLE_TOP + 0.15]
    q_high = ik_tcp(T_high, dims.UR5_READY_Q)[0]
    assert b.run(timed(np.stack([robot.joint_state().q, q_high]), b.settings.motion), "") is None


def test_the_way_back_after_a_protective_stop_keeps_the_carrying_limits(robot):
    """Holding something, the arm goes back the way it came no faster than it carries: the
    hand turns no faster than the carrying turn cap."""
    b, move = _through_the_table(robot)
    ran: list[Trajectory] = []
    execute = robot.execute
    robot.execute = lambda traj: ran.append(traj) or execute(traj)
    b.held = object()  # only whether the hand holds something matters here
    failure = b.run(move, "carrying")
    assert failure is not None and failure.message.endswith("stopped and backed away.")
    way_back = ran[-1]
    limits = motion_limits(b.settings.motion, carrying=True)
    assert excess(way_back.q, way_back.times[1], limits)["turn_speed"] <= 1.001


def test_the_scooter_stops_when_it_drives_the_still_arm_into_something(robot):
    """The arm holds still with the hand low before the table's front edge, and the user
    drives at it, the stick held: the scooter stops each time it pushes the arm harder than
    the protective stop's limit, and the arm is not bent back (with no such stop, the drive
    pressed the fingers into the table at 320-780 N). Backing away, which eases the push, is
    not stopped."""
    for _ in range(15):  # back 30 cm, to have the hand low before the table's edge
        robot.drive(-0.2, 0.0, 0.2)
        robot.sleep(0.1)
    robot.sleep(1.0)
    b = Behaviours(robot)
    assert b.go_ready().ok
    T = tcp_pose(dims.UR5_READY_Q)
    T[:3, 3] = [1.45, -0.3, TABLE_TOP - 0.02]  # `base`: under the top, before its edge
    q = ik_tcp(T, dims.UR5_READY_Q)[0]
    assert b.run(timed(np.stack([robot.joint_state().q, q]), b.settings.motion), "") is None
    x0 = robot.base_pose()[0]
    gap = TABLE_FRONT - (x0 + 1.45)  # m from the TCP to the table's front edge
    sim = robot.sim
    pushed = []
    for _ in range(30):  # 3 s at 0.2 m/s
        robot.drive(0.2, 0.0, 0.2)
        robot.sleep(0.1)
        pushed.append(sim.call(lambda m, d: sim.felt(sim.arm_contacts())))
    moved = robot.base_pose()[0] - x0
    assert moved > gap - 0.08 and max(pushed) > 50, "the hand reached the table"
    assert max(pushed) < 1.2 * dims.UR5_PROTECTIVE_STOP_FORCE, f"pushed {max(pushed):.0f} N"
    assert np.abs(robot.joint_state().q - q).max() < 0.08, "the arm was not bent back"
    said = sim.snapshot().drive_stop  # what the consoles show
    assert said.startswith(DRIVE_STOP) and " met " in said, said
    x1 = robot.base_pose()[0]
    for _ in range(10):
        robot.drive(-0.2, 0.0, 0.2)
        robot.sleep(0.1)
    assert robot.base_pose()[0] < x1 - 0.1, "it backs away from the table"
    assert sim.snapshot().drive_stop == "", "driven freely, the notice is taken down"


def test_a_motion_waits_for_the_arm_to_reach_its_start(robot):
    """A trajectory sent while the arm still lags behind the end of the last one is not
    refused for starting away from the arm: the behaviour lets the arm catch up first."""
    b = Behaviours(robot)
    assert b.go_ready().ok
    q0 = robot.joint_state().q
    q1 = q0 + np.array([0.3, 0.0, 0.0, 0.0, 0.0, 0.0])
    first = timed(np.array([q0, q1]), b.settings.motion)
    robot.execute(first)  # not waited for: the arm is still near q0
    robot.sleep(0.05)
    assert np.abs(robot.joint_state().q - q1).max() > 0.05
    second = timed(np.array([q1, q0]), b.settings.motion)
    assert b.run(second, "returning") is None
    assert np.abs(robot.joint_state().q - q0).max() < 0.02


def test_a_motion_whose_start_the_arm_does_not_reach_fails_saying_so(robot):
    """An arm held back short of a motion's start (by contact, say) is not sent a motion the
    controller would refuse with a message no user can read."""
    b = Behaviours(robot)
    assert b.go_ready().ok
    q0 = robot.joint_state().q
    elsewhere = q0 + np.array([0.3, 0.0, 0.0, 0.0, 0.0, 0.0])  # nothing takes the arm there
    failure = b.run(timed(np.array([elsewhere, q0]), b.settings.motion), "approaching")
    assert failure is not None and failure.kind == "execute"
    assert "stopped short of where approaching starts" in failure.message
    assert np.abs(robot.joint_state().q - q0).max() < 0.02, "the arm stays where it was"


def test_before_a_counter_above_the_ready_hand_the_arm_goes_to_the_high_ready_pose(robot):
    """A cloud with a counter top at 87 cm from 1.40 m on fills the ready pose's hand (TCP
    at 85 cm): going to ready goes to the high ready pose instead of finding no way."""
    xs, ys = np.meshgrid(np.arange(1.40, 1.90, 0.01), np.arange(-0.6, 0.2, 0.01))
    top = np.c_[xs.ravel(), ys.ravel(), np.full(xs.size, 0.87)]
    checker = CollisionChecker(top)
    assert not checker.clearance_ok(dims.UR5_READY_Q)[0]
    b = Behaviours(robot)
    assert b.go_ready(checker).ok
    assert np.abs(robot.joint_state().q - dims.UR5_HIGH_READY_Q).max() < 0.05


def test_with_both_ready_poses_filled_the_arm_stows_by_a_search(robot):
    """A table top at 1.06 m fills both ready poses' hands (the place on the 108 cm high
    table has just let go, its hand above it): the stow folds the arm away from where it
    is instead of finding no way."""
    top = table(1.06, x=(1.35, 1.95), y=(-0.6, 0.0))
    checker = CollisionChecker(top)
    assert not checker.clearance_ok(dims.UR5_READY_Q)[0]
    assert not checker.clearance_ok(dims.UR5_HIGH_READY_Q)[0]
    # The hand 6 cm above the top, the elbow up and the shoulder turned forward, as it
    # rests after letting go there.
    solutions = ik_tcp(top_down(1.55, -0.30, 1.12), dims.UR5_HIGH_READY_Q)
    above = next(q for q in solutions if abs(q[0]) < 1.0 and checker.clearance_ok(q)[0])
    b = Behaviours(robot)
    assert b.go_to(above, CollisionChecker(np.zeros((0, 3))), "setting up").ok
    out = b.stow(checker)
    assert out.ok, out.failure
    assert np.abs(robot.joint_state().q - dims.UR5_HOME_Q).max() < 0.05
