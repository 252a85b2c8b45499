"""The reachability filter and the planners (004 section 7)."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest
from arm_poses import EMPTY, table, top_grasp
from pydantic import ValidationError

from laserpick.description import dims
from laserpick.description.kinematics import ik_tcp, tcp_pose
from laserpick.description.shapes import body_frames
from laserpick.pipeline import joint_search, rrt
from laserpick.pipeline.collision import (
    SPHERES,
    CollisionChecker,
    held_clear_of_arm,
    sphere_centres,
)
from laserpick.pipeline.joint_search import Searches, joint_path
from laserpick.pipeline.lines import TURN_STEP, cartesian_line
from laserpick.pipeline.pick_prep import straight_lift
from laserpick.pipeline.plan import plan_pick, transit_path
from laserpick.pipeline.plan_record import load_search
from laserpick.pipeline.reach import pregrasp_pose, reachable
from laserpick.pipeline.rrt import shortcut
from laserpick.settings import MotionSettings, get_settings
from laserpick.transforms import rotation_angle, rotx
from laserpick.types import Failure, Grasp


def test_filter_keeps_reachable_grasps_and_says_why_it_drops_others():
    checker = CollisionChecker(table())
    ok = Grasp(top_grasp(1.5, -0.3, 0.52), 0.05)
    far = Grasp(top_grasp(2.6, 0.0, 0.52), 0.05)
    # A grasp whose pre-grasp lies inside a box of points.
    wall_x = np.arange(1.55, 1.75, 0.01)
    wall = np.array([[x, y, z] for x in wall_x for y in (-0.1, 0.0) for z in (0.62, 0.66)])
    walled = Grasp(top_grasp(1.65, -0.05, 0.52), 0.05)
    checker = CollisionChecker(np.vstack([table(), wall]), voxel=0.0)
    out = reachable([ok, far, walled], checker, dims.UR5_READY_Q)
    assert out[0].ik is not None and out[0].ik_failure is None
    assert np.allclose(tcp_pose(out[0].ik)[:3, 3], ok.position, atol=1e-6)
    assert out[1].ik is None and "cannot reach" in out[1].ik_failure
    assert out[2].ik is None and "collides" in out[2].ik_failure


def test_filter_swaps_the_fingers_when_that_turns_the_wrist_less():
    q_ref = dims.UR5_READY_Q
    yaw = np.pi  # the ready pose's hand turned by a half turn
    T = tcp_pose(q_ref) @ np.diag([-1.0, -1.0, 1.0, 1.0])
    out = reachable([Grasp(T, 0.05)], CollisionChecker(EMPTY), q_ref)[0]
    assert out.ik is not None
    assert abs(out.ik[5] - q_ref[5]) < 1e-6, "swapped fingers need no wrist turn"
    assert np.allclose(out.pose[:3, 0], -T[:3, 0]) and yaw


def test_filter_drops_a_grasp_under_a_board_the_arm_could_not_lift_it_from():
    """A side grasp under a board: clear at the grasp and at the pre-grasp behind it, but the
    wrist would come within the margin of the board as the hand lifts the least lift. Such a
    grasp is one the hand could close on and never raise, so the filter drops it, saying so;
    a board higher up leaves it."""
    s = get_settings().motion
    T = np.eye(4)
    T[:3, :3] = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])  # approach +x
    T[:3, 3] = [1.7, -0.25, 0.70]
    q = reachable([Grasp(T, 0.05)], CollisionChecker(EMPTY), dims.UR5_READY_Q)[0].ik
    assert q is not None
    # The board is a patch over the hand and wrist, 35 cm by 30 cm, short of the elbow.
    lo, hi = np.array([1.5, -0.4]), np.array([1.85, -0.1])

    def top(pose: np.ndarray, hand: bool) -> float:
        """The highest point under the patch of the arm's spheres, with the hand's or not."""
        centres = sphere_centres(body_frames(ik_tcp(pose, q)[0]))[0]
        r = SPHERES.radius
        under = np.all((centres[:, :2] > lo - r[:, None]) & (centres[:, :2] < hi + r[:, None]), 1)
        under &= hand | ~SPHERES.hand
        return float((centres[under, 2] + r[under]).max())

    pre = T.copy()
    pre[:3, 3] -= s.approach_distance * T[:3, 2]
    up = T.copy()
    up[2, 3] += s.lift_least
    below = max(top(T, False), top(pre, True))
    assert top(up, False) > below + 0.02

    def kept(board_z: float, lift: float) -> Grasp:
        board = table(z=board_z, x=(lo[0], hi[0]), y=(lo[1], hi[1]))
        checker = CollisionChecker(board, margin=s.clearance, voxel=0.0)
        return reachable([Grasp(T, 0.05)], checker, dims.UR5_READY_Q, lift=lift)[0]

    low = below + s.clearance + 0.01
    assert kept(low, 0.0).ik is not None  # the board is clear of the grasp and the pre-grasp
    refused = kept(low, s.lift_least)
    assert refused.ik is None and "as it lifts" in refused.ik_failure
    assert kept(top(up, False) + s.clearance + 0.005, s.lift_least).ik is not None


def test_cartesian_line_is_straight():
    q0 = dims.UR5_READY_Q
    T0 = tcp_pose(q0)
    T1 = T0.copy()
    T1[:3, 3] += [0.05, 0.1, -0.25]
    path = cartesian_line(q0, T1, 0.01)
    assert path is not None
    p = tcp_pose(path)[:, :3, 3]
    d = (T1[:3, 3] - T0[:3, 3]) / np.linalg.norm(T1[:3, 3] - T0[:3, 3])
    off = (p - T0[:3, 3]) - np.outer((p - T0[:3, 3]) @ d, d)
    assert np.linalg.norm(off, axis=1).max() < 1e-3
    assert np.allclose(tcp_pose(path[-1]), T1, atol=1e-6)


def test_a_hand_turned_about_its_tcp_turns_in_steps_and_stays_there():
    """A line that only turns the hand (30 deg about its TCP, moving nowhere) is followed in
    steps of at most `TURN_STEP`: in one step, the IK's jump refused it."""
    q0 = ik_tcp(top_grasp(1.0, 0.0, 0.95), dims.UR5_READY_Q)[0]
    T0 = tcp_pose(q0)
    T1 = T0.copy()
    T1[:3, :3] = rotx(np.radians(30)) @ T0[:3, :3]
    path = cartesian_line(q0, T1, 0.01)
    assert path is not None
    T = tcp_pose(path)
    steps = [rotation_angle(a[:3, :3], b[:3, :3]) for a, b in itertools.pairwise(T)]
    assert max(steps) <= TURN_STEP + 1e-9
    assert np.abs(T[:, :3, 3] - T0[:3, 3]).max() < 1e-6
    assert np.allclose(T[-1], T1, atol=1e-6)


