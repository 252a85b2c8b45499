"""Arm collision checks for planning (paper 004 section 7): the UR5 and its gripper as chains
of spheres, tested against the fused cloud (a KD-tree of voxel-thinned points), the keep-out
boxes around the scooter and its rider, and the floor; on planned transits, also against the
space no camera saw (`CollisionChecker.clearance_ok(seen=True)`).

Spheres cover the capsules of `description/collision.py` (a capsule of radius r as spheres at
most r apart, each grown to cover the waist between neighbours). Frames: `base`, metres.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from laserpick.description.collision import (
    FLOOR_CLEARANCE,
    GRIPPER_CAPSULES,
    HOUSING_CAPSULES,
    IDENTITY,
    KEEPOUT_BOXES,
    LINK_CAPSULES,
    Segment,
    body_frames,
)
from laserpick.description.dims import ARM_MOUNT_POS, UR5_D, UR5_HOME_Q, UR5_UNSTOW_Q
from laserpick.description.kinematics import T_FLANGE_TCP
from laserpick.pipeline.cloud import voxel_first
from laserpick.pipeline.free_space import seen_free
from laserpick.types import DepthFrame


@dataclass(frozen=True)
class SphereModel:
    """Sphere centres in their body frames and radii (m). body: 0..5 the links, 6 the flange."""

    body: np.ndarray  #: (S,) int
    centre: np.ndarray  #: (S, 3) in the body's frame
    radius: np.ndarray  #: (S,)
    hand: np.ndarray  #: (S,) bool: part of the gripper


def _spheres(segment: Segment) -> tuple[np.ndarray, float]:
    a, b, r = np.asarray(segment[0], float), np.asarray(segment[1], float), segment[2]
    length = float(np.linalg.norm(b - a))
    if length == 0.0:  # a ball: a joint housing
        return a[None], r
    n = max(2, math.ceil(length / r) + 1)
    return np.linspace(a, b, n), math.hypot(r, length / (n - 1) / 2)


def sphere_model() -> SphereModel:
    """The arm's spheres, built from the shared tables of link capsules, joint housings
    and gripper capsules."""
    body, centre, radius, hand = [], [], [], []
    parts = [(i, seg, False) for i, segs in enumerate(LINK_CAPSULES) for seg in segs]
    parts += [(i, seg, False) for i, seg in enumerate(HOUSING_CAPSULES)]
    parts += [(6, seg, True) for seg in GRIPPER_CAPSULES]
    for i, seg, is_hand in parts:
        c, r = _spheres(seg)
        body += [i] * len(c)
        centre.append(c)
        radius += [r] * len(c)
        hand += [is_hand] * len(c)
    return SphereModel(
        np.array(body), np.vstack(centre), np.array(radius), np.array(hand, dtype=bool)
    )


SPHERES = sphere_model()
_LO = np.array([b.lo for b in KEEPOUT_BOXES])
_HI = np.array([b.hi for b in KEEPOUT_BOXES])
_TURNED = np.flatnonzero([b.turn != IDENTITY for b in KEEPOUT_BOXES])
_ALIGNED = np.setdiff1d(np.arange(len(KEEPOUT_BOXES)), _TURNED)
#: (3, 3 * turned): one product takes a point into every turned box's axes at once.
_INTO_TURNED = np.array([KEEPOUT_BOXES[k].turn for k in _TURNED]).transpose(1, 0, 2).reshape(3, -1)


def _gaps(local: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Distance from points (..., K, 3) in K boxes' axes to boxes lo..hi (K, 3), 0 inside."""
    gap = np.maximum(np.maximum(lo - local, local - hi), 0.0)
    return np.sqrt(np.einsum("...i,...i->...", gap, gap))


def _box_gaps(points: np.ndarray) -> np.ndarray:
    """Distance (m) from points (..., 3) of `base` to each keep-out box, 0 inside: (..., K).
    Only the few turned boxes take the points into their own axes."""
    out = np.empty((*points.shape[:-1], len(KEEPOUT_BOXES)))
    out[..., _ALIGNED] = _gaps(points[..., None, :], _LO[_ALIGNED], _HI[_ALIGNED])
    turned = (points @ _INTO_TURNED).reshape(*points.shape[:-1], len(_TURNED), 3)
    out[..., _TURNED] = _gaps(turned, _LO[_TURNED], _HI[_TURNED])
    return out


