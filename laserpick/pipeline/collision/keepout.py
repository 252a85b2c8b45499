"""How far points are from the keep-out boxes around the scooter and its rider
(`description.shapes.KEEPOUT_BOXES`), which of the arm's bodies each box is checked
against, and which of the arm's spheres come within reach of one. Frames: `base`, metres.
"""

from __future__ import annotations

import numpy as np

from laserpick.description.shapes import IDENTITY, KEEPOUT_BOXES
from laserpick.pipeline.collision.broad_phase import Ball, balls

_LO = np.array([b.lo for b in KEEPOUT_BOXES])
_HI = np.array([b.hi for b in KEEPOUT_BOXES])
#: (K, 3, 3): each box's turn; a point p (3,) in `base` is p @ turn in the box's axes.
_TURNS = np.array([b.turn for b in KEEPOUT_BOXES], float)
_IS_TURNED = np.array([b.turn != IDENTITY for b in KEEPOUT_BOXES])
_TURNED = np.flatnonzero(_IS_TURNED)
_ALIGNED = np.setdiff1d(np.arange(len(KEEPOUT_BOXES)), _TURNED)
#: (3, 3 * turned): one product takes a point into every turned box's axes at once.
_INTO_TURNED = _TURNS[_TURNED].transpose(1, 0, 2).reshape(3, -1)
#: (7, K): whether arm body b (0 = link1 ... 6 = the hand, and what it holds) is checked
#: against keep-out box k.
BOX_CHECKS = np.array([[b not in box.spares for box in KEEPOUT_BOXES] for b in range(7)])


def _gaps(local: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Distance from points (..., K, 3) in K boxes' axes to boxes lo..hi (K, 3), 0 inside."""
    gap = np.maximum(np.maximum(lo - local, local - hi), 0.0)
    return np.sqrt(np.einsum("...i,...i->...", gap, gap))


def box_gaps(points: np.ndarray) -> np.ndarray:
    """Distance (m) from points (..., 3) of `base` to each keep-out box, 0 inside: (..., K).
    Only the few turned boxes take the points into their own axes."""
    out = np.empty((*points.shape[:-1], len(KEEPOUT_BOXES)))
    out[..., _ALIGNED] = _gaps(points[..., None, :], _LO[_ALIGNED], _HI[_ALIGNED])
    turned = (points @ _INTO_TURNED).reshape(*points.shape[:-1], len(_TURNED), 3)
    out[..., _TURNED] = _gaps(turned, _LO[_TURNED], _HI[_TURNED])
    return out


def box_contacts(
    centres: np.ndarray,
    reach: np.ndarray,
    body: np.ndarray,
    grouped: tuple[np.ndarray, list[Ball]] | None = None,
) -> np.ndarray:
    """(B, S, K) whether each sphere comes within its `reach` (S,) (m: its radius and the
    margin) of each keep-out box that checks its `body` (S,) (`BOX_CHECKS`), at centres
    (B, S, 3) (m, `base`): the verdicts of comparing `box_gaps` of every centre, the many
    spheres of one body measured only against the boxes their ball comes near
    (`broad_phase.balls`, or `grouped`, what it gave for these spheres)."""
    few, bounded = grouped if grouped is not None else balls(centres, reach, body)
    if not bounded:  # every sphere one by one, as they come
        return (box_gaps(centres) < reach[:, None]) & BOX_CHECKS[body]
    out = np.zeros((*centres.shape[:2], len(KEEPOUT_BOXES)), bool)
    if len(few):
        near = box_gaps(centres[:, few]) < reach[few, None]
        out[:, few] = near & BOX_CHECKS[body[few]]
    for ball in bounded:
        near_ball = (box_gaps(ball.middle) < ball.radius[:, None]) & BOX_CHECKS[ball.body]
        rows, boxes = np.nonzero(near_ball)
        if len(rows):
            mine = ball.spheres
            near = _gaps_to(centres[rows[:, None], mine[None, :]], boxes) < reach[mine]
            out[rows[:, None], mine[None, :], boxes[:, None]] = near
    return out


def _gaps_to(points: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """Distance (m) from points (M, N, 3) of `base` to keep-out box boxes[m] (M,), 0
    inside: (M, N), as `box_gaps` measures it."""
    turned = _IS_TURNED[boxes]
    local = points
    if turned.any():
        local = points.copy()
        local[turned] = np.einsum("mni,mij->mnj", points[turned], _TURNS[boxes[turned]])
    return _gaps(local, _LO[boxes][:, None], _HI[boxes][:, None])
