"""`perceive`: five depth frames in; the fused cloud, the laser mark and the target out.

Every stage is timed, and the timings come back with the result whether it succeeded or not,
so the console can show them and the benchmarks can compare them with the papers'.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Literal, TypeVar

import numpy as np

from laserpick.pipeline.cloud import fuse
from laserpick.pipeline.laser_mark import detect_mark, direct_mark
from laserpick.pipeline.segment import segment_target
from laserpick.settings import PerceptionSettings, get_settings
from laserpick.types import DepthFrame, Failure, FusedCloud, LaserMark, Segmentation

T = TypeVar("T")
SegmentationMethod = Literal["cluster", "grid"]


@dataclass(frozen=True)
class Perception:
    """What one perception pass found.

    timings: seconds per stage, in order: "fuse", "detect_laser", "segment".
    failure: set when a stage failed; later stages did not run and their fields are None.
    frames: the depth frames the cloud was fused from: where the cameras saw past a point,
    the space there is free (the grasp filter's free-space test); empty when not at hand.
    """

    cloud: FusedCloud
    mark: LaserMark | None
    segmentation: Segmentation | None
    failure: Failure | None
    timings: dict[str, float] = field(default_factory=dict)
    frames: tuple[DepthFrame, ...] = ()

    @property
    def ok(self) -> bool:
        return self.failure is None

    @property
    def target_points(self) -> np.ndarray:
        """(M, 3) float32 points of the target in `base` (empty when nothing was segmented)."""
        if self.segmentation is None:
            return np.zeros((0, 3), np.float32)
        return self.cloud.points[self.segmentation.indices]


def _timed(timings: dict[str, float], stage: str, fn: Callable[[], T]) -> T:
    t0 = time.perf_counter()
    try:
        return fn()
    finally:
        timings[stage] = time.perf_counter() - t0


def perceive(
    frames: Sequence[DepthFrame],
    *,
    point: Sequence[float] | None = None,
    method: SegmentationMethod = "cluster",
    settings: PerceptionSettings | None = None,
    cloud: FusedCloud | None = None,
) -> Perception:
    """Fuse the frames, find the mark, and segment the object under it.

    The mark comes from the laser dots in the IR images, or, when `point` is given, directly
    from that point in `base` (m): a click, a touch screen or an API call. cloud: the frames
    already fused with these settings (a click was aimed in it), so as not to fuse them again.
    """
    s = settings or get_settings().perception
    timings: dict[str, float] = {}
    frames = tuple(frames)
    if cloud is None:
        cloud = _timed(timings, "fuse", lambda: fuse(frames, s))
    else:
        timings["fuse"] = 0.0
    mark = _timed(
        timings,
        "detect_laser",
        lambda: direct_mark(point, s) if point is not None else detect_mark(frames, s),
    )
    if isinstance(mark, Failure):
        return Perception(cloud, None, None, mark, timings, frames)
    seg = _timed(timings, "segment", lambda: segment_target(cloud, mark.point, s, method=method))
    if isinstance(seg, Failure):
        return Perception(cloud, mark, None, seg, timings, frames)
    return Perception(cloud, mark, seg, None, timings, frames)
