"""Scene and target points near GPD's samples, in each sample's frame: cropping and thinning
the cloud, the regions a hand can reach around a sample, and the blocked matrix products that
give every (sample, point) pair's coordinates (h, u, v), and the cloud grouped by voxel
(`VoxelGroups`). Frames: `base` axes, metres.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from laserpick.pipeline.cloud import voxel_first
from laserpick.settings import GraspSettings

SAMPLE_CHUNK = 100  #: samples per block of slab_pairs' coordinate matrix
POINT_BLOCK = 1024  #: points per block of slab_pairs' coordinate matrix (cache-sized)
ROUNDING = 1e-6  #: m added to distance bounds, well above float32 rounding near the target


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
