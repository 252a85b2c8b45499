"""Partial shortcuts (Geraerts and Overmars 2007) that make a searched joint path quicker to
run: between two random points on the path, one joint at a time moves straight from its
angle at the first to its angle at the second while the others keep their course. A
search's path wanders in the joints that no obstacle needed (a wrist turned one way and
back), and joins between the path's own vertices (`rrt.shortcut`) cannot straighten one
joint alone.

A change is kept only where it is clear by the same check as the search's, and quicker by
`run_time`, the time the path takes at the joint speed limit, the TCP speed cap or the
hand's turning cap, whichever binds on each segment: what the arm's timing spends
(`timing`), less its accelerations. That estimate leaves out the corners, and each partial
shortcut adds two; where a leg between corners is short, the blends at its ends may reach
no further than half of it and the arm all but stops at each (`smoothing`): such legs are
taken out afterwards (`merge_short_legs`). Frames: joint angles in rad; TCP in `base`, m.
"""

from __future__ import annotations

import itertools

import numpy as np

from laserpick.pipeline.collision import CollisionChecker
from laserpick.pipeline.timing import Limits, straight_times

__all__ = ["SHORT_LEG", "merge_short_legs", "quicken", "run_time"]

#: Points along each segment at which the TCP's path is measured: a joint-space segment
#: moves the TCP along an arc, not a chord.
ARC_SAMPLES = 6
#: A change must save at least this (s): smaller ones only add vertices.
LEAST_GAIN = 0.02
#: Legs shorter than this (rad, joint space) `merge_short_legs` takes out. On 72 carries
#: recorded in `in-situ`, timed as the arm runs them: 7.53 s as quickened, 7.14 s with the
#: legs under 0.5 rad taken out (0.35 and 0.8 rad: within 0.02 s of that).
SHORT_LEG = 0.5


def _segment_times(path: np.ndarray, limits: Limits) -> np.ndarray:
    """(K-1,) the least time (s) each segment of `path` (K, 6) rad takes at the speed
    limits (`timing.straight_times`)."""
    return straight_times(path[:-1], path[1:], limits, ARC_SAMPLES)


def run_time(path: np.ndarray, limits: Limits) -> float:
    """The least time (s) `path` (K, 6) rad takes at the speed limits (`_segment_times`)."""
    return float(_segment_times(np.asarray(path, float), limits).sum())


def _point_at(path: np.ndarray, along: np.ndarray, t: float) -> tuple[int, np.ndarray]:
    """The segment index k and the configuration `t` along `path` (`along`: each vertex's
    position, the largest joint's motion summed from the start, rad)."""
    k = int(np.clip(np.searchsorted(along, t, side="right") - 1, 0, len(path) - 2))
    f = (t - along[k]) / max(along[k + 1] - along[k], 1e-12)
    return k, path[k] + f * (path[k + 1] - path[k])


def quicken(
    path: np.ndarray,
    checker: CollisionChecker,
    rng: np.random.Generator,
    limits: Limits,
    *,
    tries: int = 40,
    **kw,
) -> np.ndarray:
    """`path` (K, 6) rad with `tries` random partial shortcuts tried, each kept where its new
    segments pass `checker.segment_ok(..., **kw)` and it saves LEAST_GAIN s of `run_time`
    at the speed limits of `limits`. The ends stay where they are."""
    path = np.array(path, float)
    times = _segment_times(path, limits)
    for _ in range(tries):
        along = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(path, axis=0)).max(axis=1))])
        if len(path) < 2 or along[-1] <= 0.0:
            break
        t1, t2 = np.sort(rng.uniform(0.0, along[-1], 2))
        joint = int(rng.integers(6))
        k1, q1 = _point_at(path, along, t1)
        k2, q2 = _point_at(path, along, t2)
        if k2 <= k1:  # within one segment, which is straight already
            continue
        middle = path[k1 + 1 : k2 + 1].copy()
        middle[:, joint] = np.interp(along[k1 + 1 : k2 + 1], [t1, t2], [q1[joint], q2[joint]])
        piece = np.vstack([path[k1], q1, middle, q2, path[k2 + 1]])
        new_times = _segment_times(piece, limits)
        if new_times.sum() > times[k1 : k2 + 1].sum() - LEAST_GAIN:
            continue
        if not all(checker.segment_ok(a, b, **kw) for a, b in itertools.pairwise(piece)):
            continue
        path = np.vstack([path[:k1], piece, path[k2 + 2 :]])
        times = np.concatenate([times[:k1], new_times, times[k2 + 1 :]])
        repeated = np.abs(np.diff(path, axis=0)).max(axis=1) < 1e-9  # q1 fell on a vertex
        if repeated.any():
            end = path[-1].copy()
            path = path[np.concatenate([[True], ~repeated])]
            path[-1] = end
            times = _segment_times(path, limits)
    return path


def merge_short_legs(
    path: np.ndarray, checker: CollisionChecker, *, shortest: float = SHORT_LEG, **kw
) -> np.ndarray:
    """`path` (K, 6) rad with its legs shorter than `shortest` (rad) taken out where
    `checker.segment_ok(..., **kw)` allows, the shortest first: a corner at one of its ends
    dropped where the legs beside it join clear, else its two corners merged into the leg's
    middle where the legs to it are clear. The ends stay where they are."""
    path = np.array(path, float)
    while len(path) > 2:
        merged = _merge_shortest(path, checker, shortest, kw)
        if merged is None:
            break
        path = merged
    return path


def _merge_shortest(
    path: np.ndarray, checker: CollisionChecker, shortest: float, kw: dict
) -> np.ndarray | None:
    """`path` with its shortest leg under `shortest` (rad) that the check lets go taken out
    (`merge_short_legs`), or None where there is none."""
    length = np.linalg.norm(np.diff(path, axis=0), axis=1)
    last = len(path) - 1
    for k in np.argsort(length, kind="stable"):
        if length[k] >= shortest:
            break
        for drop in (k, k + 1):  # a corner at either end of leg k, joined past
            if 0 < drop < last and checker.segment_ok(path[drop - 1], path[drop + 1], **kw):
                return np.delete(path, drop, axis=0)
        if k > 0 and k + 1 < last:
            middle = (path[k] + path[k + 1]) / 2
            if checker.segment_ok(path[k - 1], middle, **kw) and checker.segment_ok(
                middle, path[k + 2], **kw
            ):
                return np.vstack([path[:k], middle, path[k + 2 :]])
    return None