def _wall_between() -> tuple[np.ndarray, np.ndarray, CollisionChecker]:
    """Two hands over the table with a wall of points between them, from the table up to
    0.8 m: both ends clear, the straight joint move through the wall."""
    q0 = ik_tcp(top_grasp(1.6, -0.5, 0.65), dims.UR5_READY_Q)[0]
    q1 = ik_tcp(top_grasp(1.6, 0.1, 0.65), dims.UR5_READY_Q)[0]
    wall = np.array(
        [[x, -0.2, z] for x in np.arange(1.45, 1.75, 0.02) for z in np.arange(0.46, 0.8, 0.02)]
    )
    return q0, q1, CollisionChecker(np.vstack([table(), wall]), voxel=0.0)


def _mould(q_in: np.ndarray, q_out: np.ndarray, gap: float = 0.01) -> np.ndarray:
    """Points (m, `base`) on spheres `gap` beyond the clearance of each of the arm's spheres
    at q_in (rad), every 1.5 cm, less those within half the gap of the arm at q_in or at
    q_out: a mould the arm stands clear in at q_in, and cannot leave."""
    margin, spacing = CollisionChecker(EMPTY).margin, 0.015
    inside = sphere_centres(body_frames(q_in))[0]
    outside = sphere_centres(body_frames(q_out))[0]
    shells = []
    for c, r in zip(inside, SPHERES.radius, strict=True):
        R = r + margin + gap
        k = np.arange(max(20, int(4 * np.pi * R * R / spacing**2))) + 0.5  # a Fibonacci sphere
        polar, around = np.arccos(1 - 2 * k / len(k)), np.pi * (1 + 5**0.5) * k
        ray = np.c_[np.cos(around) * np.sin(polar), np.sin(around) * np.sin(polar), np.cos(polar)]
        shells.append(c + R * ray)
    points = np.vstack(shells)
    for centres in (inside, outside):
        d = np.linalg.norm(points[:, None] - centres[None], axis=2)
        points = points[(d > SPHERES.radius + margin + gap / 2).all(axis=1)]
    return points


