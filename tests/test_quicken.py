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
from laserpick.pipeline.quicken import quicken, run_time
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
        assert timed(path, s).duration <= timed(searched, s).duration
        saved += timed(searched, s).duration - timed(path, s).duration
    assert saved > 0.3  # 1.7 s over the three seeds
