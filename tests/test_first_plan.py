"""Planning a pick's grasps in order (`first_plan`): the searches a pick shares, the short
searches first, and the second pass through the high ready pose. The searches are stood
in for (monkeypatched) where a test needs one to find or miss a way."""

from __future__ import annotations

import numpy as np
import pytest
from arm_poses import EMPTY, top_grasp

from laserpick.description import dims
from laserpick.description.kinematics import ik_tcp
from laserpick.pipeline import first_plan, joint_search
from laserpick.pipeline import plan as plan_module
from laserpick.pipeline.collision import CollisionChecker
from laserpick.pipeline.first_plan import plan_first
from laserpick.pipeline.grasp_choice import GraspSet
from laserpick.pipeline.plan_record import RECORD_PICKS_ENV, load_pick
from laserpick.pipeline.reach import pregrasp_pose
from laserpick.pipeline.selection import group
from laserpick.settings import get_settings
from laserpick.types import DepthFrame, Failure, Grasp


def test_a_pick_searches_each_leg_once_and_gives_up_after_its_budget(monkeypatch) -> None:
    """The leg from the stowed arm to ready is the same for every grasp of a pick: a failed
    search of it is not repeated per grasp, and failed searches stop the pick at the cap."""
    calls: list[tuple[float, float]] = []

    def no_path(a, b, *args, **kw):
        calls.append((float(a[0]), float(b[0])))
        return None

    monkeypatch.setattr(joint_search, "joint_path", no_path)
    searches = joint_search.Searches(max_failed=2)
    home, ready, pre = np.zeros(6), np.full(6, 0.5), np.full(6, 1.0)
    s = get_settings().motion
    rng = np.random.default_rng(0)
    checker = CollisionChecker(np.zeros((0, 3)))
    for _ in range(3):
        assert searches.path(home, ready, checker, rng, s) is None
    assert calls == [(0.0, 0.5)] and not searches.spent
    assert searches.path(ready, pre, checker, rng, s) is None
    assert searches.spent and searches.failed == 2
    # Forgotten, a failed leg is searched anew, and counted again.
    searches.forget_failed()
    assert searches.path(home, ready, checker, rng, s) is None
    assert calls == [(0.0, 0.5), (0.5, 1.0), (0.0, 0.5)] and searches.failed == 3


def test_a_leg_searched_again_is_one_leg_to_explain(monkeypatch) -> None:
    """A leg held to seen space that found no way is kept once to say why (`blocked`), even
    when the second pass searches it again and it fails again."""
    monkeypatch.setattr(joint_search, "joint_path", lambda *args, **kw: None)
    frame = DepthFrame(
        depth=np.ones((4, 4)), ir=np.zeros((0, 0), np.uint8), K=np.eye(3),
        T_base_cam=np.eye(4), camera="c", stamp=0.0,
    )  # fmt: skip
    checker = CollisionChecker(EMPTY, frames=[frame])
    searches = joint_search.Searches(max_failed=6)
    a, b, s = np.zeros(6), np.full(6, 0.5), get_settings().motion
    rng = np.random.default_rng(0)
    assert searches.path(a, b, checker, rng, s) is None
    searches.forget_failed()
    assert searches.path(a, b, checker, rng, s) is None
    assert searches.failed == 2 and len(searches.blocked) == 1


def _one_grasp_pick(x: float, y: float, z: float) -> GraspSet:
    """A pick of one top grasp at (x, y, z) m in `base` over an empty world."""
    world = CollisionChecker(EMPTY)
    T = top_grasp(x, y, z)
    grasp = Grasp(pose=T, width=0.05, ik=ik_tcp(T, dims.UR5_READY_Q)[0])
    return GraspSet(group([grasp]), (), world, world, T[:3, 3][None], "gpd")


