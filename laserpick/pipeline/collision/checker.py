"""The arm collision check for planning (paper 004 section 7): is the arm, with its gripper
and what it holds, clear of the cloud, the scooter's keep-out boxes and the floor at these
joint angles; on planned transits, also of the space no camera saw. Frames: `base`, metres;
joint angles in rad.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Iterator, Sequence

import numpy as np
from scipy.spatial import cKDTree

from laserpick.description.shapes import FLOOR_CLEARANCE, KEEPOUT_BOXES, body_frames
from laserpick.pipeline.collision.arm_spheres import HAND_BODY, SPHERES, sphere_centres
from laserpick.pipeline.collision.broad_phase import BodyBalls, body_balls
from laserpick.pipeline.collision.carried import (
    PAYLOAD_POINT_RADIUS,
    coarse_payload,
    held_points,
    off_upper_links,
)
from laserpick.pipeline.collision.keepout import box_contacts
from laserpick.pipeline.collision.obstacles import obstacle_mask
from laserpick.pipeline.collision.seen_space import OWN_SPACE_PADDING, OwnSpace, unseen_spheres
from laserpick.types import DepthFrame

#: Spheres of one body worth a ball against the cloud (a hand and what it holds): a
#: link's few are asked of the KD-tree at once, quicker than bounding them first.
CLOUD_BALL_MIN = 32
#: A joint segment's every this-many-th configuration is checked before the rest.
SEGMENT_COARSE = 8
#: Halvings of the margin that find the clearance a configuration keeps (`clearance_kept`):
#: 8 find a 1 cm margin's share to within 0.04 mm.
CLEARANCE_STEPS = 8


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
        self._own = OwnSpace(own, SPHERES.radius[: len(own)] + OWN_SPACE_PADDING)
        #: the last held object asked about, and its coarse points (`_coarse_of`)
        self._coarse: tuple[np.ndarray, np.ndarray] | None = None

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
        stop: bool = False,
    ) -> np.ndarray:
        """(B,) True where configuration Q[b] (B, 6) (rad) collides with nothing.

        hand: include the gripper's spheres (grasp detection already checked the hand at the
        grasp itself). payload: a held object's points (P, 3) in the TCP frame (m), each a
        sphere of PAYLOAD_POINT_RADIUS carried with the hand. margin: overrides the
        checker's clearance (m). seen: also keep the hand and what it holds where the
        cameras saw through (`unseen`): a planned transit may not take space no camera saw
        for free. The hand is what swings out into the room, into furniture beyond the
        cameras' view (a bookshelf's board); the shoulder and upper arm stay below and beside
        the sensor posts, where no camera looks, so they are not held to it. stop: return once
        a test finds a configuration blocked; the configurations not asked about yet read
        clear, so only `.all()` of what returns is then the verdict (`all_clear`).
        """
        margin = self.margin if margin is None else margin
        Q = np.atleast_2d(np.asarray(Q, float))
        frames = body_frames(Q)
        if payload is None or len(payload) == 0:
            return self._clear(frames, hand, None, margin, seen, stop)
        coarse = self._coarse_of(payload)
        if len(coarse) == len(payload):
            return self._clear(frames, hand, payload, margin, seen, stop)
        # Exact: what does not clear some of the object's points does not clear them all.
        clear = self._clear(frames, hand, coarse, margin, False, stop)
        rows = np.flatnonzero(clear)
        if len(rows) and not (stop and len(rows) < len(Q)):
            clear[rows] = self._clear(frames[rows], hand, payload, margin, seen, stop)
        return clear

    def all_clear(self, Q: np.ndarray, **kw) -> bool:
        """Whether every configuration of Q (B, 6) (rad) collides with nothing
        (`clearance_ok`'s options `kw`), the check stopping at the first test that finds one
        that does: three of four segments a search tries are blocked, most at their first
        configurations, and there every further test was work for nothing."""
        return bool(self.clearance_ok(Q, stop=True, **kw).all())

    def _coarse_of(self, payload: np.ndarray) -> np.ndarray:
        """`coarse_payload` of `payload`, kept for the next call: a search asks about the
        same held object thousands of times."""
        last = self._coarse
        if last is not None and last[0] is payload:
            return last[1]
        coarse = coarse_payload(payload)
        self._coarse = (payload, coarse)
        return coarse

    def _clear(
        self,
        frames: np.ndarray,
        hand: bool,
        payload: np.ndarray | None,
        margin: float,
        seen: bool,
        stop: bool = False,
    ) -> np.ndarray:
        """`clearance_ok` of the configurations whose body frames (B, 7, 4, 4) are `frames`
        (`body_frames`), with every point of `payload`. stop: return once a test finds a
        configuration blocked; the configurations it had not asked about yet read clear, so
        only `.all()` of what returns is the verdict."""
        spheres = sphere_centres(frames)
        centres, radius, body = spheres, SPHERES.radius, SPHERES.body
        if not hand:
            keep = ~SPHERES.hand
            centres, radius, body = centres[:, keep], radius[keep], body[keep]
        clear = np.ones(len(frames), bool)
        if payload is not None and len(payload):
            held = held_points(frames, payload)
            clear &= off_upper_links(spheres, held, margin)
            centres = np.concatenate([centres, held], axis=1)
            radius = np.append(radius, np.full(len(payload), PAYLOAD_POINT_RADIUS))
            body = np.append(body, np.full(len(payload), HAND_BODY))
        if stop and not clear.all():
            return clear
        for blocked in self._blocked(centres, radius, body, margin):
            clear &= ~blocked
            if stop and not clear.all():
                return clear
        rows = np.flatnonzero(clear) if seen and self.frames else np.zeros(0, int)
        if len(rows) and not (stop and len(rows) < len(frames)):
            # Only the configurations still clear: this projects into every camera.
            out = body == HAND_BODY
            spheres = centres[rows][:, out].reshape(-1, 3)
            blind = self.unseen(spheres, np.tile(radius[out], len(rows)))
            clear[rows[blind.reshape(len(rows), -1).any(axis=1)]] = False
        return clear

    def _blocked(
        self, centres: np.ndarray, radius: np.ndarray, body: np.ndarray, margin: float
    ) -> Iterator[np.ndarray]:
        """(B,) whether each configuration's spheres (B, S), of `radius` (S,) on the arm's
        `body` (S,), come within `margin` of the floor, of a keep-out box, of the cloud: one
        test at a time, the cheapest first, as `_clear` asks for them."""
        reach = radius + margin
        yield self._below_floor(centres, radius, margin).any(axis=1)
        balls = body_balls(centres, reach, body)
        yield box_contacts(centres, reach, body, balls).any(axis=(1, 2))
        yield self._near_cloud(centres, reach, balls).any(axis=1)

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
        out._own = OwnSpace(np.vstack([own.centres, centres]), np.append(own.reach, reach))
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
        space no camera of this checker's frames saw (`unseen_spheres`); the arm's own space
        is its spheres as the frames were captured and as `knowing` adds them, grown by
        OWN_SPACE_PADDING (the arm stood there, so nothing else did)."""
        return unseen_spheres(centres, radius, self.frames, self._own)

    def _contacts(
        self, centres: np.ndarray, radius: np.ndarray, body: np.ndarray, margin: float
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """For spheres (B, S) of `radius` (S,) on the arm's `body` (S,): whether each is
        below the floor's clearance (B, S), within `margin` of each keep-out box that checks
        its body (B, S, K), and of the cloud (B, S)."""
        reach = radius + margin
        balls = body_balls(centres, reach, body)
        boxes = box_contacts(centres, reach, body, balls)
        floor = self._below_floor(centres, radius, margin)
        return floor, boxes, self._near_cloud(centres, reach, balls)

    def _below_floor(self, centres: np.ndarray, radius: np.ndarray, margin: float) -> np.ndarray:
        """(B, S) whether each sphere, at centres (B, S, 3) (m) of `radius` (S,) (m), comes
        nearer the floor than its clearance, or than `margin` where that is negative."""
        # A negative margin (the hand at its grasp may touch the support) holds for the
        # floor too: for an object on the floor, the floor is the support.
        clearance = self.floor_clearance if margin >= 0 else margin
        return centres[..., 2] < radius + clearance

    def _near_cloud(self, centres: np.ndarray, reach: np.ndarray, balls: BodyBalls) -> np.ndarray:
        """(B, S) whether each sphere, at centres (B, S, 3) (m), comes within its `reach`
        (S,) (m) of the cloud: the spheres of a body with fewer than CLOUD_BALL_MIN one by
        one, a larger body's only where its ball comes within reach of a point
        (`broad_phase.body_balls`)."""
        near = np.zeros(centres.shape[:2], bool)
        if self.tree is None:
            return near
        bound = float(reach.max())
        few, big = balls.split(CLOUD_BALL_MIN)
        d, _ = self.tree.query(centres[:, few], k=1, distance_upper_bound=bound)
        near[:, few] = d < reach[few]
        if len(big) and len(centres):
            radius = balls.radius[:, big]
            d, _ = self.tree.query(balls.middle[:, big], k=1, distance_upper_bound=radius.max())
            rows, groups = np.nonzero(d < radius)
            pair, sphere = balls.members(rows, big[groups])
            row = rows[pair]
            d, _ = self.tree.query(centres[row, sphere], k=1, distance_upper_bound=bound)
            near[row, sphere] = d < reach[sphere]
        return near

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
        return self.path_clear(np.linspace(qa, qb, n), **kw)

    def path_clear(self, Q: np.ndarray, **kw: object) -> bool:
        """Whether every configuration of the path Q (B, 6) (rad, in order along it) is
        clear (`clearance_ok`'s options `kw`): its every SEGMENT_COARSE-th and last first, so
        that a blocked path (most of those a planner tries, and of the wide blends at a
        transit's corners) is rejected after an eighth of the work."""
        coarse = np.zeros(len(Q), bool)
        coarse[::SEGMENT_COARSE] = coarse[-1] = True
        for part in (Q[coarse], Q[~coarse]):
            if len(part) and not self.all_clear(part, **kw):
                return False
        return True