#: (7, K): whether arm body b (0 = link1 ... 6 = the hand, and what it holds) is checked
#: against keep-out box k.
_CHECKED = np.array([[b not in box.spares for box in KEEPOUT_BOXES] for b in range(7)])
#: The body a held object's spheres count as.
HAND_BODY = 6


def sphere_centres(frames: np.ndarray, model: SphereModel = SPHERES) -> np.ndarray:
    """World (`base`) centres (B, S, 3) of the spheres for body frames (B, 7, 4, 4)."""
    F = frames[:, model.body]  # (B, S, 4, 4)
    return np.einsum("bsij,sj->bsi", F[..., :3, :3], model.centre) + F[..., :3, 3]


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
    return _off_upper_links(frames, held_points(frames, payload), margin)


def _off_upper_links(frames: np.ndarray, held: np.ndarray, margin: float) -> np.ndarray:
    """`held_clear_of_arm` for body frames (B, 7, 4, 4) and the held points where they are
    (B, P, 3; m, `base`, `held_points`)."""
    upper = SPHERES.body <= PAYLOAD_CLEAR_OF_BODY
    links = sphere_centres(frames)[:, upper]
    gap = np.linalg.norm(held[:, :, None] - links[:, None], axis=-1)
    reach = SPHERES.radius[upper] + PAYLOAD_POINT_RADIUS + margin
    return ~(gap < reach).any(axis=(1, 2))


#: The arm's reach from its shoulder, with the open hand (m): obstacles beyond cannot matter.
REACH = 1.15
_SHOULDER = np.array([*ARM_MOUNT_POS[:2], ARM_MOUNT_POS[2] + UR5_D[0]])
#: Points this close (m) to a keep-out box are taken to be the scooter seen by its cameras.
SELF_PADDING = 0.02
#: Radius (m) of each point of a held object's cloud, as carried by the hand.
PAYLOAD_POINT_RADIUS = 0.01
#: Voxel (m) a carried object's points are thinned to, and the band (m) under its highest
#: point taken as its top.
CARRIED_VOXEL = 0.02
CARRIED_TOP_BAND = 0.02
#: Points this close (m) to a held object's points are taken to be the object itself.
CARRIED_PADDING = 0.03
#: A held object is checked against the arm's bodies up to this one (3: wrist 1).
PAYLOAD_CLEAR_OF_BODY = 3
#: A joint segment's every this-many-th configuration is checked before the rest.
SEGMENT_COARSE = 8
#: Halvings of the margin that find the clearance a configuration keeps (`clearance_kept`):
#: 8 find a 1 cm margin's share to within 0.04 mm.
CLEARANCE_STEPS = 8
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


def thin(points: np.ndarray, voxel: float) -> np.ndarray:
    """Mask of one point (the first) per occupied voxel of edge `voxel` (m)."""
    keep = np.zeros(len(points), bool)
    keep[voxel_first(points, voxel)] = True
    return keep


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
    table's edge its lower part, are missing from `target` (N, 3); a carry planned around
    the seen part alone swung a mug's unseen back into the forearm, and a soda can's unseen
    lower half into the upper arm. `mirrored_back` fills in the back of a box or a cylinder;
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
    above the cameras shows only part of itself. A cereal box on the 100 cm shelf was seen
    along all of its 19 cm length but its top along only the 15 cm nearest one end:
    carried as 22.6 cm long, it was set down turned 135 degrees and 4 cm off its mark.
    Upright, the middle of `carried`'s height."""
    target = np.asarray(target, float).reshape(-1, 3)
    carried = np.asarray(carried, float).reshape(-1, 3)
    middle = (carried.min(axis=0) + carried.max(axis=0)) / 2
    if len(target):
        middle[1] = (target[:, 1].min() + target[:, 1].max()) / 2
    return middle


