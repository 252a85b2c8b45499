"""Free space as the depth cameras saw it: a finger may go only where a camera saw past it.

A fused cloud holds the surfaces the cameras saw, not the space behind them. An object seen
from the front shows its front; a grasp detector that tests the hand against those points
only may put a finger down into the object's unseen back, where a guessed back is too thin.
The cameras say more than the
points: along each pixel's ray, space is free up to the depth it read. A point is seen free
when some camera's reading at its pixel lies beyond it.

Frames: points in `base` (m); each DepthFrame carries its pose in `base` and its intrinsics.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from laserpick.description.dims import GRIPPER_HAND
from laserpick.pipeline.frame_stack import MIN_RANGE, frame_stack
from laserpick.settings import GraspSettings
from laserpick.transforms import pinhole_project
from laserpick.types import DepthFrame, Grasp

#: Where the free-space test probes each finger, as fractions: across its width (hand axis,
#: of finger_width / 2 either side of its middle) and down its length (of finger_length,
#: from the tip). Its middle along the closing axis: the pad and plate's middle.
PROBE_ACROSS = (-0.6, 0.0, 0.6)
PROBE_DOWN = (0.15, 0.5, 0.85)
#: How near (px) to its image's border a target point projects for that camera's view to
#: end there. The fused cloud keeps every second pixel and none on the border, so the last
#: points lie 2-4 px in: a lying juice bottle on the 108 cm table ended 4 px inside the high
#: camera's right edge, its other 12 cm beyond it.
VIEW_EDGE_PX = 8
#: Fewest target points at the view's edge for the object to count as cut off by it.
CUT_MIN_POINTS = 5
#: `seen_free` asks the first CAPTURE_FRAMES frames (a stack's first frames are its
#: capture's, whose five cameras see past most points where the hand goes), then the rest
#: about the points those did not see past; each group at once where the points left times
#: its frames are at most AT_ONCE_MAX pairs, else one frame after another until they are
#: (past that, the one product costs more than the frames one by one, which see most points
#: free early). Measured (CPU time) on a kitchen capture's 45 frames, points where the hand
#: goes: all at once is 14 times quicker than frame by frame for 60 points, 1.4 times at
#: 700, slower from about 1400. On 5000 calls of a kitchen's pick searches (584 points on
#: average), the capture's frames first gave the same verdicts in 1.7-2.0 s of CPU against
#: 2.8 s all at once (`bench/seen_space_cost.py`, `in-situ` 7305).
CAPTURE_FRAMES = 5
AT_ONCE_MAX = 100_000
#: The longest (m) an object the hand carries is taken to be where the cameras' view cut it
#: off (the kitchen's longest, the juice bottle, is 20.6 cm).
OBJECT_SPAN_MAX = 0.25


def _reading(points: np.ndarray, f: DepthFrame) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The indices of the points (N, 3) (m, `base`) in frame `f`'s image and ahead of it,
    the depth read at their pixels (m, 0 for none) and their own depths (m)."""
    uv, z, ahead = pinhole_project(points, f.K, f.T_base_cam, MIN_RANGE)
    u, v = np.rint(uv).astype(np.int64).T
    h, w = f.depth.shape
    i = np.flatnonzero(ahead & (u >= 0) & (u < w) & (v >= 0) & (v < h))
    return i, f.depth[v[i], u[i]], z[i]


def seen_free(
    points: np.ndarray, frames: Sequence[DepthFrame], tolerance: float | np.ndarray
) -> np.ndarray:
    """(N,) bool: whether some camera saw past each point (N, 3) (m, `base`), its reading at
    the point's pixel more than `tolerance` (m; one for all, or (N,) one per point) beyond
    the point's own depth. A pixel that read nothing (0) shows nothing: nothing was seen
    there, near or far."""
    points = np.asarray(points, np.float64).reshape(-1, 3)
    tolerance = np.broadcast_to(np.asarray(tolerance, np.float64), (len(points),))
    if not frames:
        return np.zeros(len(points), bool)
    # A search held to seen space asks about tens to hundreds of points thousands of times,
    # and per frame asked, the calls cost more than the arithmetic (CAPTURE_FRAMES).
    stack = frame_stack(frames)
    free = np.zeros(len(points), bool)
    todo = np.arange(len(points))
    first = min(CAPTURE_FRAMES, len(frames))
    for lo, hi in ((0, first), (first, len(frames))):
        k = lo
        while len(todo) and k < hi:
            last = hi if len(todo) * (hi - k) <= AT_ONCE_MAX else k + 1
            free[todo] = stack.seen_past(points[todo], tolerance[todo], k, last)
            todo, k = todo[~free[todo]], last
    return free