@pytest.mark.parametrize("max_failed", [1, 2])
def test_a_grasp_whose_way_was_not_found_is_planned_again_through_the_high_ready_pose(
    monkeypatch, max_failed
) -> None:
    """From standing by, the one grasp's leg from ready to its pre-grasp finds no way: within
    the budget the grasp is planned once more, its way out through the high ready pose and
    the failed leg searched anew; with the budget spent after the first, the pick says no."""
    legs: list[tuple[bytes, bytes]] = []
    failed_once: set[bytes] = set()

    def first_search_fails(a, b, checker, rng, s, **kw):
        if s.rrt_max_samples <= first_plan.QUICK_SAMPLES:
            return None  # the short searches find no way either
        legs.append((np.round(a, 6).tobytes(), np.round(b, 6).tobytes()))
        fixed = any(np.allclose(b, q) for q in (dims.UR5_READY_Q, dims.UR5_HIGH_READY_Q))
        if not fixed and b.tobytes() not in failed_once:
            failed_once.add(b.tobytes())
            return None
        return np.array([a, b], float)

    monkeypatch.setattr(joint_search, "joint_path", first_search_fails)
    s = get_settings().motion.model_copy(update={"rrt_max_failed": max_failed})
    found = _one_grasp_pick(1.55, -0.25, 0.50)
    plan, grasp, tried = plan_first(found, dims.UR5_STANDBY_Q, np.random.default_rng(0), settings=s)
    assert tried == 1
    if max_failed == 1:
        assert isinstance(plan, Failure) and grasp is None
        assert plan.message.startswith("No collision-free path in 1 searches")
        assert len(legs) == 2  # the fixed way to ready, the pre-grasp leg once
        return
    assert not isinstance(plan, Failure), plan
    assert np.allclose(plan.transit.q[0], dims.UR5_STANDBY_Q)
    # Out to ready and on to the pre-grasp, no way; out to the high ready pose and on.
    key = [np.round(q, 6).tobytes() for q in (dims.UR5_STANDBY_Q, dims.UR5_READY_Q)]
    high = np.round(dims.UR5_HIGH_READY_Q, 6).tobytes()
    pre = legs[1][1]
    assert legs == [tuple(key), (key[1], pre), (key[0], high), (high, pre)]


def _grasps_pick(*where: tuple[float, float, float]) -> GraspSet:
    """A pick of top grasps at these (x, y, z) m in `base`, best first, over an empty world."""
    world = CollisionChecker(EMPTY)
    grasps = []
    for x, y, z in where:
        T = top_grasp(x, y, z)
        grasps.append(Grasp(pose=T, width=0.05, ik=ik_tcp(T, dims.UR5_READY_Q)[0]))
    return GraspSet(
        group(grasps), (), world, world, np.array([g.pose[:3, 3] for g in grasps]), "gpd"
    )


@pytest.mark.parametrize("quick_way", [None, 1, 5])
def test_a_grasp_whose_way_is_found_at_once_is_taken_before_one_that_needs_a_long_search(
    monkeypatch, quick_way
) -> None:
    """Grasp by grasp (`grasps_together` off): eight grasps, whose ways from ready to their
    pre-grasps only full searches find, but for the one at `quick_way` (its place in the
    order), which a short search finds: that one is taken, after the short searches of the
    grasps before it. Where no short search
    finds a way, as many as the full searches may fail (`rrt_max_failed`) are spent, and
    the full searches take the best grasp."""
    searched: list[tuple[int, int]] = []  # (grasp, samples)
    found = _grasps_pick(*[(1.5 + 0.05 * k, -0.25, 0.50) for k in range(8)])
    pres = [ik_tcp(pregrasp_pose(g.pose, 0.10), g.ik)[0] for g in found.ordered()]

    def search(a, b, checker, rng, s, **kw):
        k = next(k for k, pre in enumerate(pres, 1) if np.allclose(b, pre, atol=1e-6))
        searched.append((k, s.rrt_max_samples))
        quick = s.rrt_max_samples <= first_plan.QUICK_SAMPLES
        return np.array([a, b], float) if not quick or k == quick_way else None

    monkeypatch.setattr(joint_search, "joint_path", search)
    s = get_settings().motion.model_copy(update={"grasps_together": False})
    plan, grasp, tried = plan_first(found, dims.UR5_READY_Q, np.random.default_rng(0), settings=s)
    assert not isinstance(plan, Failure), plan
    short, full = first_plan.QUICK_SAMPLES, s.rrt_max_samples
    if quick_way is None:
        misses = s.rrt_max_failed
        assert tried == 1 and grasp is found.ordered()[0]
        assert searched == [(k, short) for k in range(1, misses + 1)] + [(1, full)]
    else:
        assert tried == quick_way and grasp is found.ordered()[quick_way - 1]
        assert searched == [(k, short) for k in range(1, quick_way + 1)]


