"""Carrying what the hand holds: rising clear of what is around it without bringing the arm
near anything, and tucking it in with the wrist turned where it must be."""

from __future__ import annotations

import numpy as np
import pytest
from arm_setups import isolation_robot, pick_object

from laserpick.behaviours import Behaviours, Held
from laserpick.description import dims
from laserpick.description.kinematics import tcp_pose
from laserpick.description.shapes import body_frames
from laserpick.pipeline.collision import SPHERES, CollisionChecker, sphere_centres
from laserpick.types import Grasp, Trajectory


@pytest.fixture
def robot():
    yield from isolation_robot()


def test_a_held_object_still_touching_its_surroundings_is_raised_before_the_tuck(robot):
    """Just after the lift, the held object may still touch parts of itself the segmentation
    left in the cloud: no path can start there, and the tuck would find "no way for
    raising". It rises clear first, as the carry to the basket does."""
    b, _ = pick_object(robot, "mug_1", from_above=True)
    assert b.held is not None
    T = tcp_pose(robot.joint_state().q)
    held = b.held.points_tcp @ T[:3, :3].T + T[:3, 3]
    low = held[held[:, 2] < held[:, 2].min() + 0.02]
    middle = held.mean(axis=0)
    outward = (low[:, :2] - middle[:2]) / np.linalg.norm(low[:, :2] - middle[:2], axis=1)[:, None]
    ring = np.c_[low[:, :2] + 0.015 * outward, low[:, 2]]  # 1.5 cm out from its foot
    b.held.surroundings = CollisionChecker(ring, voxel=0.0)
    assert not b.held.surroundings.clearance_ok(robot.joint_state().q, payload=b.held.points_tcp)[0]
    z0 = T[2, 3]
    lifted: list[float] = []
    run = b.run

    def recording(traj: Trajectory, what: str):
        if what == "lifting clear":
            lifted.append(float(tcp_pose(traj.q[-1])[2, 3] - z0))
        return run(traj, what)

    b.run = recording  # type: ignore[method-assign]
    out = b.tuck()
    assert out.ok, out.failure
    assert lifted and lifted[0] > 0.04, "it rose clear first"
    assert robot.gripper_state().holding


def test_a_rise_stops_before_the_arm_comes_near_anything(robot):
    """Rising clear of what the held object touches must not bring the arm itself near
    something else: a level hand raised swings its elbow back into the tiller and the sensor
    posts, and no carry can leave from there. The surroundings here (a stand-in checker)
    always block the held object, and block the arm 8 cm above where the hand is: one 5 cm
    step is taken, not a second."""
    b, _ = pick_object(robot, "mug_1")
    assert b.held is not None
    z0 = tcp_pose(robot.joint_state().q)[2, 3]

    class Surroundings(CollisionChecker):
        def clearance_ok(self, Q, *, payload=None, **kw):
            z = tcp_pose(np.atleast_2d(Q))[:, 2, 3]
            return np.zeros(len(z), bool) if payload is not None else z < z0 + 0.08

    b.held.surroundings = Surroundings(np.zeros((0, 3)))
    rises: list[np.ndarray] = []
    run = b.run

    def recording(traj: Trajectory, what: str):
        if what == "lifting clear":
            rises.append(traj.q)
        return run(traj, what)

    b.run = recording  # type: ignore[method-assign]
    assert b.rise_clear(b.held.surroundings, b.held.points_tcp) is None
    assert len(rises) == 1, "one step, not the one that brings the arm near something"
    assert tcp_pose(robot.joint_state().q)[2, 3] - z0 == pytest.approx(0.05, abs=0.01)


