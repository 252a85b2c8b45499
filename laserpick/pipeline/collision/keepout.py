"""How far points are from the keep-out boxes around the scooter and its rider
(`description.shapes.KEEPOUT_BOXES`), and which of the arm's bodies each box is checked
against. Frames: `base`, metres.
"""

from __future__ import annotations

import numpy as np

from laserpick.description.shapes import IDENTITY, KEEPOUT_BOXES

_LO = np.array([b.lo for b in KEEPOUT_BOXES])
_HI = np.array([b.hi for b in KEEPOUT_BOXES])
_TURNED = np.flatnonzero([b.turn != IDENTITY for b in KEEPOUT_BOXES])
_ALIGNED = np.setdiff1d(np.arange(len(KEEPOUT_BOXES)), _TURNED)
#: (3, 3 * turned): one product takes a point into every turned box's axes at once.
_INTO_TURNED = np.array([KEEPOUT_BOXES[k].turn for k in _TURNED]).transpose(1, 0, 2).reshape(3, -1)
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
