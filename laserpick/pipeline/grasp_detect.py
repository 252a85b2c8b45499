"""GPD-style grasp candidates (paper 004 section 6.2; ten Pas et al., "Grasp Pose Detection
in Point Clouds", 2017), geometric part only: sample the target, build a local frame at each
sample, rotate and slide the hand there, push it in until just before contact, and keep the
collision-free hands whose pads close antipodally on the object. GPD's learned classifier is
not reproduced; the antipodal test (GPD's own labelling rule) stands in for it.

Frames: everything is in `base` (x forward, y left, z up), metres. A hand frame has the hand
axis (x), the closing axis (y, between the fingers) and the approach axis (z, palm toward the
object); a point's hand coordinates are (h, c, a) along those axes. The TCP lies midway between
the pads' centres, pad_depth / 2 behind the fingertips.

Hand model (GraspSettings, mirroring description/dims): two fingers, each a box from the inner pad
face (at +-width_max / 2 from the hand centre when open) outward by pad + plate thickness,
finger_length deep along the approach and finger_width along the hand axis; behind the finger
roots a palm box palm_width x palm_depth x palm_length. The detector tests that hand grown
by side_clearance on its sides (cleared_hand), so a real hand clears what was seen.

Speed: every (sample, orientation) pair is one "frame". Scene points are binned by their
closing coordinate per frame (np.minimum.at), so each finger placement's deepest collision-free
depth is a min over a few bins rather than a pass over the points. Bin edges are placed on the
fingers' inner faces, so the faces that touch the object are exact; the outer faces and the
palm's sides are conservative by less than one bin (width_max / placements / 4, ~2 mm).

Three shortcuts make it 15-50x faster (bench/grasp_detect_speed.py) without changing the
result beyond float32 rounding of the coordinates (~1e-8 m):
- The antipodal test is bounded first (antipodal_possible): a frame whose pads could not
  hold enough contacts at any depth and placement needs no collision test. On the captured
  objects that is 88-100 % of the frames (a clean synthetic cylinder: only 15 %).
- Collisions are bounded with voxels (pruned_tips, a branch and bound): each voxel's
  representative is a scene point, so it bounds the stops from above; its radius bounds its
  other points' depths from below; only the voxels that could still lower a free placement's
  stop are opened. deepest_tips is the direct computation it reproduces.
- numpy is used in cache-sized blocks with the long axis innermost, selecting before
  computing, with np.take rather than fancy indexing: on a small machine, large temporaries
  and 2-D fancy indexing cost more than the arithmetic. np.minimum.at itself is cheap
  (numpy >= 1.25 has a fast path for it; sorting for np.minimum.reduceat is slower).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace

import numpy as np
from scipy.spatial import cKDTree

from laserpick.pipeline.cloud import voxel_first
from laserpick.settings import GraspSettings, get_settings
from laserpick.types import Grasp

BINS_PER_PLACEMENT = 4  #: closing-axis bins per finger-placement step (collision resolution)
SAMPLE_CHUNK = 100  #: samples per block of slab_pairs' coordinate matrix
POINT_BLOCK = 1024  #: points per block of slab_pairs' coordinate matrix (cache-sized)
PAIR_BLOCK = 8192  #: (sample, point) pairs per block of (orientations, pairs) arrays
ORIENTED_BLOCK = 32768  #: (pair, orientation) combinations per block of flat arrays
COLLISION_VOXEL = 0.010  #: voxel edge (m) of pruned_tips' bounds: only speed depends on it
MIN_SHIFT = 0.001  #: m; patch_moves shifts no hand by less: the pads would feel no change
MIN_TURN = math.radians(1.0)  #: rad; nor turns one by less
ROUNDING = 1e-6  #: m added to distance bounds, well above float32 rounding near the target


# --- Sampling and local frames -------------------------------------------------------------


def sample_indices(n_points: int, n_samples: int, rng: np.random.Generator) -> np.ndarray:
    """Indices of up to `n_samples` distinct target points, drawn uniformly (sorted)."""
    if n_points <= n_samples:
        return np.arange(n_points)
    return np.sort(rng.choice(n_points, size=n_samples, replace=False))


def local_frames(
    target: np.ndarray,
    normals: np.ndarray,
    idx: np.ndarray,
    s: GraspSettings,
    tree: cKDTree | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Surface normal and curvature axis (each (S, 3), unit) at the target points `idx`.

    The normal is the mean of the neighbours' normals within gpd_nn_radius (kept pointing the
    way they were given: outward, toward the sensors). The curvature axis is the direction of
    least normal variation: the eigenvector of sum(n n^T) with the smallest eigenvalue (GPD),
    made orthogonal to the normal. `tree`: a KD-tree of `target`, if one is at hand.
    """
    tree = tree if tree is not None else cKDTree(target)
    k = min(s.gpd_frame_neighbours, len(target))
    _, nb = tree.query(target[idx], k=k, distance_upper_bound=s.gpd_nn_radius)
    nb = np.asarray(nb).reshape(len(idx), k)
    padded = np.vstack([normals.astype(np.float64), np.zeros((1, 3))])  # index M: no neighbour
    n = padded[nb]  # (S, k, 3), zero rows for missing neighbours
    normal = n.sum(axis=1)
    own = normals[idx].astype(np.float64)
    weak = np.linalg.norm(normal, axis=1) < 1e-6  # opposing normals cancel: keep the sample's
    normal[weak] = own[weak]
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    _, vecs = np.linalg.eigh(np.einsum("ski,skj->sij", n, n))
    axis = vecs[:, :, 0]  # smallest eigenvalue first
    axis -= normal * np.sum(axis * normal, axis=1, keepdims=True)
    bad = np.linalg.norm(axis, axis=1) < 1e-3  # eigenvector along the normal: any tangent does
    if bad.any():
        alt = np.where(np.abs(normal[bad, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]])
        axis[bad] = np.cross(normal[bad], alt)
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    return normal, axis


