"""Partial shortcuts make a searched path quicker, and keep it clear."""

from __future__ import annotations

import itertools

import numpy as np
from arm_poses import EMPTY, table, top_grasp

from laserpick.description import dims
from laserpick.description.kinematics import ik_tcp
from laserpick.pipeline.collision import CollisionChecker
from laserpick.pipeline.joint_search import joint_path
from laserpick.pipeline.motion_limits import motion_limits, timed
from laserpick.pipeline.quicken import merge_short_legs, quicken, run_time
from laserpick.pipeline.rrt import rrt_connect, shortcut
from laserpick.settings import get_settings


def _wrist_detour() -> tuple[np.ndarray, np.ndarray]:
    """A move across the table whose middle turns the last joint a radian out and back, as
    a search's path does where no obstacle needed it; and the same move without."""
    q0 = ik_tcp(top_grasp(1.6, -0.5, 0.75), dims.UR5_READY_Q)[0]
    q1 = ik_tcp(top_grasp(1.6, 0.1, 0.75), dims.UR5_READY_Q)[0]
    mids = np.linspace(q0, q1, 5)[1:-1]
    mids[:, 5] += [0.5, 1.0, 0.5]
    return np.vstack([q0, mids, q1]), np.array([q0, q1])


def test_the_wandering_joint_goes_straight_and_the_path_is_quicker():
    detour, straight = _wrist_detour()
    checker = CollisionChecker(EMPTY)
    limits = motion_limits(get_settings().motion)
    out = quicken(detour, checker, np.random.default_rng(0), limits)
    assert np.array_equal(out[0], detour[0]) and np.array_equal(out[-1], detour[-1])
    before, after = run_time(detour, limits), run_time(out, limits)
    assert after < before - 0.3  # the detour costs 0.37 s
    assert after <= run_time(straight, limits) + 0.1


def test_no_change_is_kept_that_the_check_refuses():
    """With every join refused, the path stays as it was; around a wall, every segment of
    the searched path passes the same check, and the arm takes no longer on it than on the
    search's own path (the same draws come before the partial shortcuts')."""
    detour, _ = _wrist_detour()
    refusing = CollisionChecker(EMPTY)
    refusing.segment_ok = lambda a, b, **kw: False  # type: ignore[method-assign]
    rng = np.random.default_rng(0)
    kept = quicken(detour, refusing, rng, motion_limits(get_settings().motion))
    assert np.array_equal(kept, detour)
    wall = np.array(
        [[x, -0.2, z] for x in np.arange(1.45, 1.75, 0.02) for z in np.arange(0.46, 0.8, 0.02)]
    )
    checker = CollisionChecker(np.vstack([table(), wall]), voxel=0.0)
    s = get_settings().motion.model_copy(update={"quicken_paths": True})
    saved = 0.0
    for seed in range(3):
        path = joint_path(detour[0], detour[-1], checker, np.random.default_rng(seed), s)
        assert path is not None
        assert all(checker.segment_ok(a, b) for a, b in itertools.pairwise(path))
        rng = np.random.default_rng(seed)
        found = rrt_connect(detour[0], detour[-1], checker, rng, step=s.rrt_step)
        searched = shortcut(found, checker, rng)
        runs, searched_runs = (timed(p, s, clear=checker.path_clear) for p in (path, searched))
        assert runs.duration <= searched_runs.duration
        saved += searched_runs.duration - runs.duration
    assert saved > 0.3  # 0.66 s over the three seeds, as the arm runs them


def _with_short_legs() -> np.ndarray:
    """A move across the table through three corners, the middle leg 0.1 rad long and a
    corner 0.05 rad short of the end: the kind of path partial shortcuts leave."""
    q0 = ik_tcp(top_grasp(1.6, -0.5, 0.75), dims.UR5_READY_Q)[0]
    q1 = ik_tcp(top_grasp(1.6, 0.1, 0.75), dims.UR5_READY_Q)[0]
    bend = np.array([0.0, 0.3, -0.3, 0.0, 0.0, 0.4])
    a = q0 + 0.45 * (q1 - q0) + bend
    b = a + np.array([0.1, 0.0, 0.0, 0.0, 0.0, 0.0])
    return np.array([q0, a, b, q1 - 0.05 * (q1 - q0) / np.linalg.norm(q1 - q0), q1])


def test_short_legs_go_and_the_arm_runs_the_path_sooner():
    path = _with_short_legs()
    checker = CollisionChecker(EMPTY)
    s = get_settings().motion
    out = merge_short_legs(path, checker)
    assert np.array_equal(out[0], path[0]) and np.array_equal(out[-1], path[-1])
    assert len(out) < len(path)
    assert (np.linalg.norm(np.diff(out, axis=0), axis=1) >= 0.5).all()
    assert all(checker.segment_ok(a, b) for a, b in itertools.pairwise(out))
    clear = checker.path_clear
    assert timed(out, s, clear=clear).duration < timed(path, s, clear=clear).duration - 0.3


class _Joins:
    """A checker stand-in that lets through only the segments `allowed` says it may."""

    def __init__(self, allowed) -> None:
        self.allowed = allowed

    def segment_ok(self, a: np.ndarray, b: np.ndarray, **kw) -> bool:
        return bool(self.allowed(a, b))


def test_a_short_leg_whose_corners_cannot_go_is_merged_into_its_middle_or_kept():
    """Where neither corner of a short leg may be joined past, its two corners become one
    at its middle, if the legs to it are clear; else the path stays as it was."""
    path = np.zeros((4, 6))
    path[:, 0] = [0.0, 1.0, 1.1, 2.0]
    path[1:3, 1] = 1.0
    middle = (path[1] + path[2]) / 2

    def to_middle_only(a, b):  # the legs of the path itself, or to the short leg's middle
        legs = [tuple(p) for p in itertools.pairwise(path)]
        return any(np.allclose(a, x) and np.allclose(b, y) for x, y in legs) or any(
            np.allclose(q, middle) for q in (a, b)
        )

    merged = merge_short_legs(path, _Joins(to_middle_only))  # type: ignore[arg-type]
    assert np.allclose(merged, [path[0], middle, path[3]])
    kept = merge_short_legs(path, _Joins(lambda a, b: False))  # type: ignore[arg-type]
    assert np.array_equal(kept, path)
