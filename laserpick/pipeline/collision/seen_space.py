"""Space the cameras saw: a planned transit keeps the hand, and what it holds, where a camera
saw through, where the arm itself stood, or on the fixed way out of the stowed pose.
Frames: `base`, metres.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.spatial import cKDTree

from laserpick.description.dims import UR5_HOME_Q, UR5_UNSTOW_Q
from laserpick.description.shapes import body_frames
from laserpick.pipeline.collision.arm_spheres import SPHERES, sphere_centres
from laserpick.pipeline.free_space import seen_free
from laserpick.types import DepthFrame

#: Space within this much (m) of where the arm's spheres were when the frames were captured,
#: or of where the hand passes on the way out of the stowed pose, counts as seen.
OWN_SPACE_PADDING = 0.02
#: A camera saw a point free when its reading lies this far (m) beyond it: three times the
#: sensors' depth noise at 1.2 m, as for the fingers' free-space test.
SEEN_TOLERANCE = 0.006
#: Where a sphere is tested for seen space, in radii from its centre: the centre, and its
#: surface along each axis of `base`.
_SPHERE_PROBES = np.vstack([np.zeros(3), np.eye(3), -np.eye(3)])


def _unstow_box() -> tuple[np.ndarray, np.ndarray]:
    """The box (lo, hi; `base`, m) around the hand's spheres on the straight joint move from
    the stowed pose to the unstow pose, grown by OWN_SPACE_PADDING: the scooter's own side,
    which no camera sees and the hand must pass (the user keeps it clear, as a scooter
    user keeps clear the side the arm folds out on)."""
    Q = np.linspace(UR5_HOME_Q, UR5_UNSTOW_Q, 40)
    centres = sphere_centres(body_frames(Q))[:, SPHERES.hand].reshape(-1, 3)
    r = np.tile(SPHERES.radius[SPHERES.hand], len(Q))[:, None]
    pad = OWN_SPACE_PADDING
    return (centres - r).min(axis=0) - pad, (centres + r).max(axis=0) + pad


UNSTOW_BOX = _unstow_box()


class OwnSpace:
    """Space the arm fills, as spheres (centres (N, 3), `base`, m; reach (N,) m)."""

    #: Each point is tested against this many nearest centres: the spheres overlap, so one
    #: that holds a point is among its nearest; a miss only counts the point unseen.
    NEAREST = 24

    def __init__(self, centres: np.ndarray, reach: np.ndarray):
        self.centres, self.reach = centres, reach
        self._tree = cKDTree(centres) if len(centres) else None

    def holds(self, points: np.ndarray) -> np.ndarray:
        """(P,) whether each point (P, 3) lies within some sphere's reach."""
        if self._tree is None or not len(points):
            return np.zeros(len(points), bool)
        k = min(self.NEAREST, len(self.centres))
        d, j = self._tree.query(points, k=k, distance_upper_bound=float(self.reach.max()))
        d, j = d.reshape(len(points), k), j.reshape(len(points), k)
        inside = np.isfinite(d)
        inside[inside] = d[inside] <= self.reach[j[inside]]
        return inside.any(axis=1)


def unseen_spheres(
    centres: np.ndarray, radius: np.ndarray, frames: Sequence[DepthFrame], own: OwnSpace
) -> np.ndarray:
    """(N,) whether each sphere (centres (N, 3), `base`, m; radius (N,) m) reaches into
    space no camera of `frames` saw, tested at its centre and the six points of its surface
    along `base`'s axes. A point counts as seen where a camera saw past it (by
    SEEN_TOLERANCE), inside the arm's `own` space, or inside UNSTOW_BOX. Points, not whole
    spheres, so that a sphere may straddle two of these. False for all without frames."""
    if not frames or not len(centres):
        return np.zeros(len(centres), bool)
    points = (centres[:, None] + radius[:, None, None] * _SPHERE_PROBES).reshape(-1, 3)
    lo, hi = UNSTOW_BOX
    blind = ~((points >= lo) & (points <= hi)).all(axis=1)
    i = np.flatnonzero(blind)
    blind[i[seen_free(points[i], frames, SEEN_TOLERANCE)]] = False
    i = np.flatnonzero(blind)
    blind[i[own.holds(points[i])]] = False
    return blind.reshape(len(centres), -1).any(axis=1)