def tilted_frames(
    normal: np.ndarray, axis: np.ndarray, tilts: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Each frame (normal, curvature axis; (S, 3) each) turned about its closing axis,
    normal x axis, by each of `tilts` (T,) rad: (T * S, 3) each, tilt-major. The hand's
    approach at rotation 0 then leans from -normal toward the curvature axis, as GPD 2 tries
    hand axes other than the curvature axis."""
    c, s = np.cos(tilts)[:, None, None], np.sin(tilts)[:, None, None]
    return (c * normal + s * axis).reshape(-1, 3), (c * axis - s * normal).reshape(-1, 3)


def orientation_angles(n: int) -> np.ndarray:
    """Hand rotations (rad) about the curvature axis, -90 deg to +90 deg inclusive.

    GPD drops +90 deg as a duplicate of -90 deg, but the two approach from opposite sides of
    the sample (from above and from below a side face), so both are kept.
    """
    return np.linspace(-np.pi / 2, np.pi / 2, n) if n > 1 else np.zeros(1)


# --- Neighbourhoods --------------------------------------------------------------------------


def crop_ball(points: np.ndarray, centre: np.ndarray, radius: float) -> np.ndarray:
    """The points (N, 3) within `radius` (m) of `centre`."""
    d = points - centre
    return points.take(np.flatnonzero(np.einsum("ij,ij->i", d, d) <= radius * radius), axis=0)


def voxel_thin(points: np.ndarray, voxel: float) -> np.ndarray:
    """One point (the first) per occupied voxel of edge `voxel` (m); all points if 0."""
    if voxel <= 0:
        return points
    return points[voxel_first(points, voxel)]


def copies_of(points: np.ndarray, target: np.ndarray, tree: cKDTree) -> np.ndarray:
    """Mask of the `points` (N, 3) that equal a point of `target` (M, 3; `tree` is its
    KD-tree) exactly. The scene usually holds the target's own points; the detector adds the
    target whole, so the scene's copies are dropped rather than tested twice."""
    inside = np.all((points >= target.min(axis=0)) & (points <= target.max(axis=0)), axis=1)
    cand = np.flatnonzero(inside)
    dist, _ = tree.query(points.take(cand, axis=0), distance_upper_bound=1e-12)
    mask = np.zeros(len(points), bool)
    mask[cand[dist == 0]] = True
    return mask


def frame_bases(
    samples: np.ndarray, normal: np.ndarray, axis: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Each sample's (h, u, v) axes as the rows of (S, 3, 3) and the sample's own coordinates
    along them (S, 3), m: see slab_pairs. float64."""
    e1 = -normal
    basis = np.stack([axis, e1, np.cross(axis, e1)], axis=1)
    return basis, np.einsum("sij,sj->si", basis, samples)


def in_regions(
    h: np.ndarray,
    u: np.ndarray,
    v: np.ndarray,
    regions: list[tuple[float, float, float]],
    grow: np.ndarray | None = None,
) -> np.ndarray:
    """Mask of the (h, u, v) coordinates (m) that lie in any of `regions` (see slab_pairs),
    each grown by `grow` (m, per point) if given."""
    ah = np.abs(h)
    keep = np.zeros(len(h), bool)
    if grow is None:
        rho2 = u * u + v * v
        for half_slab, radius, u_max in regions:
            keep |= (ah <= half_slab) & (rho2 <= radius * radius) & (u <= u_max)
        return keep
    ah -= grow
    rho = np.hypot(u, v) - grow
    u = u - grow
    for half_slab, radius, u_max in regions:
        keep |= (ah <= half_slab) & (rho <= radius) & (u <= u_max)
    return keep


def slab_pairs(
    points: np.ndarray,
    samples: np.ndarray,
    normal: np.ndarray,
    axis: np.ndarray,
    regions: list[tuple[float, float, float]],
    vectors: np.ndarray | None = None,
) -> tuple[np.ndarray, ...]:
    """Points near each sample, in the sample's frame: (sample index, point index, h, u, v),
    and if `vectors` ((N, 3), one per point, e.g. normals) are given, their u and v components
    too.

    h is along the curvature (hand) axis, u along -normal (into the surface) and v along
    axis x (-normal), all m (float32). Rotating the hand by theta about the axis gives approach
    a = cos(theta) u + sin(theta) v and closing c = sin(theta) u - cos(theta) v.

    A point is kept if it lies in any of `regions`, each (half slab along h, radius in the
    (u, v) plane, largest u), m: the hand axis does not change as the hand rotates about it,
    so these regions cover every orientation at once. Done as matrix products over blocks of
    points and samples rather than KD-tree ball queries, which return Python lists; the blocks
    are small (POINT_BLOCK x 3 SAMPLE_CHUNK) because large temporaries cost more in page faults
    than in arithmetic. The slab test comes first: it is cheap and drops most pairs. The
    vectors ride along in the same products, cheaper than gathering them per pair afterwards.
    """
    p = np.ascontiguousarray(points, np.float32)
    vec = None if vectors is None else np.ascontiguousarray(vectors, np.float32)
    basis, own = frame_bases(samples, normal, axis)
    half_slab = max(hs for hs, _, _ in regions)
    dtypes = [np.int64, np.int64] + [np.float32] * (3 if vec is None else 5)
    out: list[list[np.ndarray]] = [[np.zeros(0, dt)] for dt in dtypes]
    for lo in range(0, len(samples), SAMPLE_CHUNK):
        n = len(basis[lo : lo + SAMPLE_CHUNK])
        # Columns h of every sample, then u, then v: (3, 3n).
        b = basis[lo : lo + n].transpose(2, 1, 0).reshape(3, 3 * n).astype(np.float32)
        b_own = own[lo : lo + n].T.reshape(3 * n).astype(np.float32)
        for plo in range(0, len(p), POINT_BLOCK):
            coords = p[plo : plo + POINT_BLOCK] @ b
            coords -= b_own  # (m, 3n): h | u | v
            pid, sid = np.divmod(np.flatnonzero(np.abs(coords[:, :n]) <= half_slab), n)
            flat = coords.ravel()
            at = pid * (3 * n) + sid
            h, u, v = flat[at], flat[at + n], flat[at + 2 * n]
            keep = np.flatnonzero(in_regions(h, u, v, regions))
            at = at.take(keep)
            found = [sid.take(keep) + lo, pid.take(keep) + plo, h.take(keep), u.take(keep)]
            found.append(v.take(keep))
            if vec is not None:
                along = (vec[plo : plo + POINT_BLOCK] @ b).ravel()  # no offset: directions
                found += [along.take(at + n), along.take(at + 2 * n)]
            for acc, val in zip(out, found, strict=True):
                acc.append(val)
    return tuple(np.concatenate(acc) for acc in out)  # type: ignore[return-value]


def point_coords(
    xyz: np.ndarray, sid: np.ndarray, basis: np.ndarray, own: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(h, u, v) (m, float32) of points `xyz` ((3, E) float32, coordinates along the first
    axis) in the frames of their samples `sid` (E,), as slab_pairs computes them. basis, own:
    frame_bases' rows as (3 axes, 3, S) and (3 axes, S) float32: gathering and multiplying
    one component at a time is several times faster than batched 3 x 3 products."""
    return tuple(  # type: ignore[return-value]
        basis[i, 0].take(sid) * xyz[0]
        + basis[i, 1].take(sid) * xyz[1]
        + basis[i, 2].take(sid) * xyz[2]
        - own[i].take(sid)
        for i in range(3)
    )


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


# --- Hand geometry along the closing axis ----------------------------------------------------


class ClosingGrid:
    """Finger placements and the closing-axis bins used to find collisions (m).

    Placement k puts the hand centre at c_k = -W/2 + (k + 1/2) W/K on the closing axis, so the
    sample always lies between the open fingers; W = width_max, K = placements. Bins are W/K/4
    wide with edges on every placement's inner finger faces.
    """

    def __init__(self, s: GraspSettings) -> None:
        w, k = s.width_max, s.gpd_finger_placements
        self.step = w / k
        self.offsets = -w / 2 + (np.arange(k) + 0.5) * self.step
        self.bin = self.step / BINS_PER_PLACEMENT
        self.finger_thick = s.pad_thickness + s.finger_thickness
        self.n_finger_bins = math.ceil(self.finger_thick / self.bin - 1e-9)
        # Bin 0 starts n0 bins below the first left inner face (at step / 2).
        self.n0 = math.ceil((w + self.finger_thick) / self.bin - 1e-9) + 1
        self.lo = 0.5 * self.step - self.n0 * self.bin
        hi = w - 0.5 * self.step + self.finger_thick
        self.n_bins = math.ceil((hi - self.lo) / self.bin) + 1
        ks = np.arange(k)
        self.left = self.n0 + ks * BINS_PER_PLACEMENT  # first bin of each left finger
        self.right = self.n0 + (ks - k) * BINS_PER_PLACEMENT  # one past each right finger
        half_palm = s.palm_width / 2
        self.palm_lo = np.floor((self.offsets - half_palm - self.lo) / self.bin).astype(int)
        self.palm_hi = np.floor((self.offsets + half_palm - self.lo) / self.bin).astype(int) + 1
        self.palm_lo = np.clip(self.palm_lo, 0, self.n_bins)
        self.palm_hi = np.clip(self.palm_hi, 0, self.n_bins)


def orientation_blocks(
    select: np.ndarray | None, n_pairs: int, n_orient: int
) -> Iterator[tuple[int, np.ndarray]]:
    """(orientation, pair indices): for each orientation the pairs that `select` ((O, P)
    bool; all pairs if None) picks for it, ORIENTED_BLOCK at a time. Small blocks keep the
    temporaries in cache, and picking first skips the many (pair, orientation) combinations
    that cannot matter."""
    for o in range(n_orient):
        pairs = np.arange(n_pairs) if select is None else np.flatnonzero(select[o])
        for lo in range(0, len(pairs), ORIENTED_BLOCK):
            yield o, pairs[lo : lo + ORIENTED_BLOCK]


def by_orientation(
    frames: np.ndarray, sid: np.ndarray, pair_ok: np.ndarray | None = None
) -> np.ndarray:
    """(O, P) bool for orientation_blocks: the pairs of samples `sid` (P,) whose frame is set
    in `frames` ((S, O) bool), and (if given) whose `pair_ok` (P,) is set."""
    out = np.empty((frames.shape[1], len(sid)), bool)
    for o, column in enumerate(np.ascontiguousarray(frames.T)):
        np.take(column, sid, out=out[o])
        if pair_ok is not None:
            out[o] &= pair_ok
    return out


def rotated(
    u: np.ndarray, v: np.ndarray, theta: float, grid: ClosingGrid
) -> tuple[np.ndarray, np.ndarray]:
    """Approach depth a (m) and closing bin (float, floor taken; may lie outside the grid) of
    points with coordinates u, v (m, float32, see slab_pairs) once the hand is rotated by
    theta (rad), in float32."""
    ct, st = np.float32(math.cos(theta)), np.float32(math.sin(theta))
    return ct * u + st * v, np.floor((st * u - ct * v - grid.lo) / grid.bin)


def bin_minima(
    h: np.ndarray,
    u: np.ndarray,
    v: np.ndarray,
    sid: np.ndarray,
    n_samples: int,
    angles: np.ndarray,
    grid: ClosingGrid,
    s: GraspSettings,
    select: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Per closing bin and frame (sample * O + orientation), the least approach depth (m,
    from the sample) of the points in the fingers' band, and of those in the palm's band plus
    finger_length: (bins, S * O) float32 each, inf where empty.

    h, u, v: pairs' coordinates (see slab_pairs) with their sample indices `sid`; select:
    optional (O, P) mask of the (orientation, pair) combinations to use (default all). The
    fingers' band is the fingers' extent along the hand axis and approach depths from the
    starting hand's finger roots on; the palm's is wider along the hand axis and starts at the
    starting palm's rear.
    """
    F, t0, n_o, n_b = s.finger_length, s.gpd_init_bite, len(angles), grid.n_bins
    n_frames = n_samples * n_o
    finger_min = np.full(n_b * n_frames, np.inf, np.float32)
    palm_min = np.full(n_b * n_frames, np.inf, np.float32)
    bands = (
        (finger_min, max(s.finger_width, s.pad_width) / 2, t0 - F, 0.0),
        (palm_min, s.palm_depth / 2, t0 - F - s.palm_length, F),
    )
    for o, p in orientation_blocks(select, len(h), n_o):
        ah = np.abs(h.take(p))
        a, j = rotated(u.take(p), v.take(p), angles[o], grid)
        ok = (j >= 0) & (j < n_b)
        frame = sid.take(p) * n_o + o
        for out, half_h, a_min, add in bands:
            i = np.flatnonzero(ok & (ah <= half_h) & (a >= a_min))
            key = j.take(i).astype(np.intp) * n_frames + frame.take(i)
            np.minimum.at(out, key, a.take(i) + add if add else a.take(i))
    return finger_min.reshape(n_b, n_frames), palm_min.reshape(n_b, n_frames)


def placement_minima(finger_min: np.ndarray, palm_min: np.ndarray, grid: ClosingGrid) -> np.ndarray:
    """(F, K) float32: for each frame and finger placement, the least depth (m) at which a
    scene point stops the fingertips: the least of bin_minima over the bins of the placement's
    fingers (finger_min) and palm (palm_min), each (bins, F)."""
    nf = grid.n_finger_bins
    stop = np.empty((len(grid.offsets), finger_min.shape[1]), np.float32)
    for k in range(len(grid.offsets)):
        left = finger_min[grid.left[k] : grid.left[k] + nf].min(axis=0)
        right = finger_min[max(grid.right[k] - nf, 0) : grid.right[k]].min(axis=0)
        palm = palm_min[grid.palm_lo[k] : grid.palm_hi[k]].min(axis=0)
        stop[k] = np.minimum(np.minimum(left, right), palm)
    return np.ascontiguousarray(stop.T)


def tips_from_stops(stop: np.ndarray, s: GraspSettings) -> np.ndarray:
    """Fingertip depths (m) from placement_minima: gpd_clearance short of the first stop, and
    -inf where even the starting hand (tips at gpd_init_bite) collides."""
    tips = stop - s.gpd_clearance
    tips[tips < s.gpd_init_bite] = -np.inf
    return tips


def deepest_tips(
    h: np.ndarray,
    u: np.ndarray,
    v: np.ndarray,
    sid: np.ndarray,
    n_samples: int,
    angles: np.ndarray,
    grid: ClosingGrid,
    s: GraspSettings,
) -> np.ndarray:
    """(S, O, K) deepest fingertip position t (m along the approach, from the sample) that a
    hand swept in from behind reaches without touching a scene point; -inf if none.

    The hand starts with its fingertips gpd_init_bite past the sample. A point in a finger's
    band (closing and hand-axis extent) at approach depth a stops the tips at a; a point in the
    palm's band stops them at a + finger_length. Points already behind the starting hand are
    out of its way.

    This is the direct computation over every (sample, point) pair of slab_pairs(cloud, ...,
    hand_regions); the detector gets the same result faster from pruned_tips.
    """
    stop = placement_minima(*bin_minima(h, u, v, sid, n_samples, angles, grid, s), grid)
    return tips_from_stops(stop, s).reshape(n_samples, len(angles), len(grid.offsets))


# --- Collisions bounded by voxels ------------------------------------------------------------


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
    F, t0 = s.finger_length, s.gpd_init_bite
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
    finger_h, palm_h = max(s.finger_width, s.pad_width) / 2, s.palm_depth / 2
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
            (lh <= palm_h) & (most >= t0 - F - s.palm_length) & (least < worst_p(j_lo, j_hi, col))
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
        h.take(keep), u.take(keep), v.take(keep), sid.take(keep), n_s, angles, grid, s, select
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


def middle_placement(free: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each row of `free` (F, K) bool: whether any placement is free, and the middle of
    the longest run of free placements (GPD's choice: it centres the hand on the object)."""
    run = np.zeros(free.shape, np.int64)
    run[:, 0] = free[:, 0]
    for k in range(1, free.shape[1]):
        run[:, k] = (run[:, k - 1] + 1) * free[:, k]
    end = np.argmax(run, axis=1)
    length = run[np.arange(len(run)), end]
    return length > 0, end - (length - 1) // 2


# --- Closing region and antipodal test -------------------------------------------------------


def pad_pairs(
    target: np.ndarray,
    normals: np.ndarray,
    samples: np.ndarray,
    normal: np.ndarray,
    axis: np.ndarray,
    s: GraspSettings,
) -> tuple[np.ndarray, ...]:
    """Target points where some candidate's pads could be, for each sample: (sample index,
    point index, h, u, v, nu, nv), the points' coordinates (m) and their normals' components
    along the same axes (see slab_pairs). The pads' hand-axis extent, out to the farthest pad
    corner."""
    reach = math.hypot(s.width_max, s.finger_length)
    region = [(s.pad_width / 2, reach, np.inf)]
    return slab_pairs(target, samples, normal, axis, region, normals)


def antipodal_possible(
    u: np.ndarray,
    v: np.ndarray,
    nu: np.ndarray,
    nv: np.ndarray,
    sid: np.ndarray,
    n_samples: int,
    angles: np.ndarray,
    grid: ClosingGrid,
    s: GraspSettings,
) -> np.ndarray:
    """(S, O) bool: whether each frame could pass closing_region's antipodal test with any
    finger placement and fingertip depth, so that only these frames need the collision test.

    Inputs as for closing_region (from pad_pairs; `sid` the pairs' samples). Any
    candidate's pads lie in the union over placements and depths: closing coordinate within
    width_max / 2 of the farthest placement, depth from gpd_init_bite - pad_depth (the
    shallowest free tips) to finger_length (the sample itself stops the palm there, and the
    tips stay gpd_clearance short of that). Counting each pad's possible contacts there bounds
    closing_region's counts from above, so a frame that fails here fails there for any tips.
    """
    n_o = len(angles)
    c_max = s.width_max / 2 + float(np.max(np.abs(grid.offsets))) + ROUNDING
    a_lo, a_hi = s.gpd_init_bite - s.pad_depth - ROUNDING, s.finger_length
    cos_fric = math.cos(math.radians(s.gpd_friction_deg))
    ct = np.cos(angles).astype(np.float32)
    st = np.sin(angles).astype(np.float32)
    left, right = np.zeros(n_samples * n_o, np.int64), np.zeros(n_samples * n_o, np.int64)
    for lo in range(0, len(u), PAIR_BLOCK):
        sl = slice(lo, lo + PAIR_BLOCK)
        # (O, m) with the long axis inner. Normals first: being within the friction cone of
        # the closing axis is the rare part.
        ndot = st[:, None] * nu[sl] - ct[:, None] * nv[sl]  # as in closing_region
        i = np.flatnonzero(np.abs(ndot) >= cos_fric)
        o, col = np.divmod(i, len(ndot[0]))
        uu, vv, c_o, s_o = u[sl].take(col), v[sl].take(col), ct.take(o), st.take(o)
        a = c_o * uu + s_o * vv
        inside = np.flatnonzero((a >= a_lo) & (a <= a_hi) & (np.abs(s_o * uu - c_o * vv) < c_max))
        f = sid[sl].take(col.take(inside)) * n_o + o.take(inside)
        toward = ndot.ravel().take(i.take(inside)) > 0  # toward the left pad (+closing)
        left += np.bincount(f[toward], minlength=len(left))
        right += np.bincount(f[~toward], minlength=len(right))
    return ((left >= s.gpd_min_contacts) & (right >= s.gpd_min_contacts)).reshape(n_samples, n_o)


Contacts = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]
"""Antipodal contacts: each one's frame, pad (0 left, 1 right), depth along the approach (m)
and whether its point is guessed."""


def closing_region(
    h: np.ndarray,
    u: np.ndarray,
    v: np.ndarray,
    nu: np.ndarray,
    nv: np.ndarray,
    frame: np.ndarray,
    angles: np.ndarray,
    offset: np.ndarray,
    tip: np.ndarray,
    s: GraspSettings,
    guessed: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Width (m), the antipodal verdict and whether the pads meet the object about their
    middle, for each candidate frame.

    h, u, v: target points' coordinates (see slab_pairs) for pairs already inside the
    pads' hand-axis extent; nu, nv: their normals' u and v components; frame: each pair's
    sample index times O (the orientation is added here). offset, tip: per frame (S * O), the
    chosen hand centre on the closing axis and fingertip depth (m); NaN for no candidate.
    guessed: per pair, whether the point is guessed (`mirrored_back`) rather than seen.

    The pads touch the points between their inner faces within pad_depth of the tips. Their
    closing extent is the width. A pad's contacts are the points within gpd_contact_band of
    the extreme on its side; enough of them (gpd_min_contacts) must have normals within the
    friction cone about the closing axis, pointing at that pad (GPD's antipodal rule). A pad
    that touches only guessed points must touch them where the other pad touches seen ones
    (`guesses_face_seen`).

    Ours, beyond GPD: whether each pad meets the object along its face, about its middle
    (`Grasp.pads_centred`). A pad's tangent patch is its contacts whose normals lie within
    gpd_tangent_deg of the closing axis: where the object's face lies along the pad. Each
    pad must have one, and the middle of its extent along the hand axis must lie within
    gpd_patch_offset of the pad's. The friction cone alone passes a hand tilted 13 degrees
    over a can's top and shifted along it until the can's side lies along the pads only
    past their edges. The simulation's pads then meet it with a corner, whose contact
    normal turns to the pad's side and spins the can out (seed 1's soda can, stop 57). A
    verdict, not a rule: such a grasp is often the only one an object offers.
    """
    n_frames = len(offset)
    cmax = np.full(n_frames, -np.inf, np.float32)
    cmin = np.full(n_frames, np.inf, np.float32)
    count = np.zeros(n_frames, np.int64)
    half = s.width_max / 2
    parts = []
    for o, theta in enumerate(angles):
        ct, st = math.cos(theta), math.sin(theta)
        f = frame + o
        # Depth first: it is NaN-safe (no candidate: never inside) and drops most pairs.
        a = ct * u + st * v
        t = tip[f]
        i = np.flatnonzero((a <= t) & (a >= t - s.pad_depth))
        f = f[i]
        cc = st * u[i] - ct * v[i] - offset[f]
        inside = np.abs(cc) < half
        i, f, cc = i[inside], f[inside], cc[inside]
        ndot = st * nu[i] - ct * nv[i]  # normal . closing axis
        np.maximum.at(cmax, f, cc)
        np.minimum.at(cmin, f, cc)
        count += np.bincount(f, minlength=n_frames)
        parts.append((i, f, cc, ndot, a[i], h[i]))
    cos_fric = math.cos(math.radians(s.gpd_friction_deg))
    left = np.zeros(n_frames, np.int64)
    right = np.zeros(n_frames, np.int64)
    band = s.gpd_contact_band
    contacts: list[Contacts] = []
    cos_tangent = math.cos(math.radians(s.gpd_tangent_deg))
    # Each pad's tangent patch along the hand axis, [pad, frame]; 1 m is past any coordinate.
    patch_lo = np.full((2, n_frames), 1.0, np.float32)
    patch_hi = np.full((2, n_frames), -1.0, np.float32)
    for i, f, cc, ndot, depth, hh in parts:
        at_left, at_right = cc >= cmax[f] - band, cc <= cmin[f] + band
        on_left = at_left & (ndot >= cos_fric)
        on_right = at_right & (ndot <= -cos_fric)
        left += np.bincount(f[on_left], minlength=n_frames)
        right += np.bincount(f[on_right], minlength=n_frames)
        for pad, on in enumerate(
            (at_left & (ndot >= cos_tangent), at_right & (ndot <= -cos_tangent))
        ):
            np.minimum.at(patch_lo[pad], f[on], hh[on])
            np.maximum.at(patch_hi[pad], f[on], hh[on])
        if guessed is not None:
            at = np.flatnonzero(on_left | on_right)
            side = (~on_left).take(at).astype(np.int64)  # 0 left, 1 right
            contacts.append((f.take(at), side, depth.take(at), guessed.take(i.take(at))))
    width = cmax - cmin
    ok = (
        (count >= s.gpd_min_points)
        & (left >= s.gpd_min_contacts)
        & (right >= s.gpd_min_contacts)
        & (width > 0)
        & (width <= s.width_max)
    )
    if guessed is not None:
        ok &= guesses_face_seen(contacts, n_frames)
    centred = (patch_lo <= patch_hi).all(axis=0) & (
        np.abs(patch_lo + patch_hi) / 2 <= s.gpd_patch_offset
    ).all(axis=0)
    return width, ok, centred


def guesses_face_seen(contacts: list[Contacts], n_frames: int) -> np.ndarray:
    """(n_frames,) bool: False where a pad's antipodal contacts are all guessed points and
    their depths along the approach do not overlap those of the other pad's seen contacts.

    The back `mirrored_back` guesses is right for a symmetric object seen square on. Seen at
    a slant, or past an end, it lies beside the seen face rather than opposite it: a box
    held by its end edge had one pad on its seen face, 4-11 mm behind the tips, and the other
    only on guessed points, 4-10 mm in front of them (pick-place, seed 102, task 9). The
    pads closed on 1.25 cm of a 6.75 cm grasp, and the box turned out of them. A pad on seen
    points, and a guessed one at the same depth, are at least a real surface faced by its
    likely back.
    """
    lo = np.full((2, 2, n_frames), np.inf, np.float32)  # [pad, guessed, frame]
    hi = np.full((2, 2, n_frames), -np.inf, np.float32)
    for f, side, depth, g in contacts:
        at = (side, g.astype(np.int64), f)
        np.minimum.at(lo, at, depth)
        np.maximum.at(hi, at, depth)
    ok = np.ones(n_frames, bool)
    for pad, other in ((0, 1), (1, 0)):
        only_guessed = ~np.isfinite(lo[pad, 0])
        overlap = np.maximum(lo[pad, 1], lo[other, 0]) <= np.minimum(hi[pad, 1], hi[other, 0])
        ok &= ~only_guessed | overlap
    return ok


# --- The detector ----------------------------------------------------------------------------


def cleared_hand(s: GraspSettings) -> GraspSettings:
    """The hand the detector tests: `s`'s grown by side_clearance on every side but the
    fingertips and the palm's front (gpd_clearance keeps those off the first contact). Its
    fingers' inner faces close in by the clearance, so a grasp's width is at most the stroke
    less twice the clearance; its outer faces, the fingers' edges along the hand axis and
    the palm's sides move out by it. The pads (the contacts) keep their size."""
    m = s.side_clearance
    if m == 0:
        return s
    return s.model_copy(
        update={
            "width_max": s.width_max - 2 * m,
            "finger_thickness": s.finger_thickness + 2 * m,
            "finger_width": max(s.finger_width, s.pad_width) + 2 * m,
            "palm_width": s.palm_width + 2 * m,
            "palm_depth": s.palm_depth + 2 * m,
        }
    )


def hand_regions(s: GraspSettings) -> list[tuple[float, float, float]]:
    """Where scene points can touch a candidate hand, around its sample, as slab_pairs
    regions (half slab along the hand axis, radius in the rotation plane, largest u), m.

    Fingers: closing up to the outer face at the edge placement, approach from the roots of
    the starting hand to the deepest tips (finger_length: the sample itself stops the palm
    there). Palm: closing up to its side at the edge placement, approach back to its rear at
    the start; it stays on the sample's outer side (u below its half-width plus offset).
    """
    grid_half = s.width_max / 2 - s.width_max / s.gpd_finger_placements / 2  # largest |c_k|
    c_finger = grid_half + s.width_max / 2 + s.pad_thickness + s.finger_thickness
    a_finger = max(s.finger_length, s.finger_length - s.gpd_init_bite)
    c_palm = grid_half + s.palm_width / 2
    a_palm = s.finger_length + s.palm_length - s.gpd_init_bite
    finger_slab = max(s.finger_width, s.pad_width) / 2
    return [
        (finger_slab, math.hypot(c_finger, a_finger), np.inf),
        (s.palm_depth / 2, math.hypot(c_palm, a_palm), c_palm),
    ]


def collision_cloud(
    scene: np.ndarray,
    centre: np.ndarray,
    target: np.ndarray,
    tree: cKDTree,
    regions: list[tuple[float, float, float]],
    s: GraspSettings,
) -> np.ndarray:
    """The points a hand on `target` could touch, relative to `centre` (m): the scene (N, 3,
    in `base`) within reach, thinned per gpd_collision_voxel, and the whole target ((M, 3),
    relative to `centre`; `tree` its KD-tree)."""
    reach = max(r for _, r, _ in regions) + max(hs for hs, _, _ in regions)
    size = float(np.max(np.linalg.norm(target, axis=1)))
    # Crop in float32 (the scene is large), a little generously: beyond `reach` of every
    # sample a point touches no hand, whatever the rounding.
    scene = np.asarray(scene, np.result_type(scene, np.float32)).reshape(-1, 3)
    cloud = crop_ball(scene, centre.astype(scene.dtype), size + reach + 1e-4)
    cloud = cloud.astype(np.float64) - centre
    # Thin the surroundings for speed; the target keeps every point (it blocks the palm even
    # if `scene` lacks it, and its points decide the fingers' inner faces). The scene's own
    # copies of target points would only be tested twice.
    cloud = voxel_thin(cloud, s.gpd_collision_voxel)
    return np.vstack([cloud[~copies_of(cloud, target, tree)], target])


def detect_grasps(
    target: np.ndarray,
    target_normals: np.ndarray,
    scene: np.ndarray,
    settings: GraspSettings | None = None,
    rng: np.random.Generator | None = None,
    timings: dict[str, float] | None = None,
    tilts: tuple[float, ...] = (0.0,),
    guessed: np.ndarray | None = None,
) -> list[Grasp]:
    """Grasp candidates on `target` that keep side_clearance from `scene` (cleared_hand).

    target: (M, 3) the segmented object's points in `base` (m); target_normals: (M, 3) their
    unit normals, pointing outward (toward the sensors). scene: (N, 3) the full cloud in
    `base`, table included; the target's own points are added to it for collisions. rng seeds
    the sampling: the same seed gives the same grasps. Returns grasps with pose (TCP in
    `base`; columns hand axis, closing axis, approach) and width (m), in sample order, then
    the hands moved onto their patches (`Hands.recentred`). timings, if given, receives the
    seconds spent in each stage (bench/grasp_detect_speed.py; the second pass adds to the
    first's stages). tilts (rad): each sample's frame is tried turned about its closing axis
    by each of these (`tilted_frames`); the default, no tilt, is GPD's. guessed: (M,) bool,
    the target points that were guessed (`mirrored_back`) rather than seen; see
    `guesses_face_seen`.
    """
    t_start = time.perf_counter()
    clock = [t_start]

    def lap(stage: str) -> None:
        now = time.perf_counter()
        if timings is not None:
            timings[stage] = timings.get(stage, 0.0) + now - clock[0]
        clock[0] = now

    s = cleared_hand(settings or get_settings().grasp)
    rng = rng if rng is not None else np.random.default_rng(0)
    target = np.asarray(target, np.float64).reshape(-1, 3)
    if len(target) < 3:
        return []
    normals = np.asarray(target_normals, np.float64).reshape(-1, 3)
    # Work relative to the target's centre: float32 keeps sub-micron precision there.
    centre = 0.5 * (target.min(axis=0) + target.max(axis=0))
    tgt = target - centre
    tree = cKDTree(tgt)

    idx = sample_indices(len(tgt), s.gpd_samples, rng)
    samples = tgt[idx]
    normal, axis = local_frames(tgt, normals, idx, s, tree)
    if tilts != (0.0,):
        normal, axis = tilted_frames(normal, axis, np.asarray(tilts, np.float64))
        samples = np.tile(samples, (len(tilts), 1))
    lap("frames")
    hands = Hands(tgt, normals, scene, centre, tree, s, guessed, lap)
    found = hands.grasps(samples, normal, axis)
    passes = (found, hands.recentred(found))
    poses = np.vstack([f.poses for f in passes])
    poses[:, :3, 3] += centre
    if timings is not None:
        timings["total"] = time.perf_counter() - t_start
    return [
        Grasp(pose=T, width=float(w), pads_centred=bool(c))
        for T, w, c in zip(
            poses,
            np.concatenate([f.width for f in passes]),
            np.concatenate([f.centred for f in passes]),
            strict=True,
        )
    ]


@dataclass(frozen=True)
class Found:
    """The passing candidates of some frames: (G,) each, or (G, 4, 4) poses relative to the
    target's centre. sample, orientation: the frame's indices into `samples` and `angles`;
    offset, tip: its hand centre on the closing axis and fingertip depth (m), as
    closing_region has them."""

    samples: np.ndarray
    normal: np.ndarray
    axis: np.ndarray
    angles: np.ndarray
    sample: np.ndarray
    orientation: np.ndarray
    offset: np.ndarray
    tip: np.ndarray
    width: np.ndarray
    centred: np.ndarray
    poses: np.ndarray

    def __len__(self) -> int:
        return len(self.sample)

    def subset(self, keep: np.ndarray) -> Found:
        """The candidates `keep` (indices) of these."""
        per = ("sample", "orientation", "offset", "tip", "width", "centred", "poses")
        return replace(self, **{k: getattr(self, k)[keep] for k in per})


class Hands:
    """The detector's passes over frames of one target: its points relative to their centre
    (`tgt`, with their normals and KD-tree), the collision cloud around them (built once, when
    a frame first needs it) and the cleared hand `s`."""

    def __init__(
        self,
        tgt: np.ndarray,
        normals: np.ndarray,
        scene: np.ndarray,
        centre: np.ndarray,
        tree: cKDTree,
        s: GraspSettings,
        guessed: np.ndarray | None,
        lap: Callable[[str], None],
    ) -> None:
        self.tgt, self.normals, self.tree = tgt, normals, tree
        self.scene, self.centre = scene, centre
        self.s, self.guessed, self.lap = s, guessed, lap
        self.angles = orientation_angles(s.gpd_orientations)
        self.grid = ClosingGrid(s)
        self.regions = hand_regions(s)
        self._cloud: np.ndarray | None = None

    def cloud(self) -> np.ndarray:
        """The collision cloud (`collision_cloud`), relative to the target's centre."""
        if self._cloud is None:
            self._cloud = collision_cloud(
                self.scene, self.centre, self.tgt, self.tree, self.regions, self.s
            )
            self.lap("crop")
        return self._cloud

    def grasps(
        self,
        samples: np.ndarray,
        normal: np.ndarray,
        axis: np.ndarray,
        only: np.ndarray | None = None,
    ) -> Found:
        """The passing candidates of every orientation of the frames at `samples` ((S, 3),
        relative to the target's centre) with those normals and curvature axes; with `only`
        ((S,) orientation indices), of that one orientation of each."""
        s, angles, grid, lap = self.s, self.angles, self.grid, self.lap
        # The pads' contents: target points where the pads could be. Most frames cannot pass
        # the antipodal test whatever the hand's depth and offset: they need no collision
        # test.
        tsid, tpid, th, tu, tv, nu, nv = pad_pairs(self.tgt, self.normals, samples, normal, axis, s)
        possible = antipodal_possible(tu, tv, nu, nv, tsid, len(samples), angles, grid, s)
        if only is not None:
            possible &= np.arange(len(angles)) == np.asarray(only)[:, None]
        live = np.flatnonzero(possible.any(axis=1))
        lap("pad_pairs")

        # Collisions and depth, for those frames: scene points where the hand could be.
        tips = np.full((len(samples), len(angles), len(grid.offsets)), -np.inf, np.float32)
        if len(live):
            pairs = CoarsePairs(self.cloud(), samples[live], normal[live], axis[live], self.regions)
            lap("collision_pairs")
            tips[live] = pruned_tips(
                pairs,
                samples[live],
                normal[live],
                axis[live],
                angles,
                grid,
                s,
                self.regions,
                possible[live],
            )
        tips = tips.reshape(len(samples) * len(angles), -1)
        has, k = middle_placement(np.isfinite(tips))
        offset = np.where(has, grid.offsets[k], np.nan).astype(np.float32)
        tip = np.where(has, tips[np.arange(len(tips)), k], np.nan).astype(np.float32)
        lap("deepest_tips")

        keep = np.flatnonzero(has.reshape(len(samples), len(angles)).any(axis=1).take(tsid))
        th, tu, tv, nu, nv, tsid, tpid = (x.take(keep) for x in (th, tu, tv, nu, nv, tsid, tpid))
        pair_guessed = None if self.guessed is None else np.asarray(self.guessed, bool).take(tpid)
        width, ok, centred = closing_region(
            th, tu, tv, nu, nv, tsid * len(angles), angles, offset, tip, s, pair_guessed
        )
        lap("closing_region")
        good = np.flatnonzero(ok & has)
        sample, orientation = np.divmod(good, len(angles))
        poses = grasp_poses(samples, normal, axis, angles, good, offset[good], tip[good], s)
        return Found(
            samples,
            normal,
            axis,
            angles,
            sample,
            orientation,
            offset[good],
            tip[good],
            width[good],
            centred[good],
            poses,
        )

    def recentred(self, found: Found) -> Found:
        """The hands of `found` that are not centred, moved onto their patches
        (`patch_moves`) and tested again from scratch: those that pass and are centred now.
        Ours, beyond GPD (see patch_moves)."""
        off = np.flatnonzero(~found.centred)
        turn, shift = patch_moves(self, found.subset(off))
        moved = np.flatnonzero(np.isfinite(shift))
        self.lap("recentre")
        if not len(moved):
            return found.subset(moved)
        i = found.sample[off[moved]]
        normal, axis = found.normal[i], found.axis[i]
        c, s = np.cos(turn[moved])[:, None], np.sin(turn[moved])[:, None]
        again = self.grasps(
            found.samples[i] + shift[moved, None] * axis,
            c * normal + s * np.cross(axis, normal),  # turns the approach by `turn`
            axis,
            only=found.orientation[off[moved]],
        )
        return again.subset(np.flatnonzero(again.centred))


def patch_moves(hands: Hands, found: Found) -> tuple[np.ndarray, np.ndarray]:
    """How to move each of `found`'s hands so that its pads meet the object along their
    faces, about their middle (closing_region's tangent patches): a turn (rad) about the hand
    axis, through the sample, that brings the closing axis onto the normals where the pads
    touch, then a shift (m) along the hand axis that brings the patches' middle onto the
    pads' middle. (G,) each. Where there is no such move, the shift is NaN (and the turn 0):
    either pad has no patch within gpd_recentre of its edges, or the move is below MIN_TURN
    and MIN_SHIFT.

    The contacts are found as closing_region finds them, at the hand's depth and placement,
    but over a slab gpd_recentre wider on each side of the pads, and against the extremes of
    that slab: off its middle, a pad meets a can's side where it is narrower than at its
    axis, and the can is widest where the pad is not. The turn is the median over each pad's
    contacts of the angle from the closing axis to their normals (to minus theirs, for the
    right pad), in the plane the hand turns in, averaged over the pads.

    The turned hand keeps the placement and fingertip depth found for the first; the second
    pass (`Hands.recentred`) finds its own.

    Ours, beyond GPD. Its eight orientations step 26 degrees about the curvature axis and do
    not include the normal itself, so no hand comes straight down onto the top of a can: the
    nearest lean 13 degrees and close across it at that slant. And 500 samples seldom put a
    hand right over an upright mug's axis: a mug held 11 mm off it slid along the pads onto
    its handle (pick-place seed 200, task 8), and one held at a 12 degree slant turned in
    them (seed 402, task 11).
    """
    s = hands.s
    turn, shift = np.full(len(found), np.nan), np.full(len(found), np.nan)
    if s.gpd_recentre <= 0 or not len(found):
        return turn, shift
    i = found.sample
    region = [(s.pad_width / 2 + s.gpd_recentre, math.hypot(s.width_max, s.finger_length), np.inf)]
    f, _, h, u, v, nu, nv = slab_pairs(
        hands.tgt, found.samples[i], found.normal[i], found.axis[i], region, hands.normals
    )
    band = s.gpd_contact_band
    theta = found.angles[found.orientation]

    def contacts(theta: np.ndarray) -> tuple[np.ndarray, ...]:
        """Per pad, the pairs at its extreme within the hand turned to `theta` (G,) rad,
        and their normals' components along its closing axis and approach."""
        ct, st = np.cos(theta).astype(np.float32).take(f), np.sin(theta).astype(np.float32).take(f)
        a = ct * u + st * v
        cc = st * u - ct * v - found.offset.take(f)
        tip = found.tip.take(f)
        inside = (a <= tip) & (a >= tip - s.pad_depth) & (np.abs(cc) < s.width_max / 2)
        cmax = np.full(len(found), -np.inf, np.float32)
        cmin = np.full(len(found), np.inf, np.float32)
        np.maximum.at(cmax, f[inside], cc[inside])
        np.minimum.at(cmin, f[inside], cc[inside])
        left = inside & (cc >= cmax.take(f) - band)
        right = inside & (cc <= cmin.take(f) + band)
        return left, right, st * nu - ct * nv, ct * nu + st * nv

    def medians(on: np.ndarray, x: np.ndarray) -> np.ndarray:
        """(G,) the median of `x` over each frame's pairs `on`; NaN for a frame with none."""
        out = np.full(len(found), np.nan)
        fs = f[on]
        order = np.argsort(fs, kind="stable")
        fs, xs = fs[order], x[on][order]
        starts = np.flatnonzero(np.r_[True, fs[1:] != fs[:-1]]) if len(fs) else fs
        for k, lo in enumerate(starts):
            hi = starts[k + 1] if k + 1 < len(starts) else len(fs)
            out[fs[lo]] = np.median(xs[lo:hi])
        return out

    left, right, n_c, n_a = contacts(theta)
    turn = (medians(left, np.arctan2(n_a, n_c)) + medians(right, np.arctan2(-n_a, -n_c))) / 2
    turned = theta + np.nan_to_num(turn)
    left, right, n_c, _ = contacts(turned)
    cos_tangent = math.cos(math.radians(s.gpd_tangent_deg))
    middles = []
    for on in (left & (n_c >= cos_tangent), right & (n_c <= -cos_tangent)):
        # As closing_region's patch extents; inf - inf: NaN where the pad has no patch.
        lo = np.full(len(found), np.inf, np.float32)
        hi = np.full(len(found), -np.inf, np.float32)
        np.minimum.at(lo, f[on], h[on])
        np.maximum.at(hi, f[on], h[on])
        with np.errstate(invalid="ignore"):
            middles.append(((lo + hi) / 2).astype(np.float64))
    shift = (middles[0] + middles[1]) / 2
    still = ~(np.abs(turn) >= MIN_TURN) & ~(np.abs(shift) >= MIN_SHIFT)
    none = np.isnan(shift) | still
    turn[none], shift[none] = np.nan, np.nan
    return np.nan_to_num(turn), shift


def grasp_poses(
    samples: np.ndarray,
    normal: np.ndarray,
    axis: np.ndarray,
    angles: np.ndarray,
    frames: np.ndarray,
    offset: np.ndarray,
    tip: np.ndarray,
    s: GraspSettings,
) -> np.ndarray:
    """(G, 4, 4) TCP poses of candidate `frames` (sample * O + orientation), with the hand
    `offset` (m) along the closing axis and fingertips `tip` (m) along the approach from the
    sample; the TCP is pad_depth / 2 behind the tips, between the pads' centres."""
    i, o = np.divmod(frames, len(angles))
    theta = angles[o][:, None]
    x = axis[i]
    e1 = -normal[i]
    e2 = np.cross(x, e1)
    approach = np.cos(theta) * e1 + np.sin(theta) * e2
    closing = np.cross(approach, x)
    poses = np.tile(np.eye(4), (len(frames), 1, 1))
    poses[:, :3, 0], poses[:, :3, 1], poses[:, :3, 2] = x, closing, approach
    poses[:, :3, 3] = (
        samples[i]
        + offset[:, None].astype(np.float64) * closing
        + (tip[:, None].astype(np.float64) - s.pad_depth / 2) * approach
    )
    return poses
