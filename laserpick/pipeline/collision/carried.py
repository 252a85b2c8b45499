"""What the hand carries: the points that stand for a held object (its seen part, its unseen
back guessed by symmetry, down to its support), where they are as the arm moves, whether they
keep clear of the arm's own links, and which cloud points are the object itself.
Frames: `base` or the TCP frame, as each function says; metres.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from laserpick.description.kinematics import T_FLANGE_TCP
from laserpick.description.shapes import body_frames
from laserpick.pipeline.cloud import thin
from laserpick.pipeline.collision.arm_spheres import SPHERES, sphere_centres
from laserpick.pipeline.collision.broad_phase import BROAD_SLACK, enclosing

#: Radius (m) of each point of a held object's cloud, as carried by the hand.
PAYLOAD_POINT_RADIUS = 0.01
#: A held object is checked against the arm's bodies up to this one (3: wrist 1).
PAYLOAD_CLEAR_OF_BODY = 3
#: Voxel (m) a carried object's points are thinned to, and the band (m) under its highest
#: point taken as its top.
CARRIED_VOXEL = 0.02
CARRIED_TOP_BAND = 0.02
#: Points this close (m) to a held object's points are taken to be the object itself.
CARRIED_PADDING = 0.03
#: The cell (m) of the coarse payload a configuration is checked with first, one point of
#: the held object in each (`coarse_payload`).
COARSE_PAYLOAD = 0.05


def coarse_payload(payload: np.ndarray) -> np.ndarray:
    """The first of a held object's points `payload` (P, 3) (m) in each cube of side
    COARSE_PAYLOAD: a configuration that does not clear these cannot clear them all, so
    checked first, they reject most blocked configurations at a fraction of the work."""
    if len(payload) == 0:
        return payload
    cells = np.floor(payload / COARSE_PAYLOAD).astype(np.int64)
    _, first = np.unique(cells, axis=0, return_index=True)
    return payload[np.sort(first)]


def held_points(frames: np.ndarray, payload: np.ndarray) -> np.ndarray:
    """Where (B, P, 3; m, `base`) the points `payload` (P, 3; m, TCP frame) of a held object
    are with the arm at body frames (B, 7, 4, 4)."""
    return held_at(frames[:, 6] @ T_FLANGE_TCP, payload)


def held_at(T_tcp: np.ndarray, payload: np.ndarray) -> np.ndarray:
    """Where (B, P, 3; m, `base`) the points `payload` (P, 3; m, TCP frame) of a held object
    are with the TCP at poses `T_tcp` (B, 4, 4; `base`)."""
    return np.einsum("bij,pj->bpi", T_tcp[:, :3, :3], payload) + T_tcp[:, None, :3, 3]


def held_clear_of_arm(Q: np.ndarray, payload: np.ndarray, margin: float) -> np.ndarray:
    """(B,) whether a held object (`payload`, its points (P, 3) in the TCP frame, m) keeps
    `margin` (m) off the arm's own upper links (up to PAYLOAD_CLEAR_OF_BODY) at each
    configuration Q[b] (B, 6) (rad). The wrist links next to the hand are expected near it."""
    frames = body_frames(np.atleast_2d(Q))
    return off_upper_links(sphere_centres(frames), held_points(frames, payload), margin)


def off_upper_links(centres: np.ndarray, held: np.ndarray, margin: float) -> np.ndarray:
    """`held_clear_of_arm` for the arm's sphere centres (B, S, 3; m, `base`,
    `sphere_centres`) and the held points where they are (B, P, 3; m, `base`,
    `held_points`). Point by point only against the link spheres that the ball about the
    points' mean, holding them all, comes within reach of: the held object is mostly far
    from the upper arm, and its points are many."""
    upper = SPHERES.body <= PAYLOAD_CLEAR_OF_BODY
    links = centres[:, upper]
    reach = SPHERES.radius[upper] + PAYLOAD_POINT_RADIUS + margin
    middle, spread = enclosing(held)
    apart = np.linalg.norm(links - middle[:, None], axis=-1)
    rows, near = np.nonzero(apart < spread[:, None] + reach + BROAD_SLACK)
    gap = np.linalg.norm(held[rows] - links[rows, near][:, None], axis=-1)
    clear = np.ones(len(held), bool)
    clear[rows[(gap < reach[near][:, None]).any(axis=1)]] = False
    return clear


def mirrored_back(
    target: np.ndarray, normals: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray | None]:
    """The unseen back of an object, guessed by symmetry: its seen points (N, 3) (m, `base`)
    turned half a turn about the vertical axis through the middle of its top, and their
    outward normals (N, 3) turned with them (None without `normals`).

    The cameras see an object from the front and above only. Most household objects (boxes,
    bottles, cans, cups) are symmetric under that half turn, so it fills in their back. The
    axis is the middle of the top band's extent: the top is seen whole from above, while the
    band's mean would lean toward the cameras, where the seen sides add points.
    """
    target = np.asarray(target, float).reshape(-1, 3)
    if len(target) == 0:
        return target.copy(), None if normals is None else np.zeros((0, 3))
    top = target[target[:, 2] > target[:, 2].max() - CARRIED_TOP_BAND]
    middle = (top[:, :2].min(axis=0) + top[:, :2].max(axis=0)) / 2
    back = target.copy()
    back[:, :2] = 2.0 * middle - target[:, :2]
    if normals is None:
        return back, None
    turned = np.array(normals, float).reshape(-1, 3)
    turned[:, :2] *= -1.0
    return back, turned


def carried_shape(
    target: np.ndarray, support: float | None = None, voxel: float = CARRIED_VOXEL
) -> np.ndarray:
    """The points (m, `base`) that stand for an object the hand is about to carry: what the
    cameras saw of it (and, where their view cut it off, what stands for the rest:
    `beyond_view`), mirrored through the vertical axis of its top, and reaching down to the
    surface it stands on.

    The cameras see an object from the front and above only, so its back half, and near a
    table's edge its lower part, are missing from `target` (N, 3), and a carry planned around
    the seen part alone swings them into the arm. `mirrored_back` fills in the back of a box
    or a cylinder;
    each `voxel` (m) column of the footprint is filled down to `support` (m, the surface's
    height; None: no filling), since the object stands on it. Other shapes are over-covered,
    which only makes the planner more careful. Thinned to one point per `voxel`.
    """
    target = np.asarray(target, float).reshape(-1, 3)
    if len(target) == 0:
        return target
    both = np.vstack([target, mirrored_back(target)[0]])
    if support is not None:
        columns, which = np.unique(np.floor(both[:, :2] / voxel), axis=0, return_inverse=True)
        low = np.full(len(columns), np.inf)
        np.minimum.at(low, which.ravel(), both[:, 2])
        fill = [
            np.c_[np.tile((c + 0.5) * voxel, (len(z), 1)), z]
            for c, bottom in zip(columns, low, strict=True)
            if len(z := np.arange(support + voxel / 2, bottom, voxel))
        ]
        both = np.vstack([both, *fill])
    return both[thin(both, voxel)]


def object_middle(target: np.ndarray, carried: np.ndarray) -> np.ndarray:
    """The middle (m, `base`) of the bounds of an object the cameras saw as `target` (N, 3;
    m, `base`), whose unseen back `carried` (M, 3; `carried_shape`) fills in: the point a
    place turns it about (`behaviours.turned_hand_xy`).

    The cameras look ahead, along the base's x axis. Along it, the middle is `carried`'s:
    they saw only the object's front, and the half turn adds its back. Across it, it is the
    middle of what they saw, since the outline of a convex object seen from the front shows
    its whole width; the half turn's axis is the middle of the top they saw, and a top
    above the cameras shows only part of itself, so its half turn's axis lies off the
    object's middle. Upright, the middle of `carried`'s height."""
    target = np.asarray(target, float).reshape(-1, 3)
    carried = np.asarray(carried, float).reshape(-1, 3)
    middle = (carried.min(axis=0) + carried.max(axis=0)) / 2
    if len(target):
        middle[1] = (target[:, 1].min() + target[:, 1].max()) / 2
    return middle


def not_carried(
    points: np.ndarray, carried: np.ndarray, padding: float = CARRIED_PADDING
) -> np.ndarray:
    """Mask (N,) of the points (N, 3) that are not the held object, whose points (M, 3) are
    `carried` (m, one frame for both): none of them within `padding` (m). The cameras see
    what the hand holds, and it must not be taken for an obstacle to its own carry."""
    if len(carried) == 0 or len(points) == 0:
        return np.ones(len(points), bool)
    d, _ = cKDTree(np.asarray(carried, float)).query(points, distance_upper_bound=padding)
    return ~np.isfinite(d)