@pytest.mark.parametrize("unseen_first", [False, True])
def test_together_one_full_search_goes_toward_every_pre_grasp(monkeypatch, unseen_first) -> None:
    """With `grasps_together`, the short searches go toward the first grasp alone, then
    toward the five after it at once; where they found no way, one full search goes
    toward the pre-grasps of all six grasps at once, best first, and the grasp whose
    pre-grasp it reaches (here the third) is taken. A way that passes the seen-space test
    only where the arm will stand at another pre-grasp is not taken: the one it reached is
    left out, and the others are searched again."""
    found = _grasps_pick(*[(1.5 + 0.05 * k, -0.25, 0.50) for k in range(6)])
    pres = [ik_tcp(pregrasp_pose(g.pose, 0.10), g.ik)[0] for g in found.ordered()]
    searched: list[tuple[list[int], int]] = []  # (grasps searched toward, samples)

    def search(a, b, checker, rng, s, **kw):
        goals = np.atleast_2d(b)
        rows = [next(k for k, p in enumerate(pres, 1) if np.allclose(g, p)) for g in goals]
        searched.append((rows, s.rrt_max_samples))
        if s.rrt_max_samples <= first_plan.QUICK_SAMPLES:
            return None
        return np.array([a, goals[min(2, len(goals) - 1)]], float)

    unseen = pres[2].tobytes() if unseen_first else None
    monkeypatch.setattr(joint_search, "joint_path", search)
    monkeypatch.setattr(plan_module, "_seen_knowing", lambda w, a, b, leg: b.tobytes() != unseen)
    s = get_settings().motion
    assert s.grasps_together
    plan, grasp, _ = plan_first(found, dims.UR5_READY_Q, np.random.default_rng(0), settings=s)
    assert not isinstance(plan, Failure), plan
    full = [rows for rows, n in searched if n > first_plan.QUICK_SAMPLES]
    assert [rows for rows, n in searched if n <= first_plan.QUICK_SAMPLES] == [
        [1],
        list(range(2, 7)),
    ]
    if unseen_first:
        assert full == [list(range(1, 7)), [1, 2, 4, 5, 6]]
        assert grasp is found.ordered()[3] and np.allclose(plan.transit.q[-1], pres[3])
    else:
        assert full == [list(range(1, 7))]
        assert grasp is found.ordered()[2] and np.allclose(plan.transit.q[-1], pres[2])


@pytest.mark.parametrize("max_failed", [6, 3])
def test_together_goes_on_grasp_by_grasp_where_the_searches_toward_all_found_no_way(
    monkeypatch, max_failed
) -> None:
    """With `grasps_together`, where the full searches toward all six pre-grasps found no
    way, from ready and again from the high ready pose, the budget left goes to the grasps
    one by one: the way to the fourth, found alone, is taken. With three failed searches
    allowed, the first grasp's own search spends them and the pick says no."""
    found = _grasps_pick(*[(1.5 + 0.05 * k, -0.25, 0.50) for k in range(6)])
    pres = [ik_tcp(pregrasp_pose(g.pose, 0.10), g.ik)[0] for g in found.ordered()]
    searched: list[list[int]] = []  # the grasps each full search went toward

    def search(a, b, checker, rng, s, **kw):
        goals = np.atleast_2d(b)
        if np.allclose(goals[0], dims.UR5_HIGH_READY_Q):
            return np.array([a, goals[0]], float)  # the fixed way up is clear
        if s.rrt_max_samples <= first_plan.QUICK_SAMPLES:
            return None
        rows = [next(k for k, p in enumerate(pres, 1) if np.allclose(g, p)) for g in goals]
        searched.append(rows)
        return np.array([a, goals[0]], float) if rows == [4] else None

    monkeypatch.setattr(joint_search, "joint_path", search)
    s = get_settings().motion.model_copy(update={"rrt_max_failed": max_failed})
    assert s.grasps_together
    plan, grasp, _ = plan_first(found, dims.UR5_READY_Q, np.random.default_rng(0), settings=s)
    together = [list(range(1, 7))] * 2
    if max_failed == 3:
        assert isinstance(plan, Failure) and grasp is None
        assert plan.message.startswith("No collision-free path in 3 searches")
        assert searched == [*together, [1]]
        return
    assert not isinstance(plan, Failure), plan
    assert searched == [*together, [1], [2], [3], [4]]
    assert grasp is found.ordered()[3] and np.allclose(plan.transit.q[-1], pres[3])


@pytest.mark.parametrize("quick_way", [False, True])
def test_the_user_hears_when_the_short_searches_found_no_way(monkeypatch, quick_way) -> None:
    """Where the short searches find no way, the pick says it searches longer before the
    full searches, which take seconds; where a short one finds a way, it says nothing."""

    def search(a, b, checker, rng, s, **kw):
        quick = s.rrt_max_samples <= first_plan.QUICK_SAMPLES
        return np.array([a, np.atleast_2d(b)[0]], float) if quick_way or not quick else None

    monkeypatch.setattr(joint_search, "joint_path", search)
    heard: list[str] = []
    found = _grasps_pick(*[(1.5 + 0.05 * k, -0.25, 0.50) for k in range(3)])
    rng = np.random.default_rng(0)
    plan, _, _ = plan_first(found, dims.UR5_READY_Q, rng, progress=heard.append)
    assert not isinstance(plan, Failure), plan
    assert heard == ([] if quick_way else [first_plan.SEARCHING_LONGER])