def test_a_rise_that_straight_up_would_bring_the_arm_near_something_reaches_out(robot):
    """A hand close before the arm's mount, raised straight, swings the elbow back into the
    sensor posts. The stand-in surroundings block the arm above 3 cm over the hand unless
    it reaches out too, and the held object until it is 4 cm up: the rise takes one step,
    up and out, and ends clear. Where that step would not bring the object clear (out of a
    shelf's gap, deeper in), it is not taken."""
    b, _ = pick_object(robot, "mug_1")
    assert b.held is not None
    T0 = tcp_pose(robot.joint_state().q)
    out = T0[:2, 3] - dims.ARM_MOUNT_POS[:2]
    out /= np.linalg.norm(out)

    class Surroundings(CollisionChecker):
        def clearance_ok(self, Q, *, payload=None, **kw):
            T = tcp_pose(np.atleast_2d(Q))
            up = T[:, 2, 3] - T0[2, 3]
            reached = (T[:, :2, 3] - T0[:2, 3]) @ out
            if payload is not None:
                return up > 0.04
            return (up < 0.03) | (reached > 0.5 * up)

    class Shelf(Surroundings):
        def clearance_ok(self, Q, *, payload=None, **kw):
            if payload is not None:  # a step out would carry the object deeper in
                return np.zeros(len(np.atleast_2d(Q)), bool)
            return super().clearance_ok(Q, **kw)

    assert b.rise_clear(Shelf(np.zeros((0, 3))), b.held.points_tcp) is None
    assert np.allclose(tcp_pose(robot.joint_state().q)[:3, 3], T0[:3, 3], atol=0.005)
    surroundings = Surroundings(np.zeros((0, 3)))
    assert b.rise_clear(surroundings, b.held.points_tcp) is None
    T = tcp_pose(robot.joint_state().q)
    assert T[2, 3] - T0[2, 3] == pytest.approx(0.05, abs=0.01)
    assert (T[:2, 3] - T0[:2, 3]) @ out == pytest.approx(0.05, abs=0.01)
    assert surroundings.clearance_ok(robot.joint_state().q, payload=b.held.points_tcp)[0]


def test_an_open_hand_among_what_it_let_go_of_rises_clear_before_it_stows(robot):
    """After a place whose lowering a touch stopped short, the straight rise back leaves the
    open hand about the object's top, and no stow can start there ("Set down; then no
    collision-free path was found"). The hand rises until it is
    clear, even though it starts among the object's points, touching them (a hand that only
    comes within the margin of them rises as any arm does, see the next test)."""
    b = Behaviours(robot)
    assert b.go_ready().ok
    T = tcp_pose(robot.joint_state().q)
    # The object's top, 4 cm across, between the open fingers at the TCP's height, where
    # the palm's lowest sphere reaches.
    xs = np.linspace(-0.02, 0.02, 5)
    top = np.array([[T[0, 3] + x, T[1, 3] + y, T[2, 3]] for x in xs for y in xs])
    standing = CollisionChecker(top, voxel=0.0)
    assert standing.clearance_kept(robot.joint_state().q) is None
    assert b.rise_clear(standing) is None  # the hand may not pass through the points: stays
    assert tcp_pose(robot.joint_state().q)[2, 3] == pytest.approx(T[2, 3], abs=0.005)
    assert b.rise_clear(standing, hand_on_the_way=False) is None
    assert standing.clearance_ok(robot.joint_state().q)[0]
    assert tcp_pose(robot.joint_state().q)[2, 3] > T[2, 3] + 0.04


