"""The roughly horizontal planes of a cloud (004 section 6.1): RANSAC for the plane with the
most support, refined by least squares, removed while one has enough inliers that face up.
Planes are (a, b, c, d) with a unit normal up; points float32 (N, 3) in `base` (x forward,
y left, z up), metres.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from laserpick.settings import PerceptionSettings
from laserpick.types import FusedCloud, SupportSurface


def min_plane_inliers(settings: PerceptionSettings) -> int:
    """Inliers a plane needs to be removed, scaled from 004's 13k to our cloud's density.

    004 fused five Occipital Structure sensors at full 640 x 480 resolution. We simulate the
    same sensors on the same mounts (114 cm at 25 and 55 deg down, 156 cm at 44 deg), so a
    table seen by both systems covers the same pixels; `fuse` keeps every `pixel_stride`-th
    pixel in each image direction, i.e. 1 / stride^2 of them. 13000 / stride^2 keeps 004's
    threshold as the same table area (3250 points at stride 2). Voxel thinning
    (`voxel_size` > 0) is not accounted for.
    """
    return max(1, math.ceil(settings.plane_min_inliers / settings.pixel_stride**2))


def _plane_through(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit normals (up) and offsets d of the planes through point triples p (H, 3, 3)."""
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    norm = np.linalg.norm(n, axis=1)
    norm[norm == 0] = np.inf  # degenerate triples get a zero normal and lose
    n = n / norm[:, None]
    n *= np.where(n[:, 2] < 0, -1.0, 1.0)[:, None]
    return n, -np.einsum("hk,hk->h", n, p[:, 0])


def _refine(points: np.ndarray) -> tuple[np.ndarray, float]:
    """Least-squares plane (unit normal up, d) through points (N, 3)."""
    c = points.mean(axis=0)
    _, _, vt = np.linalg.svd(points - c, full_matrices=False)
    n = vt[2] if vt[2, 2] >= 0 else -vt[2]
    return n, -float(n @ c)


def best_horizontal_plane(
    points: np.ndarray, cand: np.ndarray, settings: PerceptionSettings, rng: np.random.Generator
) -> np.ndarray | None:
    """RANSAC for the horizontal plane (a, b, c, d) with the most support, or None.

    `cand` indexes the points whose own normals are near vertical. Hypotheses come from triples
    of them and are scored on a random sample of them: a table holds most such points, so a
    few hundred triples find it, and no hypothesis is scored on the whole cloud. The winner is
    refitted by least squares to its sample inliers; the caller counts its inliers on the full
    cloud.
    """
    if len(cand) < 3:
        return None
    pick = cand[rng.integers(0, len(cand), min(len(cand), settings.ransac_sample))]
    sample = points[pick]
    tri = sample[rng.integers(0, len(sample), (settings.ransac_iterations, 3))]
    n, d = _plane_through(tri.astype(np.float64))
    n[n[:, 2] < math.cos(math.radians(settings.plane_max_tilt_deg))] = 0.0  # too tilted
    # float32 is ample for mm distances within a few metres, and twice as fast.
    dist = np.abs(sample @ n.T.astype(np.float32) + d.astype(np.float32))  # (S, H)
    score = np.count_nonzero(dist <= settings.plane_distance, axis=0)
    score[n[:, 2] == 0] = 0
    h = int(np.argmax(score))
    if score[h] < 3:
        return None
    n_ref, d_ref = _refine(sample[dist[:, h] <= settings.plane_distance].astype(np.float64))
    if n_ref[2] < math.cos(math.radians(settings.plane_max_tilt_deg)):
        n_ref, d_ref = n[h], float(d[h])
    return np.array([*n_ref, d_ref])


def plane_distance(points: np.ndarray, plane: np.ndarray) -> np.ndarray:
    """Signed height (m) of points above a plane (a, b, c, d) with a unit normal up."""
    return points @ plane[:3].astype(np.float32) + np.float32(plane[3])


def surface_inliers(inliers: np.ndarray, up: np.ndarray) -> int:
    """How many of a plane's `inliers` (mask) are points of a surface: those whose normal
    faces up (`up`, mask). The plane's band takes in whatever crosses it, and only a real
    surface fills it with points that face up. In the kitchen, bands 62-66 cm up through the
    counter's front held 6,700-10,800 points, under 400 of them facing up; one through a
    bowl's rim and a lying box's top beside it, at 94 cm, held 4,100, 1,700 facing up.
    Counted whole, that one passed as the bowl's support, 6 cm above the counter, and took
    the rim away with it. The counter's top: 109,000 points, 98,000 facing up. Our addition
    to 004."""
    return int(np.count_nonzero(inliers & up))


def height_at_centroid(points: np.ndarray, inliers: np.ndarray, plane: np.ndarray) -> float:
    """The plane's z (m) at the xy centroid of its inliers (a subsample of them suffices)."""
    c = points[np.flatnonzero(inliers)[::16], :2].mean(axis=0, dtype=np.float64)
    return float(-(plane[3] + plane[0] * c[0] + plane[1] * c[1]) / plane[2])


def remove_horizontal_planes(
    cloud: FusedCloud,
    settings: PerceptionSettings,
    seed: int = 0,
    find_plane: Callable[[np.ndarray, np.ndarray], np.ndarray | None] | None = None,
) -> tuple[np.ndarray, list[SupportSurface]]:
    """Remove the roughly horizontal planes from the cloud, as 004 6.1 does.

    Repeatedly: RANSAC finds the horizontal plane (normal within `plane_max_tilt_deg`, 5 deg,
    of vertical) with the most points within `plane_distance` (1.5 cm) among those left; it is
    removed if at least `min_plane_inliers` (13k scaled to our density, see there) of its
    inliers face up (`surface_inliers`) and if removing it keeps the total removed at or
    under `plane_max_removed` (70 %) of the cloud.

    Returns (keep mask (N,) bool: the points that are not on a removed plane, the removed
    planes as SupportSurfaces, largest first). A plane's height is its z at the centroid of its
    inliers (m, `base`). find_plane(points, candidate indices) -> plane or None stands in for
    the RANSAC (`best_horizontal_plane`), for comparing another library's.
    """
    rng = np.random.default_rng(seed)
    if find_plane is None:

        def find_plane(pts: np.ndarray, cand: np.ndarray) -> np.ndarray | None:
            return best_horizontal_plane(pts, cand, settings, rng)

    pts = cloud.points
    keep = np.ones(len(pts), bool)
    planes: list[SupportSurface] = []
    budget = int(settings.plane_max_removed * len(pts))
    need = min_plane_inliers(settings)
    up = cloud.normals[:, 2] >= math.cos(math.radians(settings.plane_candidate_tilt_deg))
    cand = np.flatnonzero(up)
    removed = 0
    while removed + need <= budget and len(cand) >= 3:
        plane = find_plane(pts, cand)
        if plane is None:
            break
        inl = keep & (np.abs(plane_distance(pts, plane)) <= settings.plane_distance)
        count = int(np.count_nonzero(inl))
        if surface_inliers(inl, up) < need or removed + count > budget:
            break
        keep &= ~inl
        removed += count
        cand = cand[keep[cand]]
        planes.append(SupportSurface(height=height_at_centroid(pts, inl, plane), plane=plane))
    return keep, planes