@pytest.mark.parametrize("planner", ["ompl", "ours"])
def test_joint_path_goes_around_a_wall_and_every_step_is_clear(planner):
    q0, q1, checker = _wall_between()
    assert checker.clearance_ok(np.stack([q0, q1])).all()
    assert not checker.segment_ok(q0, q1)
    s = get_settings().motion.model_copy(update={"planner": planner})
    for seed in range(3):
        path = joint_path(q0, q1, checker, np.random.default_rng(seed), s)
        assert path is not None and len(path) > 2
        assert np.array_equal(path[0], q0) and np.array_equal(path[-1], q1)
        assert all(checker.segment_ok(a, b) for a, b in itertools.pairwise(path))
        again = joint_path(q0, q1, checker, np.random.default_rng(seed), s)
        assert np.array_equal(path, again), "the same seed gives the same path"


def test_a_path_is_clear_where_every_configuration_of_it_is():
    """`path_clear` (coarse configurations first, stopping at the first blocked one) says
    what `clearance_ok` of every configuration says, on paths across the wall and beside it."""
    q0, q1, checker = _wall_between()
    rng = np.random.default_rng(3)
    verdicts = set()
    for _ in range(40):
        a, b = (q + rng.normal(0.0, 0.3, 6) for q in (q0, q1))
        Q = np.linspace(a, b, int(rng.integers(2, 60)))
        every = bool(checker.clearance_ok(Q).all())
        assert checker.path_clear(Q) == every
        verdicts.add(every)
    assert verdicts == {True, False}


def test_a_picks_way_is_searched_with_the_pick_planner_and_other_ways_with_the_planner(
    monkeypatch,
):
    """The legs of a pick's transit (`Searches.path`) go to `pick_planner`; a search asked
    of `joint_path` alone (a carry's, a stow's) to `planner`."""
    q0, q1, checker = _wall_between()
    used: list[str] = []
    search = joint_search._search
    monkeypatch.setattr(joint_search, "_search", lambda *a: used.append(a[5]) or search(*a))
    s = get_settings().motion.model_copy(update={"pick_planner": "ompl", "planner": "ours"})
    rng = np.random.default_rng(0)
    assert Searches(max_failed=6).path(q0, q1, checker, rng, s, seen=False) is not None
    assert joint_path(q0, q1, checker, rng, s) is not None
    assert used == ["ompl", "ours"]


@pytest.mark.parametrize("planner", ["ompl", "ours"])
def test_joint_path_says_none_where_the_goal_is_walled_in(planner):
    """The arm at the goal stands clear inside a mould of points that leaves it no way out:
    the search runs (both ends clear, the straight move blocked) and finds nothing."""
    goal = ik_tcp(top_grasp(1.6, -0.5, 0.65), dims.UR5_READY_Q)[0]
    start = goal + np.array([1.2, 0, 0, 0, 0, 0])  # the base turned away
    checker = CollisionChecker(_mould(goal, start), voxel=0.0)
    assert checker.clearance_ok(np.stack([start, goal])).all()
    assert not checker.segment_ok(start, goal)
    s = get_settings().motion.model_copy(update={"planner": planner, "rrt_max_samples": 200})
    assert joint_path(start, goal, checker, np.random.default_rng(0), s) is None
    # Without the mould the same move is the straight one.
    open_space = CollisionChecker(EMPTY)
    assert len(joint_path(start, goal, open_space, np.random.default_rng(0), s)) == 2


