"""The hand's collision depths bounded with voxels (a branch and bound): the collision cloud
grouped into voxels whose representative is a cloud point, so each voxel bounds the stops of
its points; only the voxels that could still lower a free placement's stop are opened.
`pruned_tips` returns what `closing_grid.deepest_tips` computes directly. Metres.
"""

from __future__ import annotations

import math

import numpy as np

from laserpick.description.dims import HandGeometry
from laserpick.pipeline.gpd.closing_grid import (
    ClosingGrid,
    bin_minima,
    by_orientation,
    orientation_blocks,
    placement_minima,
    tips_from_stops,
)
from laserpick.pipeline.gpd.neighbourhoods import (
    ROUNDING,
    frame_bases,
    in_regions,
    point_coords,
    slab_pairs,
)
from laserpick.settings import GraspSettings

COLLISION_VOXEL = 0.010  #: voxel edge (m) of pruned_tips' bounds: only speed depends on it


class VoxelGroups:
    """Cloud points grouped by the voxel (edge `edge`, m) they fall in.

    points: (N, 3) float32, sorted so that each voxel's points are contiguous (xyz: the same
    as (3, N)); starts, counts: (V,) each voxel's run in `points`; rep: (V,) index into
    `points` of each voxel's representative, the point nearest the voxel's centroid; radius:
    (V,) float32, the largest distance (m) from the representative to a point of its voxel,
    plus a rounding margin. Every point of voxel i lies within radius[i] of points[rep[i]].
    """

    def __init__(self, points: np.ndarray, edge: float) -> None:
        points = np.asarray(points, np.float32)  # as slab_pairs uses them
        lo = points.min(axis=0)
        dims = np.floor((points.max(axis=0) - lo) / np.float32(edge)).astype(np.int64) + 1
        cell = np.floor((points - lo) / np.float32(edge)).astype(np.int64)
        key = (cell[:, 0] * dims[1] + cell[:, 1]) * dims[2] + cell[:, 2]
        order = np.argsort(key)
        key = key.take(order)
        self.points = points.take(order, axis=0)
        self.starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
        self.counts = np.diff(np.r_[self.starts, len(key)])
        group = np.repeat(np.arange(len(self.starts)), self.counts)
        centroid = np.add.reduceat(self.points, self.starts) / self.counts[:, None]
        d = self.points - centroid.take(group, axis=0)
        dist = np.einsum("ij,ij->i", d, d)
        nearest = np.minimum.reduceat(dist, self.starts)
        index = np.arange(len(self.points))
        self.rep = np.minimum.reduceat(
            np.where(dist == nearest.take(group), index, len(index)), self.starts
        )
        d = self.points - self.points.take(self.rep.take(group), axis=0)
        spread = np.sqrt(np.maximum.reduceat(np.einsum("ij,ij->i", d, d), self.starts))
        self.radius = (spread + ROUNDING).astype(np.float32)
        self.xyz = np.ascontiguousarray(self.points.T)  # for point_coords

    def members(self, voxels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The points of each of `voxels` (R,): (E,) index into `voxels` and (E,) index into
        `points`, voxel by voxel."""
        count = self.counts[voxels]
        parent = np.repeat(np.arange(len(voxels)), count)
        first = np.cumsum(count) - count
        return parent, np.arange(len(parent)) - first[parent] + self.starts[voxels][parent]


class CoarsePairs:
    """The collision cloud grouped into voxels, and each sample's nearby voxels.

    Built with the representatives of the voxels (VoxelGroups) in place of the points, and the
    hand regions grown by each voxel's radius, so that every (sample, point) pair of
    slab_pairs(cloud, ..., regions) has its voxel's (sample, representative) pair here.
    sid, vid: (P,) sample and voxel indices; h, u, v: (P,) the representative's coordinates
    (m, see slab_pairs); radius: (P,) the voxel's radius (m).
    """

    def __init__(
        self,
        cloud: np.ndarray,
        samples: np.ndarray,
        normal: np.ndarray,
        axis: np.ndarray,
        regions: list[tuple[float, float, float]],
    ) -> None:
        self.voxels = VoxelGroups(cloud, COLLISION_VOXEL)
        grow = float(self.voxels.radius.max())
        grown = [(hs + grow, r + grow, um + grow) for hs, r, um in regions]
        reps = self.voxels.points.take(self.voxels.rep, axis=0)
        sid, vid, h, u, v = slab_pairs(reps, samples, normal, axis, grown)
        # Most voxels are smaller than the largest: grow the regions by their own radius.
        radius = self.voxels.radius[vid]
        keep = np.flatnonzero(in_regions(h, u, v, regions, radius))
        self.sid, self.vid, self.h, self.u, self.v, self.radius = (
            x.take(keep) for x in (sid, vid, h, u, v, radius)
        )


def pruned_tips(
    pairs: CoarsePairs,
    samples: np.ndarray,
    normal: np.ndarray,
    axis: np.ndarray,
    angles: np.ndarray,
    grid: ClosingGrid,
    hand: HandGeometry,
    s: GraspSettings,
    regions: list[tuple[float, float, float]],
    want: np.ndarray | None = None,
) -> np.ndarray:
    """deepest_tips over every (sample, cloud point) pair in `regions`, found by looking at
    few of the points (branch and bound on the voxels of `pairs`). Same result, up to float32
    rounding of the points' coordinates (~1e-8 m), for the frames in `want` ((S, O) bool,
    default all); -inf for the others.

    1. Upper bounds: the voxels' representatives are cloud points, so the stops (see
       placement_minima) computed from those in `regions`, and from each sample itself, are
       at or beyond the true ones. A placement already blocked by them is blocked for good.
    2. Every point of a voxel lies within its radius r of the representative, so its approach
       depth is at least (representative's depth - r), and its closing bin within r / bin
       bins of the representative's. A voxel whose bound is not below the stop bound of any
       still-free placement covering those bins cannot change a result.
    3. The points of the remaining (voxel, frame) combinations are added exactly.

    A point left out is thus never below the stop of a placement it could reach, so every
    placement's stop, and whether it is free, come out as deepest_tips has them.
    """
    vox = pairs.voxels
    F, t0 = hand.finger_length, s.gpd_init_bite
    n_s, n_o, n_b = len(samples), len(angles), grid.n_bins
    basis, own = frame_bases(samples, normal, axis)
    basis = np.ascontiguousarray(basis.transpose(1, 2, 0), np.float32)  # for point_coords
    own = np.ascontiguousarray(own.T, np.float32)
    want = np.ones((n_s, n_o), bool) if want is None else want

    # 1. Representatives in the regions, and the samples (cloud points too, and they stop the
    # palm at finger_length: often the deciding stop).
    exact = np.flatnonzero(in_regions(pairs.h, pairs.u, pairs.v, regions))
    sh, su, sv = point_coords(samples.T.astype(np.float32), np.arange(n_s), basis, own)
    sid = np.r_[pairs.sid.take(exact), np.arange(n_s)]
    lower = bin_minima(
        np.r_[pairs.h.take(exact), sh],
        np.r_[pairs.u.take(exact), su],
        np.r_[pairs.v.take(exact), sv],
        sid,
        n_s,
        angles,
        grid,
        hand,
        s,
        by_orientation(want, sid),
    )
    bound = placement_minima(*lower, grid)
    bound[~want.ravel()] = -np.inf  # blocked, as far as the rest is concerned

    # 2. Per bin and frame, the largest stop bound of the free placements covering that bin
    # (for the palm less finger_length, to compare with depths), and its maxima over runs of
    # bins. Only frames with a free placement are left to settle.
    free = tips_from_stops(bound, s) > -np.inf  # (F, K)
    live = free.any(axis=1)
    column = np.cumsum(live) - 1  # frame -> column of the tables below
    free = np.where(free, bound, -np.inf)[live].T  # (K, live frames)
    worst_f = np.full((n_b, len(free[0])), -np.inf, np.float32)
    worst_p = np.full((n_b, len(free[0])), -np.inf, np.float32)
    nf = grid.n_finger_bins
    for k in range(len(grid.offsets)):
        for lo, hi in (
            (grid.left[k], grid.left[k] + nf),
            (max(grid.right[k] - nf, 0), grid.right[k]),
        ):
            np.maximum(worst_f[lo:hi], free[k], out=worst_f[lo:hi])
        lo, hi = grid.palm_lo[k], grid.palm_hi[k]
        np.maximum(worst_p[lo:hi], free[k] - F, out=worst_p[lo:hi])
    widest = math.floor(2 * float(vox.radius.max()) / grid.bin) + 2  # bins a voxel can span
    worst_f, worst_p = RangeMax(worst_f, widest), RangeMax(worst_p, widest)

    # Only (pair, orientation) combinations whose frame has a free placement, and whose voxel
    # may reach into a band, can need a closer look.
    finger_h, palm_h = max(hand.finger_width, hand.pad_width) / 2, hand.palm_depth / 2
    least_h = np.abs(pairs.h) - pairs.radius
    select = by_orientation(live.reshape(n_s, n_o), pairs.sid, least_h <= max(finger_h, palm_h))
    hits: list[list[np.ndarray]] = [[np.zeros(0, np.intp)] for _ in range(n_o)]
    for o, p in orientation_blocks(select, len(pairs.sid), n_o):
        r, lh, u, v = (x.take(p) for x in (pairs.radius, least_h, pairs.u, pairs.v))
        ct, st = np.float32(math.cos(angles[o])), np.float32(math.sin(angles[o]))
        a, c = ct * u + st * v, st * u - ct * v
        # The bins the voxel's points can fall in (clipped: the grid's edge bins stand for
        # those beyond, conservatively).
        j_lo = np.clip(np.floor((c - r - grid.lo) / grid.bin), 0, n_b - 1).astype(np.intp)
        j_hi = np.clip(np.floor((c + r - grid.lo) / grid.bin), 0, n_b - 1).astype(np.intp)
        col = column.take(pairs.sid.take(p) * n_o + o)
        least, most = a - r, a + r
        need = ((lh <= finger_h) & (most >= t0 - F) & (least < worst_f(j_lo, j_hi, col))) | (
            (lh <= palm_h)
            & (most >= t0 - F - hand.palm_length)
            & (least < worst_p(j_lo, j_hi, col))
        )
        hits[o].append(p[need])

    # 3. The points of the voxels that may matter, for the orientations where they may.
    need_o = [np.concatenate(x) for x in hits]
    is_row = np.zeros(len(pairs.sid), bool)
    for p in need_o:
        is_row[p] = True
    rows = np.flatnonzero(is_row)
    row_of = np.cumsum(is_row) - 1  # pair index -> row
    need = np.zeros((n_o, len(rows)), bool)
    for o, p in enumerate(need_o):
        need[o, row_of.take(p)] = True
    parent, members = vox.members(pairs.vid.take(rows))
    sid = pairs.sid.take(rows).take(parent)
    h, u, v = point_coords(vox.xyz.take(members, axis=1), sid, basis, own)
    keep = np.flatnonzero(in_regions(h, u, v, regions))
    row = parent.take(keep)
    select = np.stack([in_row.take(row) for in_row in need])
    more = bin_minima(
        h.take(keep), u.take(keep), v.take(keep), sid.take(keep), n_s, angles, grid, hand, s, select
    )
    stop = placement_minima(np.minimum(lower[0], more[0]), np.minimum(lower[1], more[1]), grid)
    stop[~want.ravel()] = -np.inf
    return tips_from_stops(stop, s).reshape(n_s, n_o, len(grid.offsets))


class RangeMax:
    """Maxima of a (bins, columns) table over runs of consecutive bins, per column, in O(1)
    per query: a sparse table, whose level l holds the maxima over 2**l consecutive bins."""

    def __init__(self, table: np.ndarray, widest: int) -> None:
        n_levels = max(widest, 1).bit_length()  # 2**(n_levels - 1) <= widest
        levels = np.empty((n_levels, *table.shape), table.dtype)
        levels[0] = table
        for level in range(1, n_levels):
            prev, half = levels[level - 1], 2 ** (level - 1)
            levels[level, -half:] = prev[-half:]
            np.maximum(prev[:-half], prev[half:], out=levels[level, :-half])
        self.flat = levels.ravel()
        self.n_bins, self.n_cols = table.shape
        self.log2 = np.zeros(widest + 1, np.intp)  # floor(log2(n)) for n >= 1
        for level in range(1, n_levels):
            self.log2[2**level :] = level

    def __call__(self, lo: np.ndarray, hi: np.ndarray, col: np.ndarray) -> np.ndarray:
        """Max over bins lo..hi (inclusive, hi - lo < widest) of column `col`, elementwise."""
        level = self.log2.take(hi - lo + 1)
        first = (level * self.n_bins + lo) * self.n_cols + col
        last = (level * self.n_bins + hi + 1 - (1 << level)) * self.n_cols + col
        return np.maximum(self.flat.take(first), self.flat.take(last))
