"""Depth frames stacked to be asked all at once (`free_space.seen_free`): their images in one
flat buffer and one matrix that takes a point to every frame's pixel. A pick asks its
capture's frames, with the views from the way in, thousands of times; the stack is built once
and kept while it is asked, and its buffer is filled again by the next stack once no one
asks it.

Frames: points in `base` (m); each DepthFrame carries its pose in `base` and its intrinsics.
"""

from __future__ import annotations

import threading
import weakref
from collections.abc import Sequence

import numpy as np

from laserpick.types import DepthFrame

__all__ = ["MIN_RANGE", "STACKS_KEPT", "FrameStack", "frame_stack"]

#: Nearest a point may be to a camera (m) to count as in its view: the sensors' minimum range.
MIN_RANGE = 0.1
#: Stacks kept: a pick asks of its capture's frames (with the views from the way in) and grasp
#: detection of its own. Each holds a copy of its frames' depth images (45 frames of 640 x
#: 480: 55 MB).
STACKS_KEPT = 2
#: Buffers of stacks let go that no one asks any more, kept for the next stacks to fill: a
#: new 55 MB buffer is paged in (transparent huge pages compacted) at every pick, 0.02-0.32 s
#: of its planning in an `in-situ` bench, a buffer filled again 0.014 s. A stack takes a
#: spare at most SPARE_SLACK times the length it needs.
SPARES_KEPT = STACKS_KEPT
SPARE_SLACK = 2


class FrameStack:
    """Depth frames asked all at once: their images (H, W; m) in one flat buffer, each from
    its offset, and one matrix that takes a point of `base` to every frame's homogeneous pixel
    at once (`projection`). `spare`: a buffer to fill (1-D, of the images' type, at least
    as long as they are together), else one is allocated."""

    def __init__(self, frames: Sequence[DepthFrame], spare: np.ndarray | None = None) -> None:
        self.frames = tuple(frames)  # kept, so that the ids that key the cache stay theirs
        self.size = np.array([f.depth.shape for f in frames])  # (F, 2): h, w
        total, dtype = _needs(frames)
        #: the buffer the images were copied into (`depths` is its start)
        self.buffer = spare if _fits(spare, total, dtype) else np.empty(total, dtype)
        self.depths = self.buffer[:total]
        np.concatenate([f.depth.ravel() for f in frames], out=self.depths)
        self.offset = np.concatenate([[0], np.cumsum(self.size.prod(axis=1))[:-1]])
        # Each frame's K [R^T | -R^T t], as (4, 3F): a point's homogeneous pixel in every
        # frame is one product, (x, y, z, 1) times it. Its pixels match `pinhole_project`'s
        # (none of 5.8 million differed on a kitchen capture; depths within 1e-15 m).
        K = np.array([f.K for f in frames], np.float64)
        T = np.array([f.T_base_cam for f in frames], np.float64)
        R_t = np.transpose(T[:, :3, :3], (0, 2, 1))
        rows = np.concatenate([K @ R_t, -(K @ R_t @ T[:, :3, 3:])], axis=2)  # (F, 3, 4)
        self.projection = rows.reshape(-1, 4).T.copy()

    def seen_past(
        self, points: np.ndarray, tolerance: np.ndarray, first: int = 0, last: int | None = None
    ) -> np.ndarray:
        """(N,) whether some frame from `first` to `last` (default: all the rest) read beyond
        each point (N, 3) (m, `base`) by more than its `tolerance` (N,) (m), at the point's
        pixel, in one product and one gather: each point's pixel and depth in each frame,
        and the depth read there."""
        last = len(self.frames) if last is None else last
        cols = self.projection[:, 3 * first : 3 * last]
        pixel = (points @ cols[:3] + cols[3]).reshape(len(points), last - first, 3)
        z = pixel[..., 2]
        ahead = z > MIN_RANGE
        depth = np.where(ahead, z, 1.0)
        u = np.rint(pixel[..., 0] / depth).astype(np.int64)
        v = np.rint(pixel[..., 1] / depth).astype(np.int64)
        h, w = self.size[first:last, 0], self.size[first:last, 1]
        n, f = np.nonzero(ahead & (u >= 0) & (u < w) & (v >= 0) & (v < h))
        at = self.offset[first + f] + v[n, f] * w[f] + u[n, f]
        free = np.zeros(len(points), bool)
        free[n[self.depths[at] > z[n, f] + tolerance[n]]] = True
        return free


def _needs(frames: Sequence[DepthFrame]) -> tuple[int, np.dtype]:
    """The length and type of a buffer that holds the frames' images together."""
    return sum(f.depth.size for f in frames), np.result_type(*(f.depth for f in frames))


def _fits(buffer: np.ndarray | None, total: int, dtype: np.dtype) -> bool:
    """Whether `buffer` holds `total` values of `dtype`, without wasting more than its
    SPARE_SLACK share."""
    return (
        buffer is not None
        and buffer.dtype == dtype
        and total <= len(buffer) <= SPARE_SLACK * max(total, 1)
    )


_STACKS: dict[tuple[int, ...], FrameStack] = {}
_SPARES: list[np.ndarray] = []
_LOCK = threading.Lock()


def frame_stack(frames: Sequence[DepthFrame]) -> FrameStack:
    """The frames stacked (`FrameStack`) once while they are asked: the last STACKS_KEPT are
    kept (the carry's search ahead asks from its own thread). A stack let go lends its
    buffer to the next only where no one holds it any more."""
    key = tuple(map(id, frames))
    with _LOCK:
        stack = _STACKS.pop(key, None)
        if stack is None:
            while len(_STACKS) >= STACKS_KEPT:
                _let_go(next(iter(_STACKS)))
            stack = FrameStack(frames, _take_spare(*_needs(frames)))
        _STACKS[key] = stack
    return stack


def _let_go(key: tuple[int, ...]) -> None:
    """Drop the stack of `key` from those kept, and keep its buffer as a spare where no one
    held the stack but the cache (a search on another thread may still ask it: its buffer
    is then left to it). The largest SPARES_KEPT spares are kept."""
    stack = _STACKS.pop(key)
    alive, buffer = weakref.ref(stack), stack.buffer
    del stack
    if alive() is not None:
        return
    _SPARES.append(buffer)
    _SPARES.sort(key=len, reverse=True)
    del _SPARES[SPARES_KEPT:]


def _take_spare(total: int, dtype: np.dtype) -> np.ndarray | None:
    """The smallest spare buffer that `_fits` `total` values of `dtype`, taken from the
    spares; None where none does."""
    fitting = [k for k, b in enumerate(_SPARES) if _fits(b, total, dtype)]
    return _SPARES.pop(fitting[-1]) if fitting else None