def test_a_search_toward_several_goals_ends_at_one_it_reaches():
    """Of two goals, the first walled in, ours grows toward both at once and ends at the
    other. With either planner, a goal the arm cannot stand at is left out and the search
    goes to the next; where a later goal has a straight move and the first has none, the
    move is that straight one."""
    walled = ik_tcp(top_grasp(1.6, -0.5, 0.65), dims.UR5_READY_Q)[0]
    start = walled + np.array([1.2, 0, 0, 0, 0, 0])
    other = start + np.array([0, 0, 0, 0, 0.6, 0.8])
    checker = CollisionChecker(_mould(walled, start), voxel=0.0)
    assert checker.clearance_ok(np.stack([start, walled, other])).all()
    found = rrt.rrt_connect(
        start, np.stack([walled, other]), checker, np.random.default_rng(0), max_samples=300
    )
    assert found is not None and len(found) > 2, "a search, not the straight move"
    assert np.array_equal(found[0], start) and np.array_equal(found[-1], other)
    assert all(checker.segment_ok(a, b) for a, b in itertools.pairwise(found))
    q0, q1, wall = _wall_between()
    in_the_wall = ik_tcp(top_grasp(1.6, -0.2, 0.6), dims.UR5_READY_Q)[0]
    assert not wall.clearance_ok(in_the_wall)[0] and not wall.segment_ok(q0, q1)
    for planner in ("ours", "ompl"):
        s = get_settings().motion.model_copy(update={"planner": planner})
        path = joint_path(q0, np.stack([in_the_wall, q1]), wall, np.random.default_rng(0), s)
        assert path is not None and len(path) > 2 and np.array_equal(path[-1], q1)
        assert all(wall.segment_ok(a, b) for a, b in itertools.pairwise(path))
    beside = ik_tcp(top_grasp(1.6, -0.5, 0.85), dims.UR5_READY_Q)[0]
    assert wall.segment_ok(q0, beside)
    path = joint_path(q0, np.stack([q1, beside]), wall, np.random.default_rng(0), s)
    assert np.array_equal(path, np.stack([q0, beside]))


def test_a_search_grown_in_parts_draws_and_finds_as_one_grown_at_once():
    q0, q1, checker = _wall_between()
    whole = rrt.rrt_connect(q0, q1, checker, np.random.default_rng(3), max_samples=2000)
    search = rrt.ConnectSearch(q0, q1, checker, np.random.default_rng(3))
    assert search.grow(2) is None and search.samples == 2
    parts = search.grow(2000)
    assert whole is not None and parts is not None and np.array_equal(whole, parts)


def test_a_tree_in_a_pocket_steps_out_with_shorter_steps():
    """A cereal box's carry recorded in `isolation` (seed 8): held by its top, the box hangs
    low in the basket at the goal, where 0 of 64 full steps are clear. The goal's tree steps
    out with quarter steps (`rrt.POCKET_TRAPS`) and the search ends; with full steps only,
    it spends every sample."""
    q0, q1, checker, kw = load_search(Path(__file__).parent / "data" / "cereal_box_carry.npz")
    s = get_settings().motion
    found = rrt.rrt_connect(q0, q1, checker, np.random.default_rng(0), step=s.rrt_step, **kw)
    assert found is not None
    assert all(checker.segment_ok(a, b, **kw) for a, b in itertools.pairwise(found))
    rng = np.random.default_rng(0)
    assert rrt.rrt_connect(q0, q1, checker, rng, step=s.rrt_step, pocket_traps=None, **kw) is None


