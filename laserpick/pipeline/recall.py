"""Views from the way in: what the depth cameras saw while the scooter drove up, carried into
the frame where it now stands by the wheel odometry.

Five cameras on fixed mounts leave blind spots around the scooter. Parked before a bookshelf
or a high table, the space just ahead of the scooter's front right corner, which the arm
crosses on its way out from the stowed pose, lies in no camera's view; a metre back, on the
drive in, it lay in the middle of it. A real mobile manipulator keeps what its cameras saw as
it moved (a local map). `ViewMemory` keeps the last few captures of a drive, with the
odometry's pose at each, and hands them back re-expressed in the current `base` frame:

- their frames, so that the planner's seen-space test counts what they saw through as seen;
- their points where no camera sees now (`Recalled.blind_points`), so that what they saw
  there (a shelf's board beside the arm, a table's leg) is an obstacle.

Where a camera sees now, the current capture alone says what is there: a view only fills in
the blind spots, and only for a while (a view older than `max_age` s of robot time is
forgotten: people move things). Frames: poses (x, y, yaw) in the odometry's frame (m, rad);
what comes back is in the current `base`.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.spatial import cKDTree

from laserpick.pipeline.cloud import fuse, voxel_first
from laserpick.pipeline.collision import not_carried, self_filter, within_reach
from laserpick.pipeline.free_space import hidden
from laserpick.settings import PerceptionSettings, get_settings
from laserpick.transforms import invert, planar_pose
from laserpick.types import DepthFrame

#: Voxel (m) a view's points are thinned to: the planner's own (`CollisionChecker`).
VIEW_VOXEL = 0.01
#: A view's point counts as seen now where a camera reads within this (m) of it or beyond:
#: three times the sensors' depth noise at 1.2 m, as for the seen-space test.
NOW_TOLERANCE = 0.006
#: A view's points this close (m) to the target's, or to others of its points so joined, are
#: taken for the target itself (parts of it hidden now), not for an obstacle beside it: two
#: voxels of VIEW_VOXEL, so a surface of them hangs together.
TARGET_PADDING = 0.02


@dataclass(frozen=True)
class View:
    """One capture on the way, in `base` as the scooter stood then: its frames, its points
    (M, 3) thinned to VIEW_VOXEL, and the odometry's pose (x, y, yaw) then."""

    frames: tuple[DepthFrame, ...]
    points: np.ndarray
    pose: np.ndarray

    @property
    def stamp(self) -> float:
        """Robot time (s) of the capture: its oldest frame's."""
        return min(f.stamp for f in self.frames)


@dataclass(frozen=True)
class Recalled:
    """The views kept on the way in, in `base` as the scooter stands now."""

    frames: tuple[DepthFrame, ...] = ()
    points: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.float32))

    def blind_points(
        self,
        now: Sequence[DepthFrame],
        target: np.ndarray | None = None,
        support: float | None = None,
    ) -> np.ndarray:
        """The recalled points (M, 3) that no camera of the capture `now` sees (`hidden`),
        less the `target`'s own (m, `base`; `on_target`, above the `support` height, m)."""
        pts = self.points
        if len(pts):
            pts = pts[hidden(pts, now, NOW_TOLERANCE)]
        if target is not None and len(target) and len(pts):
            pts = pts[~on_target(pts, target, support)]
        return pts


def on_target(points: np.ndarray, target: np.ndarray, support: float | None = None) -> np.ndarray:
    """(N,) whether each point (N, 3) is part of the target, whose points (M, 3) are known
    (m, `base`): joined to them through points at most TARGET_PADDING apart, above its
    `support` (m; default its lowest point) and within TARGET_PADDING of its extent.

    A view from elsewhere sees parts of the target that the capture now does not: its
    back, a corner hidden now behind something nearer, a patch that reads nothing now. They
    hang together with what is seen of it, as its neighbours, across a gap, do not."""
    target = np.asarray(target, float)
    points = np.asarray(points, float)
    lo, hi = target.min(axis=0) - TARGET_PADDING, target.max(axis=0) + TARGET_PADDING
    lo[2] = (target[:, 2].min() if support is None else support) + TARGET_PADDING / 2
    inside = np.all((points >= lo) & (points <= hi), axis=1)
    d, _ = cKDTree(target).query(points, distance_upper_bound=TARGET_PADDING)
    part = inside & np.isfinite(d)
    candidates = np.flatnonzero(inside)
    if not part.any() or not len(candidates):
        return part
    tree = cKDTree(points[candidates])
    grown = np.zeros(len(candidates), bool)
    grown[part[candidates]] = True
    frontier = np.flatnonzero(grown)
    while len(frontier):
        near = tree.query_ball_point(tree.data[frontier], TARGET_PADDING)
        new = np.unique(np.concatenate([np.asarray(n, int) for n in near]))
        new = new[~grown[new]]
        grown[new] = True
        frontier = new
    part[candidates[grown]] = True
    return part


def _turn(a: float, b: float) -> float:
    """Smallest angle (rad) between headings a and b."""
    return abs((a - b + math.pi) % (2 * math.pi) - math.pi)