def test_a_cancel_while_planning_makes_no_further_search(monkeypatch) -> None:
    """Once `stop` says so (the operator cancelled), no further search is made: the pick's
    planning fails after the search under way, not after its whole budget of searches
    (a juice bottle's spent 20-34 s), and nothing more is said."""
    searched: list[int] = []
    cancelled = {"now": False}

    def search(a, b, checker, rng, s, **kw):
        searched.append(s.rrt_max_samples)
        cancelled["now"] = True  # the operator cancels while the first search runs
        return None

    monkeypatch.setattr(joint_search, "joint_path", search)
    heard: list[str] = []
    found = _grasps_pick(*[(1.5 + 0.05 * k, -0.25, 0.50) for k in range(6)])
    rng = np.random.default_rng(0)
    plan, grasp, _ = plan_first(
        found, dims.UR5_READY_Q, rng, progress=heard.append, stop=lambda: cancelled["now"]
    )
    assert isinstance(plan, Failure) and grasp is None
    assert searched == [first_plan.QUICK_SAMPLES] and heard == []
    # Uncancelled, the same pick goes on to its full searches.
    searched.clear()
    plan_first(found, dims.UR5_READY_Q, np.random.default_rng(0))
    assert searched.count(get_settings().motion.rrt_max_samples) >= 2


def test_a_recorded_pick_is_planned_again_alike(monkeypatch, tmp_path) -> None:
    """With LASERPICK_RECORD_PICKS set, `plan_first` writes what it was given; loaded
    (`load_pick`), the same pick plans to the same grasp and the same transit, and its
    generator draws as the pick's did, from before its first draw."""
    monkeypatch.setenv(RECORD_PICKS_ENV, str(tmp_path))
    found = _grasps_pick((1.5, -0.25, 0.50), (1.6, -0.2, 0.55))
    refused = found.ordered()[0]
    admit = lambda g: Failure("ik_plan", "not this one") if g is refused else None  # noqa: E731
    rng = np.random.default_rng(7)
    draw = np.random.default_rng(7).integers(2**32)
    plan, grasp, place = plan_first(found, dims.UR5_STANDBY_Q, rng, admit=admit)
    assert not isinstance(plan, Failure) and place == 2 and grasp is found.ordered()[1]
    (path,) = tmp_path.glob("*.pkl")
    pick = load_pick(path)
    assert pick["rng"].integers(2**32) == draw
    again, _, place_again = plan_first(**load_pick(path))
    assert not isinstance(again, Failure) and place_again == place
    assert np.array_equal(again.transit.q, plan.transit.q)
    # The replay, recording too, wrote the same pick again, named second in the run's order.
    first, second = sorted(tmp_path.glob("*.pkl"))
    assert first == path and first.name.startswith("0000-") and second.name.startswith("0001-")
    assert np.array_equal(load_pick(second)["q_now"], pick["q_now"])


class _NoStraightMove:
    """A world where every configuration is clear and no straight move is."""

    frames = ()

    def segment_ok(self, *args, **kw) -> bool:
        return False

    def clearance_ok(self, Q, **kw) -> np.ndarray:
        return np.ones(len(np.atleast_2d(Q)), bool)


@pytest.mark.parametrize("each_goal", [False, True])
def test_a_full_search_toward_several_grasps_counts_each_goal_it_found_no_way_to(
    monkeypatch, each_goal
) -> None:
    """OMPL searches several goals one after another, each with the whole budget: with
    `each_goal` (a pick's full searches) each goal it found no way to counts as a failed
    search, and the search stops once the pick's budget is spent; without (the short
    searches), the leg counts once, every goal searched."""
    searched: list[float] = []

    def no_way(q_start, goal, *args, **kw):
        searched.append(float(goal[0]))
        return None

    monkeypatch.setattr(joint_search, "ompl_connect", no_way)
    s = get_settings().motion.model_copy(update={"pick_planner": "ompl"})
    searches = joint_search.Searches(max_failed=3, each_goal=each_goal)
    goals = np.array([np.full(6, 0.1 * k) for k in range(1, 6)])
    rng = np.random.default_rng(0)
    assert searches.path(np.zeros(6), goals, _NoStraightMove(), rng, s, seen=False) is None
    if each_goal:
        assert searched == pytest.approx([0.1, 0.2, 0.3]) and searches.spent
    else:
        assert len(searched) == 5 and searches.failed == 1 and not searches.spent