def test_shortcut_does_not_check_a_blocked_join_twice():
    """Once the only joins left are blocked, the shortcut stops: it spent its 60 tries
    re-checking one blocked join of a three-point path (170 ms of a 220 ms plan)."""
    q0, q1, checker = _wall_between()
    mid = ik_tcp(top_grasp(1.6, -0.2, 0.95), dims.UR5_READY_Q)[0]
    assert not checker.segment_ok(q0, q1)
    calls: list[tuple[bytes, bytes]] = []
    segment_ok = checker.segment_ok

    def counting(a, b, **kw):
        calls.append((a.tobytes(), b.tobytes()))
        return segment_ok(a, b, **kw)

    checker.segment_ok = counting  # type: ignore[method-assign]
    path = np.array([q0, mid, q1])
    short = shortcut(path, checker, np.random.default_rng(0))
    assert np.array_equal(short, path)
    assert len(calls) == 1


def test_joint_path_from_a_blocked_start_gives_up_without_searching():
    """A start inside an obstacle can never be left: the search is not run (it spent all of
    its 2000 samples, 12 s, on a held can guessed into the forearm)."""
    q0 = ik_tcp(top_grasp(1.6, -0.5, 0.40), dims.UR5_READY_Q)[0]  # the hand in the table
    q1 = ik_tcp(top_grasp(1.6, 0.1, 0.65), dims.UR5_READY_Q)[0]
    checker = CollisionChecker(table(), voxel=0.0)
    assert not checker.clearance_ok(q0)[0] and checker.clearance_ok(q1)[0]
    checked: list[int] = []
    clearance_ok = checker.clearance_ok

    def counting(Q, **kw):
        checked.append(len(np.atleast_2d(Q)))
        return clearance_ok(Q, **kw)

    checker.clearance_ok = counting  # type: ignore[method-assign]
    assert joint_path(q0, q1, checker, np.random.default_rng(0), get_settings().motion) is None
    assert len(checked) == 2, "the straight segment and the ends, no search"


def test_plan_pick_approaches_straight_and_lifts_within_the_limits():
    s = get_settings().motion
    world = CollisionChecker(table())
    T = top_grasp(1.55, -0.25, 0.50, yaw=0.4)
    q_grasp = ik_tcp(T, dims.UR5_READY_Q)[0]
    plan = plan_pick(
        dims.UR5_HOME_Q, q_grasp, world, world, np.random.default_rng(0), s, via=(dims.UR5_READY_Q,)
    )
    assert not isinstance(plan, Failure), plan
    assert np.allclose(plan.transit.q[0], dims.UR5_HOME_Q)
    assert np.allclose(plan.transit.q[-1], plan.approach.q[0])
    # The approach ends at the grasp, coming straight down the approach axis.
    start, end = tcp_pose(plan.approach.q[[0, -1]])
    assert np.allclose(end, T, atol=1e-6)
    assert np.allclose(start[:3, 3] - end[:3, 3], [0, 0, s.approach_distance], atol=1e-6)
    top = tcp_pose(plan.lift.q[-1])[:3, 3]
    assert np.isclose(top[2] - T[2, 3], s.lift, atol=1e-6)
    for traj in (plan.transit, plan.approach, plan.regrip, plan.lift):
        qd = np.diff(traj.q, axis=0) / np.diff(traj.times)[:, None]
        assert np.abs(qd).max() <= s.joint_speed * 1.02
    for traj, speed in ((plan.approach, s.approach_speed), (plan.regrip, s.approach_speed)):
        tcp = tcp_pose(traj.q)[:, :3, 3]
        v = np.linalg.norm(np.diff(tcp, axis=0), axis=1) / np.diff(traj.times)
        assert v.max() <= speed * 1.05
    tcp = tcp_pose(plan.lift.q)[:, :3, 3]
    v = np.linalg.norm(np.diff(tcp, axis=0), axis=1) / np.diff(plan.lift.times)
    assert s.approach_speed < v.max() <= s.lift_speed * 1.05  # the lift at its own speed


