"""Which cloud points the arm is checked against: those within its reach, above the floor's
clearance, thinned, that are neither the arm itself nor the scooter; and the points that
stand for what the cameras could not see but must be there (a surface's front).
Frames: `base`, metres.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from laserpick.description.dims import ARM_MOUNT_POS, UR5_D
from laserpick.description.shapes import FLOOR_CLEARANCE, body_frames
from laserpick.pipeline.cloud import thin
from laserpick.pipeline.collision.arm_spheres import SPHERES, sphere_centres
from laserpick.pipeline.collision.carried import CARRIED_VOXEL
from laserpick.pipeline.collision.keepout import box_gaps

#: The arm's reach from its shoulder, with the open hand (m): obstacles beyond cannot matter.
REACH = 1.15
_SHOULDER = np.array([*ARM_MOUNT_POS[:2], ARM_MOUNT_POS[2] + UR5_D[0]])
#: Points this close (m) to a keep-out box are taken to be the scooter seen by its cameras.
SELF_PADDING = 0.02


def self_filter(points: np.ndarray, q: np.ndarray, padding: float = 0.03) -> np.ndarray:
    """Mask (N,) of the points that are not the arm itself at joint angles q (6,): a real
    robot's self filter, so the planner does not take its own arm for an obstacle.

    padding (m) grows every sphere, for sensor noise and the capture's timing.
    """
    centres = sphere_centres(body_frames(q))[0]
    keep = np.ones(len(points), bool)
    if len(points) == 0:
        return keep
    tree = cKDTree(np.asarray(points, float))
    for c, r in zip(centres, SPHERES.radius + padding, strict=True):
        keep[tree.query_ball_point(c, r)] = False
    return keep


def within_reach(points: np.ndarray) -> np.ndarray:
    """Mask (N,) of the points (N, 3), `base`, m, that the arm, its hand and what the hand
    holds could touch: finite and within REACH of the shoulder. No other point can matter to
    a collision check."""
    d = np.asarray(points, np.float32).reshape(-1, 3) - _SHOULDER.astype(np.float32)
    with np.errstate(invalid="ignore"):
        return np.einsum("ij,ij->i", d, d) < REACH**2  # NaN compares false: it drops out


def obstacle_mask(
    points: np.ndarray, *, voxel: float = 0.01, q_self: np.ndarray | None = None
) -> np.ndarray:
    """Mask (N,) of the points worth checking against: finite, within the arm's reach, above
    the floor's clearance (no sphere goes lower: the floor itself is checked exactly), one
    per `voxel` (m; 0 keeps all), not the arm itself at q_self (rad) if given, and not the
    scooter (inside its keep-out boxes, which the checker tests exactly)."""
    with np.errstate(invalid="ignore"):
        mask = within_reach(points) & (points[:, 2] > FLOOR_CLEARANCE)
    idx = np.flatnonzero(mask)
    if voxel > 0:
        idx = idx[thin(points[idx], voxel)]
    if q_self is not None:
        idx = idx[self_filter(points[idx], q_self)]
    # The scooter and its rider, where the cameras see them, are the keep-out boxes already.
    inside = (box_gaps(np.asarray(points[idx], float)) <= SELF_PADDING).any(axis=1)
    idx = idx[~inside]
    out = np.zeros(len(points), bool)
    out[idx] = True
    return out


def surface_front(
    points: np.ndarray, height: float, band: float, voxel: float = CARRIED_VOXEL
) -> np.ndarray:
    """Points (m, `base`) that stand for the front of a surface the cameras saw from above: a
    wall across the whole width they saw of it, as near to the robot as the nearest of its
    top they saw, from `height` (m) down to the floor's clearance, a point per `voxel` (m).

    points (N, 3), `base`: the cloud; those within `band` (m) of `height` are the surface's
    top. The cameras look down and ahead, so a counter's front runs out of their view before
    its top does, and its near edge with it (the view's edge cuts the top on a slant): a
    counter's unseen front can stand 20 cm nearer than its seen top's edge. A table is open below
    its edge and a round one's edge curves away; the arm has no business under either, so
    the wall only makes the planner more careful there."""
    points = np.asarray(points, float).reshape(-1, 3)
    top = points[np.abs(points[:, 2] - height) < band]
    z = np.arange(height - voxel, FLOOR_CLEARANCE, -voxel)
    if len(top) == 0 or len(z) == 0:
        return np.zeros((0, 3))
    y = np.arange(top[:, 1].min(), top[:, 1].max() + voxel, voxel)
    return np.column_stack(
        [np.full(len(y) * len(z), top[:, 0].min()), np.repeat(y, len(z)), np.tile(z, len(y))]
    )
