"""The target object's points at a laser mark: 004 section 6.1, with 002 and EL-E (000) options.

Two methods:

- "cluster" (004 6.1): remove the roughly horizontal planes (RANSAC), extract Euclidean
  clusters at 5 mm, keep the one nearest the mark (with the pieces an overhang or thin
  coverage split from it: rejoin.py); a cluster under 500 points gives way to a
  0.1 m ball around the mark (less the other clusters in it: ours). 002 II.C adds a guard:
  a segment that swallowed more than 90 % of the points around the mark has merged with its
  support, and the 8 cm ball replaces it.
- "grid" (000 4.2.2): EL-E's surface height histogram, then 26-connected components of a
  1 x 1 x 0.25 cm occupancy grid of the points above the surface.

Points are float32 (N, 3) in `base` (x forward, y left, z up; metres). Only sensor data comes
in: the fused cloud and the mark.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from scipy import ndimage
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from laserpick.pipeline.planes import (
    best_horizontal_plane,
    height_at_centroid,
    min_plane_inliers,
    plane_distance,
    remove_horizontal_planes,
    surface_inliers,
)
from laserpick.pipeline.rejoin import fragment_labels, min_cluster_points, overhang_labels
from laserpick.pipeline.surface import surface_height, voi_mask
from laserpick.settings import PerceptionSettings
from laserpick.types import Failure, FusedCloud, Segmentation, SupportSurface

#: What the user hears. Nothing standing at a mark on a surface is also what a clear glass or
#: plastic object looks like to depth cameras (the beam and their light pass through it).
NO_OBJECT = (
    "I see no object at the mark, only the surface: a clear glass or plastic object does not"
    " show to my cameras."
)
NOTHING_SEEN = "The mark is not on anything my cameras can see."

#: 26-connectivity in a 3D grid (000 4.2.2).
_TWENTY_SIX = np.ones((3, 3, 3), bool)


# --- Euclidean clusters (004 6.1) -------------------------------------------------------------


def euclidean_clusters(points: np.ndarray, tolerance: float) -> np.ndarray:
    """Euclidean cluster extraction: a label (N,) int per point, from 0; PCL's definition.

    Two points share a cluster when a chain of points, each within `tolerance` (m) of the
    next, joins them: the connected components of the radius-`tolerance` neighbour graph.
    Call it on a crop (a few thousand points): cKDTree pairs + sparse components take ~10 ms
    for 8k points, twice as fast as Open3D's cluster_dbscan(eps, min_points=1), which is the
    same definition and gives the same clusters (bench/open3d_vs_ours.py).
    """
    n = len(points)
    if n == 0:
        return np.zeros(0, np.int64)
    # An unbalanced, uncompacted tree builds faster and queries as fast for a crop this size.
    tree = cKDTree(points, balanced_tree=False, compact_nodes=False)
    pairs = tree.query_pairs(tolerance, output_type="ndarray")
    graph = csr_matrix((np.ones(len(pairs), bool), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    # Each pair is stored once; weak components of the directed graph are the clusters.
    _, labels = connected_components(graph, directed=True, connection="weak")
    return labels.astype(np.int64)


# --- the target -------------------------------------------------------------------------------


def _crop_plane(
    cloud: FusedCloud, crop: np.ndarray, settings: PerceptionSettings, seed: int = 0
) -> SupportSurface | None:
    """The horizontal plane with the most support among the cloud's points `crop` (indices),
    if it has the inliers `remove_horizontal_planes` asks of a plane; else None."""
    up = cloud.normals[crop, 2] >= math.cos(math.radians(settings.plane_candidate_tilt_deg))
    plane = best_horizontal_plane(cloud.points, crop[up], settings, np.random.default_rng(seed))
    if plane is None:
        return None
    on = np.abs(plane_distance(cloud.points[crop], plane)) <= settings.plane_distance
    if surface_inliers(on, up) < min_plane_inliers(settings):
        return None
    inl = np.zeros(len(cloud), bool)
    inl[crop] = on
    return SupportSurface(height=height_at_centroid(cloud.points, inl, plane), plane=plane)


def _surface_under(
    points: np.ndarray, mark: np.ndarray, planes: list[SupportSurface], settings
) -> SupportSurface | None:
    """The removed plane under the mark: the highest one at or below it (within the plane
    distance) with inliers among `points` (the crop around the mark); its height at the mark."""
    best: SupportSurface | None = None
    for s in planes:
        h = float(-(s.plane[3] + s.plane[0] * mark[0] + s.plane[1] * mark[1]) / s.plane[2])
        if h > mark[2] + settings.plane_distance or (best is not None and h <= best.height):
            continue
        if np.any(np.abs(plane_distance(points, s.plane)) <= settings.plane_distance):
            best = SupportSurface(height=h, plane=s.plane)
    return best


def _sq_dist(points: np.ndarray, mark: np.ndarray) -> np.ndarray:
    """Squared distances (m^2) of the points to the mark."""
    d = points - mark
    return np.einsum("ij,ij->i", d, d)


def _segment_cluster(
    cloud: FusedCloud, mark: np.ndarray, d2: np.ndarray, settings: PerceptionSettings
) -> Segmentation | Failure:
    """004 6.1's segmentation with our regrowth, and 002's merged-with-support guard.

    `d2`: squared distance (m^2) of every cloud point to the mark.
    """
    pts = cloud.points
    keep, planes = remove_horizontal_planes(cloud, settings)
    crop = np.flatnonzero(d2 <= settings.cluster_crop_radius**2)
    crop_pts = pts[crop]
    surface = _surface_under(crop_pts, mark, planes, settings)
    if surface is None:
        # One plane filling the view (the floor before the scooter) holds more than 004's
        # 70 % of the cloud and stays; the object would be clustered with it. It is looked
        # for in the crop around the mark instead, by the same RANSAC. Our addition to 004.
        local = _crop_plane(cloud, crop, settings)
        if local is not None:
            on_plane = np.abs(plane_distance(crop_pts, local.plane)) <= settings.plane_distance
            keep = keep.copy()
            keep[crop[on_plane]] = False
            planes = [*planes, local]
            surface = _surface_under(crop_pts, mark, planes, settings)
    # Plane removal at 1.5 cm also strips every object's bottom 1.5 cm (and all of a phone).
    # Removed points clearly above their plane, beyond the depth noise, rejoin the clustering,
    # so the cluster regrows into them through the same 5 mm chains. Our addition to 004.
    cand = keep[crop]
    for s in planes:
        h = plane_distance(crop_pts, s.plane)
        cand |= (h > settings.regrow_min_height) & (h <= settings.plane_distance)
    idx = crop[cand]
    labels = euclidean_clusters(pts[idx], settings.cluster_tolerance)
    sizes = np.bincount(labels, minlength=1)
    real = np.flatnonzero(sizes[labels] >= settings.cluster_noise_points)
    nearest = real[np.argmin(d2[idx[real]])] if len(real) else -1
    gap = math.sqrt(d2[idx[nearest]]) if nearest >= 0 else math.inf
    on_plane = surface is not None and mark[2] - surface.height <= settings.plane_distance
    if gap == math.inf or (on_plane and gap > settings.mark_object_distance):
        # The mark is on a table with nothing standing there (a transparent cup reads as the
        # table under it): a ball here would be a piece of table.
        return Failure("precondition", NO_OBJECT)
    joined = overhang_labels(pts, idx, labels, labels[nearest], real, settings)
    joined = fragment_labels(pts, idx, labels, joined, keep[idx], settings)
    target = idx[np.isin(labels, list(joined))]
    method: Literal["cluster", "ball", "merged_radius"] = "cluster"
    if len(target) < min_cluster_points(settings):
        # 004's ball, less the other objects in it: the points of every other cluster of
        # real size. Whole, the ball about an 8 mm pill took in part of the phone 10 cm
        # away, and the grasp closed on the phone (9 of 12 `surfaces` pills). Ours.
        ball = d2 <= settings.fallback_ball_radius**2
        others = real[labels[real] != labels[nearest]]
        ball[idx[others]] = False
        target, method = np.flatnonzero(ball), "ball"
    # 002 II.C: "if more than 90 % of the available points are considered part of the object",
    # the segment has merged with its support. The available points: the whole cloud (planes
    # included) within the crop radius of the mark, 30 cm, more than any graspable object
    # fills, so only a segment that took in its support can hold 90 % of them.
    if len(target) > settings.merged_fraction * len(crop):
        target, method = np.flatnonzero(d2 <= settings.merged_radius**2), "merged_radius"
    return Segmentation(indices=np.sort(target), method=method, surface=surface)


def _segment_grid(
    cloud: FusedCloud, mark: np.ndarray, settings: PerceptionSettings
) -> Segmentation | Failure:
    """EL-E's object segmentation (000 4.2.2) in the VOI around the mark.

    The surface top z_top comes from the height histogram (4.2.1); the points above it (plus
    `grid_surface_margin`, our addition) go into
    a 3D occupancy grid of `grid_cell_xy` x `grid_cell_xy` x `grid_cell_z` (1 x 1 x 0.25 cm);
    26-connected components of the occupied cells are the objects (when 1 to 50 cm long, as
    EL-E requires), and the one with the point nearest the mark is the target.
    """
    pts = cloud.points
    voi = np.nonzero(voi_mask(pts, mark, settings))[0]
    z_top = surface_height(pts[voi], settings)
    if z_top is None:
        return Failure("precondition", NOTHING_SEEN)
    surface = SupportSurface(height=z_top, plane=np.array([0.0, 0.0, 1.0, -z_top]))
    # Our margin: EL-E's laser scanner was quieter than our depth sensors (sigma ~1.5 mm at
    # the table, against 2.5 mm bins), and the table's noise just above z_top fills enough
    # 1 cm cells to join every object into one 26-connected component. One grid layer more
    # leaves the noise out.
    idx = voi[pts[voi, 2] > z_top + settings.grid_surface_margin]
    if len(idx) == 0:
        return Failure("precondition", NO_OBJECT)
    cell = np.array([settings.grid_cell_xy, settings.grid_cell_xy, settings.grid_cell_z])
    origin = pts[idx].min(axis=0).astype(np.float64)
    ijk = np.floor((pts[idx] - origin) / cell).astype(np.int64)
    grid = np.zeros(ijk.max(axis=0) + 1, bool)
    grid[tuple(ijk.T)] = True
    labels, _ = ndimage.label(grid, structure=_TWENTY_SIX)
    point_label = labels[tuple(ijk.T)]
    d = np.linalg.norm(pts[idx] - mark, axis=1)
    lab, gap = _nearest_object(pts[idx], point_label, d, settings)
    on_surface = mark[2] - z_top <= settings.plane_distance
    target = idx[point_label == lab] if lab else idx[:0]
    # A few cells of noise are not an object (a clear cup leaves only speckle where it stands).
    if len(target) < settings.cluster_noise_points or (
        on_surface and gap > settings.mark_object_distance
    ):
        return Failure("precondition", NO_OBJECT)
    return Segmentation(indices=np.sort(target), method="grid", surface=surface)


def _nearest_object(
    points: np.ndarray, label: np.ndarray, dist: np.ndarray, settings: PerceptionSettings
) -> tuple[int, float]:
    """The grid component nearest the mark that EL-E counts as an object, and its distance (m).

    000 4.2.2 rejects components shorter than 1 cm along their direction of maximum variance
    (noise from the flat surface) or longer than 50 cm (too large to grasp). Components are
    tried nearest first; (0, inf) when none qualifies.
    """
    n = int(label.max()) + 1
    near = np.full(n, np.inf)
    np.minimum.at(near, label, dist)
    for lab in np.argsort(near):
        if not np.isfinite(near[lab]):
            break
        p = points[label == lab].astype(np.float64)
        if len(p) >= 2:
            c = p - p.mean(axis=0)
            axis = np.linalg.svd(c, full_matrices=False)[2][0]
            length = float(np.ptp(c @ axis))
            if settings.grid_min_object_length <= length <= settings.grid_max_object_length:
                return int(lab), float(near[lab])
    return 0, np.inf


def segment_target(
    cloud: FusedCloud,
    mark_point: np.ndarray,
    settings: PerceptionSettings,
    method: Literal["cluster", "grid"] = "cluster",
) -> Segmentation | Failure:
    """The points of the object at the mark (m, `base`), or a Failure that says why not.

    "cluster" is 004 6.1 (with 002's merged guard and our regrowth, see `_segment_cluster`);
    "grid" is EL-E's occupancy grid (000 4.2.2). Either fails with kind "precondition" when
    the mark is far from every point, or when it is on a support surface with no object at it.
    """
    mark = np.asarray(mark_point, np.float32).reshape(3)
    if len(cloud) == 0:
        return Failure("precondition", NOTHING_SEEN)
    d2 = _sq_dist(cloud.points, mark)
    if d2.min() > settings.mark_max_gap**2:
        return Failure("precondition", NOTHING_SEEN)
    if method == "grid":
        return _segment_grid(cloud, mark, settings)
    return _segment_cluster(cloud, mark, d2, settings)