def test_from_the_stowed_arm_the_transit_goes_out_through_the_unstow_pose():
    """Home, the unstow pose, ready, the pre-grasp: the way out of the stowed pose is the
    same straight move for every grasp, and it is left out where the cloud fills the
    unstow pose. The timed transit rounds its corners, within the checked blends' reach."""
    s = get_settings().motion
    world = CollisionChecker(table())
    q_grasp = ik_tcp(top_grasp(1.55, -0.25, 0.50, yaw=0.4), dims.UR5_READY_Q)[0]
    q_pre = ik_tcp(pregrasp_pose(tcp_pose(q_grasp), s.approach_distance), q_grasp)[0]
    home, unstow, ready = dims.UR5_HOME_Q, dims.UR5_UNSTOW_Q, dims.UR5_READY_Q
    rng = np.random.default_rng(0)
    route = transit_path(home, q_pre, world, rng, s, Searches(6), via=(ready,), unstow=unstow)
    assert route is not None
    waypoints, checks = route
    np.testing.assert_allclose(waypoints[:3], [home, unstow, ready])
    assert len(checks) == len(waypoints) - 1
    plan = plan_pick(home, q_grasp, world, world, rng, s, via=(ready,), unstow=unstow)
    assert not isinstance(plan, Failure), plan
    gap = [np.linalg.norm(plan.transit.q - q, axis=1) for q in (unstow, ready)]
    passed = [int(np.argmin(g)) for g in gap]
    assert max(g.min() for g in gap) <= s.blend_checked and passed[0] < passed[1]
    # A point where the unstow pose's wrist would be (something stands just ahead of the
    # scooter's corner).
    corner = body_frames(unstow)[0, 6, :3, 3]
    blocked = CollisionChecker(np.vstack([table(), corner[None]]), voxel=0.0)
    assert not blocked.clearance_ok(unstow)[0]
    plan = plan_pick(home, q_grasp, blocked, blocked, rng, s, via=(ready,), unstow=unstow)
    assert not isinstance(plan, Failure), plan
    assert np.abs(plan.transit.q - unstow).max(axis=1).min() > 0.05


def test_from_standing_by_the_transit_keeps_the_elbow_up_and_is_seconds_shorter():
    """Standing by between picks (`UR5_STANDBY_Q`) the arm is on the ready poses' elbow-up
    branch: the way to the grasp through ready does not turn the elbow over, as the way
    from the stowed pose must, and runs at least 2.5 s shorter at the same limits."""
    s = get_settings().motion
    world = CollisionChecker(table())
    q_grasp = ik_tcp(top_grasp(1.55, -0.25, 0.50, yaw=0.4), dims.UR5_READY_Q)[0]
    via = (dims.UR5_READY_Q,)
    rng = np.random.default_rng(0)
    home = plan_pick(
        dims.UR5_HOME_Q, q_grasp, world, world, rng, s, via=via, unstow=dims.UR5_UNSTOW_Q
    )
    standby = plan_pick(dims.UR5_STANDBY_Q, q_grasp, world, world, rng, s, via=via, standby=True)
    assert not isinstance(home, Failure) and not isinstance(standby, Failure), (home, standby)
    np.testing.assert_allclose(standby.transit.q[0], dims.UR5_STANDBY_Q)
    assert home.transit.q[:, 2].min() < -1.0, "from the stowed pose the elbow turns over"
    assert standby.transit.q[:, 2].min() > 0.3, "the elbow stays up"
    assert standby.transit.duration < home.transit.duration - 2.5