def test_an_open_hand_rising_off_what_it_let_go_of_keeps_clear_of_all_else(robot):
    """Let go of a tall can over the basket, the hand rises among the can's points, which it
    may pass; but not into what stands beside its way up (the projector's post): unchecked,
    it rose into the post, and no way to ready or to the stowed pose could start there. A
    post's edge 7 cm beside the hand's axis, from 7 cm above the TCP up, clear of the wrist
    as it rises but not of the housing: the hand does not rise into it."""
    b = Behaviours(robot)
    assert b.go_ready().ok
    q0 = robot.joint_state().q
    T = tcp_pose(q0)
    xs = np.linspace(-0.02, 0.02, 5)
    top = np.array([[T[0, 3] + x, T[1, 3] + y, T[2, 3]] for x in xs for y in xs])
    heights = np.arange(0.07, 0.36, 0.01)
    post = np.array([[T[0, 3] + x, T[1, 3] + 0.07, T[2, 3] + z] for x in xs / 2 for z in heights])
    beside = CollisionChecker(post, voxel=0.0)
    around = CollisionChecker(np.vstack([top, post]), voxel=0.0)
    assert beside.clearance_ok(q0)[0] and not around.clearance_ok(q0)[0]
    assert b.rise_clear(around, hand_on_the_way=beside) is None
    assert beside.clearance_ok(robot.joint_state().q)[0], "the hand kept clear of the post"
    # With the post 5 cm higher, it rises one step, through the can's top, and is clear.
    higher = CollisionChecker(post + [0.0, 0.0, 0.05], voxel=0.0)
    assert (
        b.rise_clear(
            CollisionChecker(np.vstack([top, higher.points]), voxel=0.0), hand_on_the_way=higher
        )
        is None
    )
    q = robot.joint_state().q
    assert tcp_pose(q)[2, 3] - T[2, 3] == pytest.approx(0.05, abs=0.01)
    assert higher.clearance_ok(q)[0] and CollisionChecker(top, voxel=0.0).clearance_ok(q)[0]
    assert b.go_ready().ok
    # Unchecked, the same rise runs the hand into it.
    assert b.rise_clear(around, hand_on_the_way=False) is None
    q = robot.joint_state().q
    assert not beside.clearance_ok(q)[0] and beside.clearance_ok(q, hand=False)[0]


def test_an_arm_let_down_within_the_margin_of_a_surface_rises_away_from_it(robot):
    """A place may let the forearm down nearer a surface than the margin (it must only not
    reach into the support): set down on the 31 cm table, a cereal box leaves it 4 mm above
    the top, and a rise held to the full margin cannot leave, the arm left out over the
    surface. A patch of surface 4 mm under the middle of the forearm: the arm rises, keeping
    at least those 4 mm, and ends clear."""
    b = Behaviours(robot)
    assert b.go_ready().ok
    q0 = robot.joint_state().q
    forearm = np.flatnonzero(~SPHERES.hand & (SPHERES.body == 2))
    middle = forearm[len(forearm) // 2]
    centre = sphere_centres(body_frames(q0))[0, middle]
    under = centre - [0.0, 0.0, SPHERES.radius[middle] + 0.004]
    patch = under + np.array([[dx, dy, 0.0] for dx in (-0.01, 0, 0.01) for dy in (-0.01, 0, 0.01)])
    top = CollisionChecker(patch, voxel=0.0, margin=0.01)
    assert not top.clearance_ok(q0)[0]
    assert top.clearance_kept(q0) == pytest.approx(0.004, abs=0.001)
    assert b.rise_clear(top) is None
    q = robot.joint_state().q
    assert top.clearance_ok(q)[0]
    assert tcp_pose(q)[2, 3] - tcp_pose(q0)[2, 3] == pytest.approx(0.05, abs=0.01)


def test_an_object_held_by_one_end_is_tucked_in_with_the_hand_turned_away_from_the_arm(robot):
    """A banana held 8 cm off its middle reaches 19 cm back along the hand: at the carry
    pose, and raised in front, it would come within the margin of the upper arm. The last
    wrist joint turns it the other way, and the arm tucks it in (unturned, no goal is
    clear, and the arm keeps it where it lifted it)."""
    b = Behaviours(robot)
    assert b.go_ready().ok
    rod = np.mgrid[-0.19:0.021:0.01, -0.02:0.021:0.01, -0.02:0.011:0.01].reshape(3, -1).T
    free = CollisionChecker(np.zeros((0, 3)))
    assert not free.clearance_ok(dims.UR5_CARRY_Q, payload=rod)[0]
    assert not free.clearance_ok(dims.UR5_HIGH_READY_Q, payload=rod)[0]
    middle = (rod.min(axis=0) + rod.max(axis=0)) / 2
    grasp = Grasp(pose=tcp_pose(b.current_q()), width=0.03, ik=b.current_q())
    b.held = Held(grasp, 0.02, rod, middle, free)
    out = b.tuck()
    assert out.ok, out.failure
    q = robot.joint_state().q
    assert np.allclose(q[:5], dims.UR5_CARRY_Q[:5], atol=0.02)
    assert abs(q[5] - dims.UR5_CARRY_Q[5]) > 1.0  # turned
    assert free.clearance_ok(q, payload=rod)[0]