def moved(then: np.ndarray, now: np.ndarray, distance: float, turn: float) -> bool:
    """Whether the scooter, from odometry pose `then` to `now` (x, y, yaw; m, rad), has gone
    at least `distance` (m) or turned at least `turn` (rad)."""
    gone = math.hypot(now[0] - then[0], now[1] - then[1])
    return gone >= distance or _turn(now[2], then[2]) >= turn


def motion(then: np.ndarray, now: np.ndarray) -> np.ndarray:
    """T (4, 4) taking `base` at odometry pose `then` (x, y, yaw) into `base` at `now`."""
    return invert(planar_pose(*now)) @ planar_pose(*then)


def moved_points(points: np.ndarray, then: np.ndarray, now: np.ndarray) -> np.ndarray:
    """`points` (N, 3; m, `base` at odometry pose `then`) in `base` at odometry pose `now`."""
    T = motion(then, now)
    return points @ T[:3, :3].T + T[:3, 3]


class ViewMemory:
    """The last `size` views of a drive, one each `spacing` m driven or `turn` rad turned,
    none older than `max_age` s of robot time. Thread-safe: the session adds views on one
    thread and recalls them on another. settings: how a view's frames are fused."""

    def __init__(
        self,
        spacing: float,
        turn: float,
        size: int,
        max_age: float,
        settings: PerceptionSettings | None = None,
    ) -> None:
        if spacing <= 0 or turn <= 0 or size < 0 or max_age <= 0:
            raise ValueError("spacing, turn and max_age must be positive, size not negative")
        self.spacing, self.turn, self.size, self.max_age = spacing, turn, size, max_age
        self.settings = settings
        self._views: tuple[View, ...] = ()
        self._lock = threading.Lock()

    def __len__(self) -> int:
        return len(self._views)

    def due(self, pose: np.ndarray) -> bool:
        """Whether the scooter, at odometry `pose`, has moved far enough from the last view
        for another (always, before the first)."""
        if self.size == 0:
            return False
        views = self._views
        if not views:
            return True
        return moved(views[-1].pose, pose, self.spacing, self.turn)

    def add(
        self, frames: Sequence[DepthFrame], pose: np.ndarray, q_arm: np.ndarray | None = None
    ) -> None:
        """Keep a capture taken at odometry `pose`; the oldest goes beyond `size`. q_arm (6,)
        (rad): the arm's joint angles in the capture (None: no arm in view). Its own points
        are left out (`self_filter`), as the planner leaves them out of a capture now: carried
        to where the scooter stands now, they would be a ghost of the arm, in the very place
        it folds into (the stow after the first drop found no way home in every in-situ task)."""
        if self.size == 0 or not frames:
            return
        # The workspace box, reaching as much farther ahead as the views span: what lay
        # beyond it from here may lie within it where the scooter stops.
        s = self.settings or get_settings().perception
        far = (s.workspace_max[0] + self.spacing * self.size, *s.workspace_max[1:])
        points = fuse(frames, s.model_copy(update={"workspace_max": far})).points
        if q_arm is not None:
            points = points[self_filter(points, q_arm)]
        view = View(tuple(frames), points[voxel_first(points, VIEW_VOXEL)], np.array(pose, float))
        with self._lock:
            self._views = (*self._views, view)[-self.size :]

    def forget(self, points: np.ndarray, pose: np.ndarray, above: float = -np.inf) -> None:
        """Leave out of every view what it saw within CARRIED_PADDING of `points` (m, `base`
        as the scooter stands at odometry `pose`) and higher than `above` (m): an object
        picked up since, whose ghost would otherwise stand where it was, wherever no camera
        sees it gone now. The surface it stood on, below `above`, stays. (`base` heights do
        not change as the scooter drives.)"""
        if len(points) == 0:
            return
        pts = np.asarray(points, float)
        with self._lock:
            kept = []
            for view in self._views:
                then = moved_points(pts, np.asarray(pose, float), view.pose)
                gone = ~not_carried(view.points, then) & (view.points[:, 2] > above)
                kept.append(replace(view, points=view.points[~gone]))
            self._views = tuple(kept)

    def clear(self) -> None:
        with self._lock:
            self._views = ()

    def recall(self, pose: np.ndarray, now: float) -> Recalled:
        """The views younger than `max_age` at robot time `now` (s), in `base` as the scooter
        stands at odometry `pose`: frames and points, these within the arm's reach
        (`within_reach`) and thinned to VIEW_VOXEL again."""
        frames: list[DepthFrame] = []
        points = []
        for view in self._views:
            if now - view.stamp > self.max_age:
                continue
            T = motion(view.pose, np.asarray(pose, float))
            frames += [replace(f, T_base_cam=T @ f.T_base_cam) for f in view.frames]
            points.append(
                view.points @ T[:3, :3].T.astype(np.float32) + T[:3, 3].astype(np.float32)
            )
        if not points:
            return Recalled()
        pts = np.concatenate(points)
        # Most of what the views saw lies out of the arm's reach (in the kitchen, over nine
        # tenths of it); those points cannot matter to a plan, and they
        # would cost the hidden-now test and the thinning their time.
        pts = pts[within_reach(pts)]
        return Recalled(tuple(frames), pts[voxel_first(pts, VIEW_VOXEL)])