def test_a_grasp_on_the_other_elbow_branch_is_reached_without_a_wrist_turning_over():
    """A high side grasp whose IK, taken nearest the ready pose, is elbow down with the
    middle wrist at +4.6 rad: from standing by, the way out turns the elbow over at the unstow
    pose (that wrist at -1.57 rad), and the leg on to the grasp does not turn it back over
    by a full turn: the grasp is the same posture, the wrist at -1.65 rad."""
    s = get_settings().motion
    world = CollisionChecker(EMPTY)
    T = tcp_pose(np.array([-0.16, -0.6, -1.75, -0.52, -1.73, 1.52]))
    T[:3, 3] += 0.10 * T[:3, 2]
    q_grasp = next(q for q in ik_tcp(T, dims.UR5_READY_Q) if q[2] < 0 and q[4] > np.pi)
    plan = plan_pick(
        dims.UR5_STANDBY_Q,
        q_grasp,
        world,
        world,
        np.random.default_rng(0),
        s,
        via=(dims.UR5_READY_Q, dims.UR5_HIGH_READY_Q),
        standby=True,
        unstow=dims.UR5_STANDBY_EXIT_Q,
        turn=dims.UR5_UNSTOW_Q,
    )
    assert not isinstance(plan, Failure), plan
    np.testing.assert_allclose(tcp_pose(plan.q_grasp), T, atol=1e-6)
    assert plan.q_grasp[4] < 0
    # Standing by, the wrist is at +1.57 rad: down to the unstow pose's -1.57 and no farther.
    assert np.ptp(plan.transit.q[:, 4]) < np.pi + 0.2


def test_the_lift_keeps_what_the_hand_will_hold_off_the_forearm():
    """Far out over the 87 cm counter, the arm straightens as it lifts and its forearm comes
    down over the hand. A bowl 14 cm across held by its far rim would end the full lift
    under the forearm, where no way onward can start: the lift is the low one instead. Not
    holding it, the full lift is clear."""
    s = get_settings().motion
    q = np.array([-0.01, -1.27, 0.93, 1.77, 1.87, 1.66])  # a grasp from above, 1.57 m out
    T = tcp_pose(q)
    middle = T[:3, 3] + [-0.065, 0.0, 0.0]  # nearer the robot than the rim in the hand
    turn = np.linspace(0.0, 2 * np.pi, 24, endpoint=False)
    bowl = np.vstack(
        [
            np.c_[middle[0] + r * np.cos(turn), middle[1] + r * np.sin(turn), np.full(24, z)]
            for r in (0.04, 0.07)
            for z in T[2, 3] + np.arange(-0.04, 0.025, 0.02)
        ]
    )
    payload = Grasp(T, 0.01).in_hand(bowl)
    empty = CollisionChecker(EMPTY, margin=s.clearance)
    full = straight_lift(q, T, empty, s)
    assert full is not None
    assert tcp_pose(full[-1])[2, 3] - T[2, 3] == pytest.approx(s.lift, abs=1e-6)
    clear = held_clear_of_arm(full, payload, s.clearance)
    assert clear[0] and not clear[-1]
    held = straight_lift(q, T, empty, s, payload)
    assert held is not None
    assert tcp_pose(held[-1])[2, 3] - T[2, 3] == pytest.approx(s.lift_low, abs=1e-6)
    assert held_clear_of_arm(held, payload, s.clearance).all()


def test_under_a_board_the_lift_is_the_low_one_then_the_least_then_none():
    """A board above the arm that the full lift would reach leaves the low lift; one that
    the low lift would reach, the least; one that even the least would reach, none."""
    s = get_settings().motion
    T = top_grasp(1.55, -0.25, 0.70)
    q = ik_tcp(T, dims.UR5_READY_Q)[0]
    full = straight_lift(q, T, CollisionChecker(EMPTY), s)
    assert full is not None
    # The board is a patch above the hand, 20 cm across: over the wrist, not the elbow.
    centres = sphere_centres(body_frames(full))
    over = np.all(np.abs(centres[0, :, :2] - T[:2, 3]) < 0.1 + SPHERES.radius[:, None], axis=1)
    arm = ~SPHERES.hand & over
    rise = tcp_pose(full)[:, 2, 3] - T[2, 3]
    tops = (centres[:, arm, 2] + SPHERES.radius[arm]).max(axis=1)
    top_low = float(tops[rise <= s.lift_low + 1e-9].max())
    top_least = float(tops[rise <= s.lift_least + 1e-9].max())
    assert tops.max() > top_low + 0.02 and top_low > top_least + 0.006  # each rises higher

    def lifted(board_z: float) -> float | None:
        board = table(z=board_z, x=(T[0, 3] - 0.1, T[0, 3] + 0.1), y=(T[1, 3] - 0.1, T[1, 3] + 0.1))
        lift = straight_lift(q, T, CollisionChecker(board, margin=s.clearance), s)
        return None if lift is None else float(tcp_pose(lift[-1])[2, 3] - T[2, 3])

    assert lifted(float(tops.max()) + s.clearance + 0.01) == pytest.approx(s.lift, abs=1e-6)
    assert lifted(top_low + s.clearance + 0.005) == pytest.approx(s.lift_low, abs=1e-6)
    assert lifted(top_least + s.clearance + 0.002) == pytest.approx(s.lift_least, abs=1e-6)
    assert lifted(float(tops[0]) + s.clearance + 0.005) is None


