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
    VoxelGroups,
    frame_bases,
    in_regions,
    point_coords,
    slab_pairs,
)
from laserpick.settings import GraspSettings

COLLISION_VOXEL = 0.010  #: voxel edge (m) of pruned_tips' bounds: only speed depends on it


class CoarsePairs:
    """The collision cloud grouped into voxels (`voxels`: VoxelGroups of COLLISION_VOXEL,
    made once for all of a target's frames), and each sample's nearby voxels.

    Built with the representatives of the voxels in place of the points, and the hand
    regions grown by each voxel's radius, so that every (sample, point) pair of
    slab_pairs(cloud, ..., regions) has its voxel's (sample, representative) pair here.
    sid, vid: (P,) sample and voxel indices; h, u, v: (P,) the representative's coordinates
    (m, see slab_pairs); radius: (P,) the voxel's radius (m).
    """

    def __init__(
        self,
        voxels: VoxelGroups,
        samples: np.ndarray,
        normal: np.ndarray,
        axis: np.ndarray,
        regions: list[tuple[float, float, float]],
    ) -> None:
        self.voxels = voxels
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
    n_s, n_o = len(samples), len(angles)
    basis, own = frame_bases(samples, normal, axis)
    basis = np.ascontiguousarray(basis.transpose(1, 2, 0), np.float32)  # for point_coords
    own = np.ascontiguousarray(own.T, np.float32)
    want = np.ones((n_s, n_o), bool) if want is None else want
    sample_xyz = point_coords(samples.T.astype(np.float32), np.arange(n_s), basis, own)
    lower = _representative_minima(pairs, sample_xyz, want, angles, grid, hand, s, regions)
    bound = placement_minima(*lower, grid)
    bound[~want.ravel()] = -np.inf  # blocked, as far as the rest is concerned
    live, column, worst_f, worst_p = _free_stop_maxima(bound, pairs.voxels, grid, hand, s)
    need_o = _voxels_to_open(pairs, live, column, worst_f, worst_p, angles, grid, hand, s)
    more = _opened_minima(pairs, need_o, basis, own, n_s, angles, grid, hand, s, regions)
    stop = placement_minima(np.minimum(lower[0], more[0]), np.minimum(lower[1], more[1]), grid)
    stop[~want.ravel()] = -np.inf
    return tips_from_stops(stop, s).reshape(n_s, n_o, len(grid.offsets))


def _representative_minima(
    pairs: CoarsePairs,
    sample_xyz: tuple[np.ndarray, np.ndarray, np.ndarray],
    want: np.ndarray,
    angles: np.ndarray,
    grid: ClosingGrid,
    hand: HandGeometry,
    s: GraspSettings,
    regions: list[tuple[float, float, float]],
) -> tuple[np.ndarray, np.ndarray]:
    """pruned_tips' step 1: bin_minima of the representatives in `regions` and of the
    samples themselves (`sample_xyz`: their (h, u, v); cloud points too, and they stop the
    palm at finger_length: often the deciding stop), for the frames in `want`."""
    n_s = len(want)
    sh, su, sv = sample_xyz
    exact = np.flatnonzero(in_regions(pairs.h, pairs.u, pairs.v, regions))
    sid = np.r_[pairs.sid.take(exact), np.arange(n_s)]
    return bin_minima(
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


def _free_stop_maxima(
    bound: np.ndarray, vox: VoxelGroups, grid: ClosingGrid, hand: HandGeometry, s: GraspSettings
) -> tuple[np.ndarray, np.ndarray, RangeMax, RangeMax]:
    """pruned_tips' step 2 tables: per bin and frame, the largest stop bound (`bound`, (F, K)
    m) of the free placements covering that bin (for the palm less finger_length, to compare
    with depths), as RangeMax over runs of bins as wide as a voxel of `vox` can span. Only
    frames with a free placement are left to settle: `live` (F,) says which, `column` maps a
    frame to its column of the tables."""
    free = tips_from_stops(bound, s) > -np.inf  # (F, K)
    live = free.any(axis=1)
    column = np.cumsum(live) - 1  # frame -> column of the tables below
    free = np.where(free, bound, -np.inf)[live].T  # (K, live frames)
    worst_f = np.full((grid.n_bins, len(free[0])), -np.inf, np.float32)
    worst_p = np.full((grid.n_bins, len(free[0])), -np.inf, np.float32)
    nf = grid.n_finger_bins
    for k in range(len(grid.offsets)):
        for lo, hi in (
            (grid.left[k], grid.left[k] + nf),
            (max(grid.right[k] - nf, 0), grid.right[k]),
        ):
            np.maximum(worst_f[lo:hi], free[k], out=worst_f[lo:hi])
        lo, hi = grid.palm_lo[k], grid.palm_hi[k]
        np.maximum(worst_p[lo:hi], free[k] - hand.finger_length, out=worst_p[lo:hi])
    widest = math.floor(2 * float(vox.radius.max()) / grid.bin) + 2  # bins a voxel can span
    return live, column, RangeMax(worst_f, widest), RangeMax(worst_p, widest)


def _voxels_to_open(
    pairs: CoarsePairs,
    live: np.ndarray,
    column: np.ndarray,
    worst_f: RangeMax,
    worst_p: RangeMax,
    angles: np.ndarray,
    grid: ClosingGrid,
    hand: HandGeometry,
    s: GraspSettings,
) -> list[np.ndarray]:
    """pruned_tips' step 2: per orientation, the (voxel, sample) pairs whose frame has a free
    placement and whose voxel may reach into a band below the stop bound of a free placement
    covering its bins (`_free_stop_maxima`)."""
    F, t0, n_o, n_b = hand.finger_length, s.gpd_init_bite, len(angles), grid.n_bins
    finger_h, palm_h = max(hand.finger_width, hand.pad_width) / 2, hand.palm_depth / 2
    least_h = np.abs(pairs.h) - pairs.radius
    select = by_orientation(live.reshape(-1, n_o), pairs.sid, least_h <= max(finger_h, palm_h))
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
    return [np.concatenate(x) for x in hits]


def _opened_minima(
    pairs: CoarsePairs,
    need_o: list[np.ndarray],
    basis: np.ndarray,
    own: np.ndarray,
    n_s: int,
    angles: np.ndarray,
    grid: ClosingGrid,
    hand: HandGeometry,
    s: GraspSettings,
    regions: list[tuple[float, float, float]],
) -> tuple[np.ndarray, np.ndarray]:
    """pruned_tips' step 3: bin_minima of the points of the voxels that may matter
    (`need_o`, per orientation the pairs of `_voxels_to_open`), for the orientations where
    they may. basis, own: the samples' frames as point_coords takes them."""
    vox = pairs.voxels
    n_o = len(angles)
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
    return bin_minima(
        h.take(keep), u.take(keep), v.take(keep), sid.take(keep), n_s, angles, grid, hand, s, select
    )


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
