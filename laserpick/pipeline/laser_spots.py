"""The laser's dots in one IR image, and the `base` point each lies on (004 section 5.2).

A dot saturates the IR image, so, per image:

1. Spots: connected groups of pixels at or above `laser_threshold`, with at least
   `laser_spot_min_px` of them, and their sub-pixel centroid (the mean of the saturated
   pixels' coordinates: the saturated core of a dot is a symmetric disc).
2. Pairs: spots within `laser_pair_px` of each other, by hierarchical clustering (complete
   linkage, so every spot of a cluster is that close to every other). Two spots in a cluster
   are the two beams; one spot is a single beam.
3. Each spot is lifted to `base` with the depth at its centroid: the median of the valid
   depths in the smallest window (3x3, 5x5, ... up to `laser_depth_window_px` on each side)
   holding at least three of them. A spot with no depth near it yields no point: a dot on
   glass, a shiny highlight or out of range fails rather than guessing.

`laser_mark` fuses the five views into the mark. Every function here reads only an image,
intrinsics and extrinsics: no simulator truth.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import ndimage
from scipy.cluster.hierarchy import fcluster, linkage

from laserpick.types import DepthFrame

__all__ = ["MIN_DEPTHS", "Spot", "find_spots", "lift", "pair_spots", "spot_depth"]

#: Fewest valid depths a window must hold before its median is trusted.
MIN_DEPTHS = 3


@dataclass(frozen=True)
class Spot:
    """One bright spot in one IR image: sub-pixel centroid (u right, v down; px) and area."""

    u: float
    v: float
    area: int


def find_spots(ir: np.ndarray, threshold: int, min_px: int = 1) -> list[Spot]:
    """Saturated spots in an IR image (H, W) uint8: 8-connected pixels >= threshold.

    Thresholds the whole image once with numpy and labels only the bounding box of the
    bright pixels, which is a few dozen pixels across when only the laser is that bright.
    """
    W = ir.shape[1]
    flat = np.flatnonzero(ir.reshape(-1) >= threshold)
    if flat.size < min_px:
        return []
    rows, cols = np.divmod(flat, W)
    r0, c0 = int(rows.min()), int(cols.min())
    box = np.zeros((int(rows.max()) - r0 + 1, int(cols.max()) - c0 + 1), bool)
    box[rows - r0, cols - c0] = True
    labels, n = ndimage.label(box, structure=np.ones((3, 3), bool))
    lab = labels[rows - r0, cols - c0]
    count = np.bincount(lab, minlength=n + 1)
    su = np.bincount(lab, weights=cols, minlength=n + 1)
    sv = np.bincount(lab, weights=rows, minlength=n + 1)
    return [
        Spot(su[i] / count[i], sv[i] / count[i], int(count[i]))
        for i in range(1, n + 1)
        if count[i] >= min_px
    ]


def pair_spots(spots: Sequence[Spot], pair_px: float) -> list[list[int]]:
    """Groups of spot indices lying within `pair_px` (px) of each other (complete linkage)."""
    if len(spots) <= 1:
        return [[i] for i in range(len(spots))]
    uv = np.array([[s.u, s.v] for s in spots])
    ids = fcluster(linkage(uv, method="complete"), t=pair_px, criterion="distance")
    return [np.flatnonzero(ids == k).tolist() for k in np.unique(ids)]


def spot_depth(depth: np.ndarray, u: float, v: float, max_half: int) -> float | None:
    """Depth (m) at a spot's centroid (u, v px): the median of the valid depths in the
    smallest square window, half-size 1 up to `max_half` px, holding MIN_DEPTHS of them.

    Growing the window only as needed keeps a dot near an object's rim from borrowing the
    depth of the surface behind it. None if no window has enough depth.
    """
    H, W = depth.shape
    iu, iv = round(u), round(v)
    if not (0 <= iu < W and 0 <= iv < H):
        return None
    half = 1
    while True:
        win = depth[max(iv - half, 0) : iv + half + 1, max(iu - half, 0) : iu + half + 1]
        valid = win[win > 0]
        if valid.size >= MIN_DEPTHS:
            return float(np.median(valid))
        if half >= max_half:
            return None
        half = min(2 * half, max_half)


def lift(frame: DepthFrame, u: float, v: float, z: float) -> np.ndarray:
    """The `base` point (m) of pixel (u, v) at optical depth z (m)."""
    K = frame.K
    p_cam = np.array([(u - K[0, 2]) / K[0, 0] * z, (v - K[1, 2]) / K[1, 1] * z, z])
    return frame.T_base_cam[:3, :3] @ p_cam + frame.T_base_cam[:3, 3]
