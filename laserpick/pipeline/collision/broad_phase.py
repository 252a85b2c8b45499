"""The collision check's broad phase: each body's spheres (a link's, the hand's with the
points of what it holds) are bounded by one ball at each configuration, and a body's
spheres are measured one by one only where its ball comes near something: a keep-out box,
the cloud. A point's gap to an obstacle changes no faster than the point moves, so the
verdicts are those of measuring every sphere. Frames: `base`, metres.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

__all__ = ["BROAD_SLACK", "BodyBalls", "body_balls", "enclosing"]

#: What a ball's radius adds (m): far above float rounding, far below any margin, so that a
#: ball never passes over a sphere the exact test would catch.
BROAD_SLACK = 1e-6


@dataclass(frozen=True)
class BodyBalls:
    """One ball about each body's spheres at each of B configurations. `order` (S,) lists the
    check's spheres body by body; body g's run starts at `starts[g]` and holds `counts[g]`;
    `middle` (B, G, 3) m is the mean of its centres, `radius` (B, G) m reaches from there
    to whatever any of them reaches, plus BROAD_SLACK."""

    order: np.ndarray
    starts: np.ndarray
    counts: np.ndarray
    middle: np.ndarray
    radius: np.ndarray

    def split(self, least: int) -> tuple[np.ndarray, np.ndarray]:
        """The spheres (indices into the check's) of the bodies with fewer than `least`, and
        the bodies (indices into the balls) with more."""
        return _split(self.order.tobytes(), self.counts.tobytes(), least)

    def members(self, rows: np.ndarray, groups: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The spheres of the (configuration, body) pairs rows[m], groups[m] (M,), one entry a
        sphere: (which pair, which sphere), each (N,), the pairs' spheres one after another."""
        n = self.counts[groups]
        pair = np.repeat(np.arange(len(rows)), n)
        first = np.cumsum(n) - n  # where each pair's run starts in the output
        within = np.arange(len(pair)) - first[pair]
        return pair, self.order[self.starts[groups][pair] + within]


def enclosing(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The ball about the mean of each row of points (B, N, 3) (m) that holds them all: its
    middle (B, 3) and radius (B,), m."""
    middle = points.mean(axis=1)
    offset = points - middle[:, None]
    return middle, np.sqrt(np.einsum("bni,bni->bn", offset, offset)).max(axis=1)


@functools.lru_cache(maxsize=32)
def _runs(body_key: bytes) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """`order`, `starts`, `counts` of `BodyBalls` for the bodies (S,) (int64 bytes): the same
    few lists of spheres (with the hand, without, with a held object) are asked thousands
    of times a search."""
    body = np.frombuffer(body_key, np.int64)
    order = np.argsort(body, kind="stable")
    _, starts, counts = np.unique(body[order], return_index=True, return_counts=True)
    return order, starts, counts


@functools.lru_cache(maxsize=32)
def _split(order_key: bytes, counts_key: bytes, least: int) -> tuple[np.ndarray, np.ndarray]:
    """`BodyBalls.split` for its `order` and `counts` (int64 bytes), kept as `_runs` is."""
    order, counts = np.frombuffer(order_key, np.int64), np.frombuffer(counts_key, np.int64)
    big = counts >= least
    return np.sort(order[~np.repeat(big, counts)]), np.flatnonzero(big)


def body_balls(centres: np.ndarray, reach: np.ndarray, body: np.ndarray) -> BodyBalls:
    """A ball about each body's spheres, at centres (B, S, 3) (m), each sphere reaching
    `reach` (S,) (m: its radius and the margin) and on `body` (S,)."""
    order, starts, counts = _runs(np.asarray(body, np.int64).tobytes())
    runs = centres[:, order]
    middle = np.add.reduceat(runs, starts, axis=1) / counts[:, None]
    offset = runs - np.repeat(middle, counts, axis=1)
    spread = np.sqrt(np.einsum("bsi,bsi->bs", offset, offset)) + reach[order]
    radius = np.maximum.reduceat(spread, starts, axis=1) + BROAD_SLACK
    return BodyBalls(order, starts, counts, middle, radius)
