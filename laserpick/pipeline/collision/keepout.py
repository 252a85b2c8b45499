"""How far points are from the keep-out boxes around the scooter and its rider
(`description.shapes.KEEPOUT_BOXES`), which of the arm's bodies each box is checked
against, and which of the arm's spheres come within reach of one. Frames: `base`, metres.
"""

from __future__ import annotations

import numpy as np

from laserpick.description.shapes import IDENTITY, KEEPOUT_BOXES
from laserpick.pipeline.collision.broad_phase import BodyBalls, body_balls

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
    bounded: BodyBalls | None = None,
) -> np.ndarray:
    """(B, S, K) whether each sphere comes within its `reach` (S,) (m: its radius and the
    margin) of each keep-out box that checks its `body` (S,) (`BOX_CHECKS`), at centres
    (B, S, 3) (m, `base`): the verdicts of comparing `box_gaps` of every centre, a body's
    spheres measured only against the boxes its ball comes near (`broad_phase.body_balls`,
    or `bounded`, what it gave for these spheres)."""
    balls = bounded if bounded is not None else body_balls(centres, reach, body)
    out = np.zeros((*centres.shape[:2], len(KEEPOUT_BOXES)), bool)
    ball_body = body[balls.order[balls.starts]]
    near = (box_gaps(balls.middle) < balls.radius[..., None]) & BOX_CHECKS[ball_body][None]
    rows, groups, boxes = np.nonzero(near)
    if len(rows):
        pair, sphere = balls.members(rows, groups)
        row, box = rows[pair], boxes[pair]
        out[row, sphere, box] = _gaps_to(centres[row, sphere], box) < reach[sphere]
    return out


def _gaps_to(points: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """Distance (m) from each point (N, 3) of `base` to keep-out box boxes[n] (N,), 0
    inside: (N,), as `box_gaps` measures it."""
    turned = _IS_TURNED[boxes]
    local = points
    if turned.any():
        local = points.copy()
        local[turned] = np.einsum("ni,nij->nj", points[turned], _TURNS[boxes[turned]])
    return _gaps(local, _LO[boxes], _HI[boxes])