def test_plan_pick_refuses_a_grasp_under_the_table():
    world = CollisionChecker(table())
    q = ik_tcp(top_grasp(1.55, -0.25, 0.40), dims.UR5_READY_Q)[0]
    plan = plan_pick(dims.UR5_READY_Q, q, world, world, np.random.default_rng(0))
    assert isinstance(plan, Failure) and plan.kind == "ik_plan"


def test_the_hand_may_grasp_a_low_object_on_the_floor_but_not_reach_into_it():
    """A 2.5 cm tissue packet on the floor, grasped from above with the fingertips 5 mm over
    the floor (`vertical_grasp`): the hand at its grasp may come as near the floor as to a
    table's points. With the fingertips 5 mm into the floor it is refused."""
    half_pad = dims.GRIPPER_HAND.pad_depth / 2
    plans = {}
    for tips in (0.005, -0.005):
        q = ik_tcp(top_grasp(1.55, -0.30, tips + half_pad), dims.UR5_READY_Q)[0]
        world = CollisionChecker(EMPTY)
        plans[tips] = plan_pick(dims.UR5_READY_Q, q, world, world, np.random.default_rng(0))
    assert not isinstance(plans[0.005], Failure), plans[0.005]
    refused = plans[-0.005]
    assert isinstance(refused, Failure) and "hit something beside" in refused.message


def test_what_stands_between_the_open_fingers_is_closed_on_and_what_stands_beside_is_not():
    """A packet's side face that the segmentation left out of the target stands between the
    open fingers of a grasp from above: the housing's spheres reach down there, but the real
    housing does not, so the grasp is planned. The same face where a finger comes down is
    hit."""
    top = 0.46
    T = top_grasp(1.55, -0.30, top + 0.016)
    q = ik_tcp(T, dims.UR5_READY_Q)[0]
    xs, zs = np.meshgrid(np.arange(-0.04, 0.041, 0.005), np.arange(0.0, 0.04, 0.005))

    def face(y: float) -> np.ndarray:  # a vertical sheet along the hand axis, in `base`
        local = np.c_[xs.ravel(), np.full(xs.size, y), -zs.ravel()]
        return local @ T[:3, :3].T + T[:3, 3]

    for y, planned in ((0.01, True), (0.05, False)):
        pts = np.vstack([table(top), face(y)])
        pts = pts[pts[:, 2] >= top - 1e-9]
        world = CollisionChecker(pts)
        plan = plan_pick(dims.UR5_READY_Q, q, world, world, np.random.default_rng(0))
        if planned:
            assert not isinstance(plan, Failure), plan
        else:
            assert isinstance(plan, Failure) and "hit something beside" in plan.message


def test_lifts_out_of_order_are_refused_saying_which():
    """A least lift under the re-grip's would set the object back down; a low lift above
    the full one would never be tried. Either is refused with the four values."""
    with pytest.raises(ValidationError, match="regrip_lift < lift_least <= lift_low <= lift"):
        MotionSettings(lift_least=0.01)
    with pytest.raises(ValidationError, match=r"0\.02, 0\.03, 0\.12, 0\.1"):
        MotionSettings(lift_low=0.12)
    assert MotionSettings(lift_least=0.05).lift_least == 0.05