def surface_front(
    points: np.ndarray, height: float, band: float, voxel: float = CARRIED_VOXEL
) -> np.ndarray:
    """Points (m, `base`) that stand for the front of a surface the cameras saw from above: a
    wall across the whole width they saw of it, as near to the robot as the nearest of its
    top they saw, from `height` (m) down to the floor's clearance, a point per `voxel` (m).

    points (N, 3), `base`: the cloud; those within `band` (m) of `height` are the surface's
    top. The cameras look down and ahead, so a counter's front runs out of their view before
    its top does, and its near edge with it (the view's edge cuts the top on a slant): a
    stow planned around what they saw swung the upper arm into the 87 cm counter's unseen
    front (203 N), about 20 cm nearer than the seen top's edge there. A table is open below
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
    inside = (_box_gaps(np.asarray(points[idx], float)) <= SELF_PADDING).any(axis=1)
    idx = idx[~inside]
    out = np.zeros(len(points), bool)
    out[idx] = True
    return out


class _OwnSpace:
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


class CollisionChecker:
    """Is the arm clear of the cloud, the scooter and the floor at these joint angles?

    obstacles: (N, 3) points in `base` (m). Points beyond the arm's reach are dropped, the
    rest thinned to one per `voxel` (m) for the KD-tree. margin: clearance (m) kept from
    every obstacle on top of the spheres' radii. q_self: the arm's joint angles when the
    points were captured, to filter out the arm's own points. filtered: the points have
    been through `obstacle_mask` already (voxel is then unused). frames: the depth frames
    the points came from, for the seen-space test of planned transits (none: every space
    counts as seen, as before the test; q_self then says where the arm stood in them).
    """

    def __init__(
        self,
        obstacles: np.ndarray,
        *,
        margin: float = 0.01,
        voxel: float = 0.01,
        q_self: np.ndarray | None = None,
        filtered: bool = False,
        frames: Sequence[DepthFrame] = (),
    ):
        pts = np.asarray(obstacles, float).reshape(-1, 3)
        if not filtered:  # `filtered`: the points already passed obstacle_mask
            pts = pts[obstacle_mask(pts, voxel=voxel, q_self=q_self)]
        self.points = pts
        self.tree = cKDTree(self.points) if len(self.points) else None
        self.margin = margin
        #: m the arm keeps above the floor (z = 0 in `base`): see `floor_as_support`
        self.floor_clearance = FLOOR_CLEARANCE
        self.frames = tuple(frames)
        # Where the arm stood counts as seen; only the seen-space test, with frames, asks.
        stood = q_self is not None and bool(self.frames)
        own = sphere_centres(body_frames(q_self))[0] if stood else np.zeros((0, 3))
        self._own = _OwnSpace(own, SPHERES.radius[: len(own)] + OWN_SPACE_PADDING)

    @classmethod
    def world_and_surroundings(
        cls,
        points: np.ndarray,
        target: np.ndarray,
        *,
        margin: float = 0.01,
        voxel: float = 0.01,
        q_self: np.ndarray | None = None,
        frames: Sequence[DepthFrame] = (),
    ) -> tuple[CollisionChecker, CollisionChecker]:
        """Checkers for the whole cloud and for the cloud without the `target` (indices),
        sharing one pass of cropping, thinning and self filtering. The whole cloud's checker
        is the one transits are planned with: it alone gets the frames."""
        pts = np.asarray(points, float).reshape(-1, 3)
        keep = obstacle_mask(pts, voxel=voxel, q_self=q_self)
        others = keep.copy()
        others[target] = False
        return (
            cls(pts[keep], margin=margin, filtered=True, q_self=q_self, frames=frames),
            cls(pts[others], margin=margin, filtered=True),
        )

    def clearance_ok(
        self,
        Q: np.ndarray,
        *,
        hand: bool = True,
        payload: np.ndarray | None = None,
        margin: float | None = None,
        seen: bool = False,
    ) -> np.ndarray:
        """(B,) True where configuration Q[b] (B, 6) (rad) collides with nothing.

        hand: include the gripper's spheres (grasp detection already checked the hand at the
        grasp itself). payload: a held object's points (P, 3) in the TCP frame (m), each a
        sphere of PAYLOAD_POINT_RADIUS carried with the hand. margin: overrides the
        checker's clearance (m). seen: also keep the hand and what it holds where the
        cameras saw through (`unseen`): a planned transit may not take space no camera saw
        for free. The hand is what swings out into the room, into furniture beyond the
        cameras' view (a bookshelf's board); the shoulder and upper arm stay below and beside
        the sensor posts, where no camera looks, so they are not held to it.
        """
        margin = self.margin if margin is None else margin
        Q = np.atleast_2d(np.asarray(Q, float))
        frames = body_frames(Q)
        centres = sphere_centres(frames)
        radius, body = SPHERES.radius, SPHERES.body
        if not hand:
            keep = ~SPHERES.hand
            centres, radius, body = centres[:, keep], radius[keep], body[keep]
        clear = np.ones(len(Q), bool)
        if payload is not None and len(payload):
            held = held_points(frames, payload)
            clear &= _off_upper_links(frames, held, margin)
            centres = np.concatenate([centres, held], axis=1)
            radius = np.append(radius, np.full(len(payload), PAYLOAD_POINT_RADIUS))
            body = np.append(body, np.full(len(payload), HAND_BODY))
        clear &= ~self._hits(centres, radius, body, margin).any(axis=1)
        rows = np.flatnonzero(clear) if seen and self.frames else np.zeros(0, int)
        if len(rows):  # only the configurations still clear: this projects into every camera
            out = body == HAND_BODY
            spheres = centres[rows][:, out].reshape(-1, 3)
            blind = self.unseen(spheres, np.tile(radius[out], len(rows)))
            clear[rows[blind.reshape(len(rows), -1).any(axis=1)]] = False
        return clear

    def clearance_kept(
        self, q: np.ndarray, *, hand: bool = True, steps: int = CLEARANCE_STEPS
    ) -> float | None:
        """The clearance (m) configuration q (6,) (rad) keeps from everything: the checker's
        margin where it is clear, else the largest smaller margin at which it is (found by
        halving, to within margin / 2**steps), None where it touches something (not clear
        at no margin). A move out from where a place left the arm may keep this much, not
        more: the forearm let down with an object onto the 31 cm table stood 4 mm above it."""
        q = np.asarray(q, float)
        if self.clearance_ok(q, hand=hand)[0]:
            return self.margin
        if not self.clearance_ok(q, hand=hand, margin=0.0)[0]:
            return None
        lo, hi = 0.0, self.margin
        for _ in range(steps):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if self.clearance_ok(q, hand=hand, margin=mid)[0] else (lo, mid)
        return lo

    def knowing(self, *Q: np.ndarray) -> CollisionChecker:
        """This checker, with the arm's spheres at configurations Q (6,) (rad) counted as seen
        too, as where it stood at capture: a leg's ends, where the arm stands before it and
        must stand after (a pre-grasp beside the cameras' view, checked against the cloud).
        Without frames nothing is unseen, and the checker is returned as it is."""
        if not self.frames:
            return self
        out = copy.copy(self)
        centres = sphere_centres(body_frames(np.array(Q, float))).reshape(-1, 3)
        reach = np.tile(SPHERES.radius + OWN_SPACE_PADDING, len(Q))
        own = self._own
        out._own = _OwnSpace(np.vstack([own.centres, centres]), np.append(own.reach, reach))
        return out

    def with_points(self, extra: np.ndarray) -> CollisionChecker:
        """This checker with the points `extra` (M, 3) (m, `base`; already through
        `obstacle_mask`) added after its own (what the cameras could not see but must be
        there: a wall under a surface's seen front); the same margin and seen space.
        Returned as it is when there are none."""
        if len(extra) == 0:
            return self
        out = copy.copy(self)
        out.points = np.vstack([self.points, extra])
        out.tree = cKDTree(out.points)
        return out

    def without(self, drop: np.ndarray) -> CollisionChecker:
        """This checker less its points where the mask `drop` (N,) is set (what is known to
        be no obstacle: parts of the target the segmentation left out); the same margin and
        seen space. Returned as it is when nothing is dropped."""
        if not drop.any():
            return self
        out = copy.copy(self)
        out.points = self.points[~drop]
        out.tree = cKDTree(out.points) if len(out.points) else None
        return out

    def floor_as_support(self) -> CollisionChecker:
        """This checker with the floor as a support the arm may come to but not into (no
        FLOOR_CLEARANCE above it): for an arm setting something down on the floor, as it
        may come to a table top it sets something down on."""
        out = copy.copy(self)
        out.floor_clearance = 0.0
        return out

    def unseen(self, centres: np.ndarray, radius: np.ndarray) -> np.ndarray:
        """(N,) whether each sphere (centres (N, 3), `base`, m; radius (N,) m) reaches into
        space no camera saw, tested at its centre and the six points of its surface along
        `base`'s axes. A point counts as seen where a camera saw past it (by SEEN_TOLERANCE),
        inside the arm's own spheres as the frames were captured or as `knowing` adds them
        (grown by OWN_SPACE_PADDING: the arm stood there, so nothing else did), or inside
        UNSTOW_BOX.
        Points, not whole spheres, so that a sphere may straddle two of these. False for all
        without frames."""
        if not self.frames or not len(centres):
            return np.zeros(len(centres), bool)
        points = (centres[:, None] + radius[:, None, None] * _SPHERE_PROBES).reshape(-1, 3)
        lo, hi = UNSTOW_BOX
        blind = ~((points >= lo) & (points <= hi)).all(axis=1)
        i = np.flatnonzero(blind)
        blind[i[seen_free(points[i], self.frames, SEEN_TOLERANCE)]] = False
        i = np.flatnonzero(blind)
        blind[i[self._own.holds(points[i])]] = False
        return blind.reshape(len(centres), -1).any(axis=1)

    def _contacts(
        self, centres: np.ndarray, radius: np.ndarray, body: np.ndarray, margin: float
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """For spheres (B, S) of `radius` (S,) on the arm's `body` (S,): whether each is
        below the floor's clearance (B, S), within `margin` of each keep-out box that checks
        its body (B, S, K), and of the cloud (B, S)."""
        B, S, _ = centres.shape
        reach = radius[None, :] + margin
        # A negative margin (the hand at its grasp may touch the support) holds for the
        # floor too: for an object on the floor, the floor is the support.
        clearance = self.floor_clearance if margin >= 0 else margin
        floor = centres[..., 2] < radius + clearance
        boxes = (_box_gaps(centres) < reach[..., None]) & _CHECKED[body]
        cloud = np.zeros((B, S), bool)
        if self.tree is not None:
            bound = float(radius.max() + margin)
            d, _ = self.tree.query(centres.reshape(-1, 3), k=1, distance_upper_bound=bound)
            cloud = d.reshape(B, S) < reach
        return floor, boxes, cloud

    def _hits(
        self, centres: np.ndarray, radius: np.ndarray, body: np.ndarray, margin: float
    ) -> np.ndarray:
        """(B, S) whether each sphere touches an obstacle, a keep-out box or the floor."""
        floor, boxes, cloud = self._contacts(centres, radius, body, margin)
        return floor | boxes.any(axis=-1) | cloud

    def what_hits(self, q: np.ndarray, *, hand: bool = True) -> list[str]:
        """Names of what configuration q (6,) touches: "floor", a keep-out box, or "cloud"."""
        centres = sphere_centres(body_frames(q))
        keep = np.ones(len(SPHERES.radius), bool) if hand else ~SPHERES.hand
        floor, boxes, cloud = self._contacts(
            centres[:, keep], SPHERES.radius[keep], SPHERES.body[keep], self.margin
        )
        names = ["floor"] if floor.any() else []
        names += [b.name for k, b in enumerate(KEEPOUT_BOXES) if boxes[..., k].any()]
        return names + (["cloud"] if cloud.any() else [])

    def points_near(self, q: np.ndarray, *, hand: bool = True) -> np.ndarray:
        """The cloud's points (M, 3) (m, `base`) within the margin of configuration q's (6,)
        spheres: what a refused posture comes too close to."""
        if self.tree is None:
            return np.zeros((0, 3))
        keep = np.ones(len(SPHERES.radius), bool) if hand else ~SPHERES.hand
        centres = sphere_centres(body_frames(q))[0][keep]
        near = self.tree.query_ball_point(centres, SPHERES.radius[keep] + self.margin)
        return self.points[np.unique(np.concatenate([np.asarray(i, int) for i in near]))]

    def segment_ok(
        self, qa: np.ndarray, qb: np.ndarray, *, step: float = 0.03, **kw: object
    ) -> bool:
        """Whether the straight joint-space segment qa -> qb is clear, checked every `step`
        rad of the largest joint motion (0.03 rad moves a 0.9 m reach by under 3 cm)."""
        n = max(2, math.ceil(float(np.max(np.abs(qb - qa))) / step) + 1)
        Q = np.linspace(qa, qb, n)
        # Every SEGMENT_COARSE-th configuration first: a blocked segment (most of those a
        # planner tries) is then rejected after an eighth of the work.
        coarse = np.zeros(n, bool)
        coarse[::SEGMENT_COARSE] = coarse[-1] = True
        for part in (Q[coarse], Q[~coarse]):
            if len(part) and not self.clearance_ok(part, **kw).all():  # type: ignore[arg-type]
                return False
        return True
