"""Synthetic perceptions of one object on a table, as `find_grasps` takes them: the object's
points and a table top about it, in `base` (m)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from laserpick.pipeline.perceive import Perception
from laserpick.types import FusedCloud, LaserMark, Segmentation, SupportSurface


def table_perception(
    obj: np.ndarray,
    obj_normals: np.ndarray,
    centre: np.ndarray,
    height: float,
    under: Callable[[np.ndarray], np.ndarray],
) -> Perception:
    """`obj` (N, 3; m, `base`) with outward normals `obj_normals` standing on a table top at
    `height` (m): the table's points on a 6 mm grid 30 cm either way about `centre` (x, y),
    less those `under` the object (a mask of the table points' (M, 2) x, y), segmented as the
    object and marked at its top above `centre`."""
    g = np.arange(-0.3, 0.3, 0.006)
    x, y = np.meshgrid(g, g)
    table = np.column_stack([x.ravel() + centre[0], y.ravel() + centre[1], np.full(x.size, height)])
    table = table[~under(table[:, :2])]
    pts = np.vstack([obj, table]).astype(np.float32)
    normals = np.vstack([obj_normals, np.tile([0.0, 0.0, 1.0], (len(table), 1))]).astype(np.float32)
    n = len(pts)
    cloud = FusedCloud(pts, normals, np.zeros(n, np.uint8), np.arange(n, dtype=np.int32), ("c",))
    surface = SupportSurface(height, np.array([0.0, 0.0, 1.0, -height]))
    seg = Segmentation(np.arange(len(obj)), "cluster", surface)
    top = np.array([centre[0], centre[1], obj[:, 2].max()])
    return Perception(cloud, LaserMark(top, "confirmed", 0, "direct"), seg, None)
