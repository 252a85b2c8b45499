"""The collision check's broad phase: a body with many spheres (the hand, with the points of
what it holds) is bounded by one ball at each configuration, and its spheres are measured one
by one only where that ball comes near something: a keep-out box, the cloud. A point's gap
to an obstacle changes no faster than the point moves, so the verdicts are those of
measuring every sphere. Frames: `base`, metres.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["BROAD_MIN", "BROAD_SLACK", "Ball", "balls", "enclosing"]

#: What a ball's radius adds (m): far above float rounding, far below any margin, so that a
#: ball never passes over a sphere the exact test would catch.
BROAD_SLACK = 1e-6
#: Spheres of one body worth a ball: fewer are measured one by one at once, which is quicker
#: than bounding them first.
BROAD_MIN = 32


@dataclass(frozen=True)
class Ball:
    """The spheres of one body at B configurations: `spheres` (n,) indices into the check's
    spheres; `middle` (B, 3) their centres' mean, m; `radius` (B,) m, from `middle` to
    whatever any of them reaches, plus BROAD_SLACK."""

    body: int
    spheres: np.ndarray
    middle: np.ndarray
    radius: np.ndarray


def enclosing(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The ball about the mean of each row of points (B, N, 3) (m) that holds them all: its
    middle (B, 3) and radius (B,), m."""
    middle = points.mean(axis=1)
    offset = points - middle[:, None]
    return middle, np.sqrt(np.einsum("bni,bni->bn", offset, offset)).max(axis=1)


def balls(
    centres: np.ndarray, reach: np.ndarray, body: np.ndarray
) -> tuple[np.ndarray, list[Ball]]:
    """For spheres at centres (B, S, 3) (m), each reaching `reach` (S,) (m: its radius and
    the margin) and on `body` (S,): the indices of the spheres on bodies with fewer than
    BROAD_MIN of them, to be measured one by one, and a `Ball` for each other body."""
    counts = np.bincount(body)
    few = np.flatnonzero(counts[body] < BROAD_MIN)
    out = []
    for b in np.flatnonzero(counts >= BROAD_MIN):
        mine = np.flatnonzero(body == b)
        middle, spread = enclosing(centres[:, mine])
        out.append(Ball(int(b), mine, middle, spread + reach[mine].max() + BROAD_SLACK))
    return few, out
