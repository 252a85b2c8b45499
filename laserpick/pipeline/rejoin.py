"""Pieces of the target that the Euclidean clustering split off, joined back.

004 section 6.1 clusters at 5 mm. An object seen whole can still fall into several clusters:

- under an overhang (a doll's chin, a mug's rim over its handle) no downward-looking sensor
  sees, so the object's upper and lower parts can lie more than 5 mm apart
  (`overhang_labels`);
- where the cameras see a surface from far off or at a grazing angle, its points thin out: at
  about 1 m, every second pixel of a Structure sensor lands 3-4 mm apart on a lying tissue
  packet, 5-6 mm in its sparse tenth, and half the packet fell into a dozen clusters of 4 to 23
  points (`fragment_labels`).

Both work on the labels of `euclidean_clusters` over the clustered points `idx` (indices into
the cloud's points, m in `base`) and return the set of labels that make up the target. Our
additions to 004.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import cKDTree

from laserpick.settings import PerceptionSettings

__all__ = ["fragment_labels", "min_cluster_points", "overhang_labels"]

#: The neighbour whose distance sets a point's local spacing: the 4th nearest, so that on a
#: grid seen at an angle it is the spacing along the sparser of the two pixel directions.
SPACING_NEIGHBOUR = 4


def min_cluster_points(settings: PerceptionSettings) -> int:
    """Points the target cluster needs before the ball replaces it: 004's 500, scaled.

    Like the plane inliers (see `planes.min_plane_inliers`), 004's 500 counts full-resolution
    pixels of its Structure sensors; we keep 1 / pixel_stride^2 of them, so 500 / stride^2 (125
    at stride 2) asks for the same visible object area.
    """
    return max(1, math.ceil(settings.cluster_min_points / settings.pixel_stride**2))


def overhang_labels(
    pts: np.ndarray,
    idx: np.ndarray,
    labels: np.ndarray,
    target_label: int,
    real: np.ndarray,
    settings: PerceptionSettings,
) -> set[int]:
    """The target's label and those of the clusters an overhang split from it.

    A cluster among `real` (positions in `idx` of clusters of real size) within
    `occlusion_gap` of the target whose top-down footprint mostly lies inside the target's (or
    the target's inside its) is taken to be the same object. Objects standing apart on a table
    do not overlap seen from above, so this does not merge neighbours.
    """
    joined = {int(target_label)}
    if settings.occlusion_gap <= 0:
        return joined
    target = pts[idx[labels == target_label]]
    tree = cKDTree(target)
    lo, hi = target[:, :2].min(axis=0) - 0.005, target[:, :2].max(axis=0) + 0.005
    for label in np.unique(labels[real]):
        if label == target_label:
            continue
        other = pts[idx[labels == label]]
        gap = np.min(tree.query(other, distance_upper_bound=settings.occlusion_gap)[0])
        if gap > settings.occlusion_gap:
            continue
        xy = other[:, :2]
        inside = np.mean(np.all((xy >= lo) & (xy <= hi), axis=1))
        olo, ohi = xy.min(axis=0) - 0.005, xy.max(axis=0) + 0.005
        covered = np.mean(np.all((target[:, :2] >= olo) & (target[:, :2] <= ohi), axis=1))
        if inside > 0.5 or covered > 0.5:
            joined.add(int(label))
    return joined


def fragment_labels(
    pts: np.ndarray,
    idx: np.ndarray,
    labels: np.ndarray,
    joined: set[int],
    off_planes: np.ndarray,
    settings: PerceptionSettings,
) -> set[int]:
    """`joined` and the small clusters that continue it where its points thin out.

    A fragment joins when it lies within `fragment_gap_ratio` times the local spacing of the
    target's point nearest it (that point's distance to its 4th nearest neighbour), never
    further than `fragment_gap_max`. Where the target is dense the reach stays at the 5 mm
    tolerance, so a neighbour or speckle beside a well-seen object stays out; where it is
    sparse a missed pixel or two is bridged. Joined fragments extend the front, so a chain
    of them joins.

    A fragment is a cluster of fewer than `min_cluster_points` (too small to be taken for an
    object) with a point off every removed plane (`off_planes`, (len(idx),) bool): a piece
    wholly within a plane's 1.5 cm is as likely the support's depth noise, which on a floor
    seen from 1.5 m joined a phone.
    """
    ratio, reach = settings.fragment_gap_ratio, settings.fragment_gap_max
    if ratio <= 0 or reach <= settings.cluster_tolerance:
        return joined
    sizes = np.bincount(labels)
    member = np.isin(labels, list(joined))
    lifted = np.bincount(labels, weights=off_planes, minlength=len(sizes)) > 0
    free = ~member & (sizes[labels] < min_cluster_points(settings)) & lifted[labels]
    if not free.any():
        return joined
    cloud = pts[idx]
    if len(cloud) <= SPACING_NEIGHBOUR:
        return joined
    tree = cKDTree(cloud)
    front = np.flatnonzero(member)
    joined = set(joined)
    while len(front) and free.any():
        spacing = tree.query(cloud[front], k=SPACING_NEIGHBOUR + 1)[0][:, -1]
        allowed = np.clip(ratio * spacing, settings.cluster_tolerance, reach)
        free_pos = np.flatnonzero(free)
        d, nearest = cKDTree(cloud[front]).query(cloud[free_pos], distance_upper_bound=reach)
        close = np.isfinite(d)
        close[close] = d[close] <= allowed[nearest[close]]
        new = {int(label) for label in np.unique(labels[free_pos[close]])}
        if not new:
            break
        joined |= new
        grown = np.isin(labels, list(new))
        front = np.flatnonzero(grown)
        free &= ~grown
    return joined