def hidden(points: np.ndarray, frames: Sequence[DepthFrame], tolerance: float) -> np.ndarray:
    """(N,) bool: whether no camera sees each point (N, 3) (m, `base`) now: every frame
    misses it, read nothing at its pixel, or read something nearer by more than `tolerance`
    (m) in front of it. A point some camera reads at, or sees past, is not hidden."""
    points = np.asarray(points, np.float64).reshape(-1, 3)
    known = np.zeros(len(points), bool)
    for f in frames:
        i, reading, z = _reading(points, f)
        known[i[(reading > 0) & (reading >= z - tolerance)]] = True
    return ~known


def beyond_view(
    target: np.ndarray,
    frames: Sequence[DepthFrame],
    step: float,
    tolerance: float,
    support: float | None = None,
    others: Sequence[DepthFrame] = (),
) -> np.ndarray:
    """Points (m, `base`) that stand for the part of an object the cameras' view cut off: none
    when no part of it lies at the view's edge.

    target (N, 3), `base`: what the cameras saw of the object in `frames`. A point lies at
    the view's edge when it projects within VIEW_EDGE_PX of the border of some frame's
    image and well inside none. The object may go on beyond, and its unseen end, which no
    plan knows of, can meet the furniture as the arm tucks it in.

    So the edge points are carried on, `step` (m) at a time, away from the seen part's
    middle, until the object spans OBJECT_SPAN_MAX that way. The way is level: what stands
    or lies on a surface goes on along it, and the edge's own slant says little (the
    bottle's top ran farther into the view than its side, which tilted the way 37 degrees
    up). A copy some camera saw past (by `tolerance`, m), of `frames` or of `others` (views
    from elsewhere), is left out: the object is not there. So is one within `tolerance` of
    the `support` height (m) it stands on: no camera sees past a surface, and the carried
    shape reaches down to it anyway (`carried_shape`).
    """
    target = np.asarray(target, np.float64).reshape(-1, 3)
    near_edge = np.zeros(len(target), bool)
    inside = np.zeros(len(target), bool)
    for f in frames:
        uv, _, ahead = pinhole_project(target, f.K, f.T_base_cam, MIN_RANGE)
        h, w = f.depth.shape
        inner = ahead & (uv >= VIEW_EDGE_PX).all(axis=1)
        inner &= (uv[:, 0] < w - VIEW_EDGE_PX) & (uv[:, 1] < h - VIEW_EDGE_PX)
        seen = ahead & (uv >= 0).all(axis=1) & (uv[:, 0] < w) & (uv[:, 1] < h)
        near_edge |= seen & ~inner
        inside |= inner
    edge = target[near_edge & ~inside]
    if len(edge) < CUT_MIN_POINTS:
        return np.zeros((0, 3))
    way = edge.mean(axis=0) - target.mean(axis=0)
    way[2] = 0.0
    if np.linalg.norm(way) < 1e-3:  # cut off above or below: no level way on
        return np.zeros((0, 3))
    way /= np.linalg.norm(way)
    along = target @ way
    reach = OBJECT_SPAN_MAX - float(along.max() - along.min())
    steps = np.arange(1, int(np.ceil(reach / step)) + 1)[:, None, None] * step
    copies = (edge[None] + steps * way).reshape(-1, 3)
    if not len(copies):
        return copies
    if support is not None:
        copies = copies[copies[:, 2] > support + tolerance]
    return copies[~seen_free(copies, [*frames, *others], tolerance)]


def finger_probes(poses: np.ndarray) -> np.ndarray:
    """(G, P, 3) points (m, `base`) inside the open fingers of the hands at TCP `poses`
    (G, 4, 4): PROBE_ACROSS x PROBE_DOWN in each finger's middle, both fingers."""
    poses = np.asarray(poses, np.float64).reshape(-1, 4, 4)
    hand = GRIPPER_HAND
    c = hand.width_max / 2 + (hand.pad_thickness + hand.finger_thickness) / 2
    tip = hand.pad_depth / 2  # the TCP lies this far behind the fingertips
    local = np.array(
        [
            (x * hand.finger_width / 2, side * c, tip - d * hand.finger_length)
            for side in (-1.0, 1.0)
            for x in PROBE_ACROSS
            for d in PROBE_DOWN
        ]
    )
    return np.einsum("gij,pj->gpi", poses[:, :3, :3], local) + poses[:, None, :3, 3]


def fingers_seen_free(
    grasps: Sequence[Grasp], frames: Sequence[DepthFrame], s: GraspSettings
) -> np.ndarray:
    """(G,) bool: whether the cameras saw free space at enough (free_space_share) of each
    grasp's finger probes. True for all when there are no frames to ask."""
    if not frames or not grasps:
        return np.ones(len(grasps), bool)
    probes = finger_probes(np.array([g.pose for g in grasps]))
    free = seen_free(probes.reshape(-1, 3), frames, s.free_space_tolerance)
    return free.reshape(len(grasps), -1).mean(axis=1) >= s.free_space_share
