"""GPD-style grasp candidates (paper 004 section 6.2; ten Pas et al., "Grasp Pose Detection
in Point Clouds", 2017), geometric part only: sample the target, build a local frame at each
sample, rotate and slide the hand there, push it in until just before contact, and keep the
collision-free hands whose pads close antipodally on the object. GPD's learned classifier is
not reproduced; the antipodal test (GPD's own labelling rule) stands in for it.

Frames: everything is in `base` (x forward, y left, z up), metres. A hand frame has the hand
axis (x), the closing axis (y, between the fingers) and the approach axis (z, palm toward the
object); a point's hand coordinates are (h, c, a) along those axes. The TCP lies midway between
the pads' centres, pad_depth / 2 behind the fingertips.

Hand model (GraspSettings, mirroring robot/dims): two fingers, each a box from the inner pad
face (at +-width_max / 2 from the hand centre when open) outward by pad + plate thickness,
finger_length deep along the approach and finger_width along the hand axis; behind the finger
roots a palm box palm_width x palm_depth x palm_length.

Speed: every (sample, orientation) pair is one "frame". Scene points are binned by their
closing coordinate per frame (np.minimum.at), so each finger placement's deepest collision-free
depth is a min over a few bins rather than a pass over the points. Bin edges are placed on the
fingers' inner faces, so the faces that touch the object are exact; the outer faces and the
palm's sides are conservative by less than one bin (width_max / placements / 4, ~2 mm).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import cKDTree

from laserpick.pipeline.types import Grasp
from laserpick.settings import GraspSettings, get_settings

BINS_PER_PLACEMENT = 4  #: closing-axis bins per finger-placement step (collision resolution)
SAMPLE_CHUNK = 100  #: samples per block of the point/sample distance matrix (memory bound)


# --- Sampling and local frames -------------------------------------------------------------


def sample_indices(n_points: int, n_samples: int, rng: np.random.Generator) -> np.ndarray:
    """Indices of up to `n_samples` distinct target points, drawn uniformly (sorted)."""
    if n_points <= n_samples:
        return np.arange(n_points)
    return np.sort(rng.choice(n_points, size=n_samples, replace=False))


def local_frames(
    target: np.ndarray, normals: np.ndarray, idx: np.ndarray, s: GraspSettings
) -> tuple[np.ndarray, np.ndarray]:
    """Surface normal and curvature axis (each (S, 3), unit) at the target points `idx`.

    The normal is the mean of the neighbours' normals within gpd_nn_radius (kept pointing the
    way they were given: outward, toward the sensors). The curvature axis is the direction of
    least normal variation: the eigenvector of sum(n n^T) with the smallest eigenvalue (GPD),
    made orthogonal to the normal.
    """
    tree = cKDTree(target)
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
    return points[np.einsum("ij,ij->i", d, d) <= radius * radius]


def voxel_thin(points: np.ndarray, voxel: float) -> np.ndarray:
    """One point (the first) per occupied voxel of edge `voxel` (m); all points if 0."""
    if voxel <= 0 or len(points) == 0:
        return points
    keys = np.floor(points / voxel).astype(np.int64)
    _, first = np.unique(keys, axis=0, return_index=True)
    return points[np.sort(first)]


def slab_pairs(
    points: np.ndarray,
    samples: np.ndarray,
    normal: np.ndarray,
    axis: np.ndarray,
    regions: list[tuple[float, float, float]],
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Points near each sample, in the sample's frame: (sample index, point index, h, u, v).

    h is along the curvature (hand) axis, u along -normal (into the surface) and v along
    axis x (-normal), all m. Rotating the hand by theta about the axis gives approach
    a = cos(theta) u + sin(theta) v and closing c = sin(theta) u - cos(theta) v.

    A point is kept if it lies in any of `regions`, each (half slab along h, radius in the
    (u, v) plane, largest u), m: the hand axis does not change as the hand rotates about it,
    so these regions cover every orientation at once. Done as blocked matrix products rather
    than KD-tree ball queries, which return Python lists.
    """
    p = points.astype(np.float32)
    e1 = -normal
    e2 = np.cross(axis, e1)
    out: list[list[np.ndarray]] = [[], [], [], [], []]
    for lo in range(0, len(samples), SAMPLE_CHUNK):
        sl = slice(lo, lo + SAMPLE_CHUNK)
        basis = np.concatenate([axis[sl], e1[sl], e2[sl]])  # (3n, 3)
        n = len(basis) // 3
        own = np.einsum("ij,ij->i", basis, np.tile(samples[sl], (3, 1)))
        coords = p @ basis.T.astype(np.float32) - own.astype(np.float32)  # (N, 3n): h | u | v
        h, u, v = coords[:, :n], coords[:, n : 2 * n], coords[:, 2 * n :]
        rho2 = u * u + v * v
        ah = np.abs(h)
        keep = np.zeros(h.shape, bool)
        for half_slab, radius, u_max in regions:
            keep |= (ah <= half_slab) & (rho2 <= radius * radius) & (u <= u_max)
        pid, sid = np.nonzero(keep)
        for acc, val in zip(out, (sid + lo, pid, h[keep], u[keep], v[keep]), strict=True):
            acc.append(val)
    return tuple(np.concatenate(acc) for acc in out)  # type: ignore[return-value]


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

    def index(self, c: np.ndarray) -> np.ndarray:
        """Bin of each closing coordinate; -1 outside the grid."""
        j = np.floor((c - self.lo) / self.bin).astype(np.int64)
        j[(j < 0) | (j >= self.n_bins)] = -1
        return j


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
    """
    F, t0 = s.finger_length, s.gpd_init_bite
    n_frames = n_samples * len(angles)
    finger_min = np.full(n_frames * grid.n_bins, np.inf, np.float32)
    palm_min = np.full(n_frames * grid.n_bins, np.inf, np.float32)
    in_finger_h = np.abs(h) <= max(s.finger_width, s.pad_width) / 2
    in_palm_h = np.abs(h) <= s.palm_depth / 2
    for o, theta in enumerate(angles):
        ct, st = math.cos(theta), math.sin(theta)
        a = ct * u + st * v
        j = grid.index(st * u - ct * v)
        key = (sid * len(angles) + o) * grid.n_bins + j
        fm = in_finger_h & (a >= t0 - F) & (j >= 0)
        np.minimum.at(finger_min, key[fm], a[fm])
        pm = in_palm_h & (a >= t0 - F - s.palm_length) & (j >= 0)
        np.minimum.at(palm_min, key[pm], a[pm] + F)
    finger_min = finger_min.reshape(n_frames, grid.n_bins)
    palm_min = palm_min.reshape(n_frames, grid.n_bins)
    nf = grid.n_finger_bins
    tips = np.empty((n_frames, len(grid.offsets)), np.float32)
    for k in range(len(grid.offsets)):
        left = finger_min[:, grid.left[k] : grid.left[k] + nf].min(axis=1)
        right = finger_min[:, max(grid.right[k] - nf, 0) : grid.right[k]].min(axis=1)
        palm = palm_min[:, grid.palm_lo[k] : grid.palm_hi[k]].min(axis=1)
        tips[:, k] = np.minimum(np.minimum(left, right), palm) - s.gpd_clearance
    tips[tips < t0] = -np.inf  # even the starting hand collides
    return tips.reshape(n_samples, len(angles), len(grid.offsets))


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


def closing_region(
    u: np.ndarray,
    v: np.ndarray,
    nu: np.ndarray,
    nv: np.ndarray,
    frame: np.ndarray,
    angles: np.ndarray,
    offset: np.ndarray,
    tip: np.ndarray,
    s: GraspSettings,
) -> tuple[np.ndarray, np.ndarray]:
    """Width (m) and the antipodal verdict of each candidate frame.

    u, v: target points' coordinates (see slab_pairs) for pairs already inside the
    pads' hand-axis extent; nu, nv: their normals' u and v components; frame: each pair's
    sample index times O (the orientation is added here). offset, tip: per frame (S * O), the
    chosen hand centre on the closing axis and fingertip depth (m); NaN for no candidate.

    The pads touch the points between their inner faces within pad_depth of the tips. Their
    closing extent is the width. A pad's contacts are the points within gpd_contact_band of
    the extreme on its side; enough of them (gpd_min_contacts) must have normals within the
    friction cone about the closing axis, pointing at that pad (GPD's antipodal rule).
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
        cc = st * u - ct * v - offset[f]
        a = ct * u + st * v
        inside = (np.abs(cc) < half) & (a <= tip[f]) & (a >= tip[f] - s.pad_depth)
        f, cc = f[inside], cc[inside]
        ndot = st * nu[inside] - ct * nv[inside]  # normal . closing axis
        np.maximum.at(cmax, f, cc)
        np.minimum.at(cmin, f, cc)
        count += np.bincount(f, minlength=n_frames)
        parts.append((f, cc, ndot))
    cos_fric = math.cos(math.radians(s.gpd_friction_deg))
    left = np.zeros(n_frames, np.int64)
    right = np.zeros(n_frames, np.int64)
    band = s.gpd_contact_band
    for f, cc, ndot in parts:
        left += np.bincount(f[(cc >= cmax[f] - band) & (ndot >= cos_fric)], minlength=n_frames)
        right += np.bincount(f[(cc <= cmin[f] + band) & (ndot <= -cos_fric)], minlength=n_frames)
    width = cmax - cmin
    ok = (
        (count >= s.gpd_min_points)
        & (left >= s.gpd_min_contacts)
        & (right >= s.gpd_min_contacts)
        & (width > 0)
        & (width <= s.width_max)
    )
    return width, ok


# --- The detector ----------------------------------------------------------------------------


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


def detect_grasps(
    target: np.ndarray,
    target_normals: np.ndarray,
    scene: np.ndarray,
    settings: GraspSettings | None = None,
    rng: np.random.Generator | None = None,
) -> list[Grasp]:
    """Grasp candidates on `target` that do not collide with `scene`.

    target: (M, 3) the segmented object's points in `base` (m); target_normals: (M, 3) their
    unit normals, pointing outward (toward the sensors). scene: (N, 3) the full cloud in
    `base`, table included; the target's own points are added to it for collisions. rng seeds
    the sampling: the same seed gives the same grasps. Returns grasps with pose (TCP in
    `base`; columns hand axis, closing axis, approach) and width (m), in sample order.
    """
    s = settings or get_settings().grasp
    rng = rng if rng is not None else np.random.default_rng(0)
    target = np.asarray(target, np.float64).reshape(-1, 3)
    if len(target) < 3:
        return []
    normals = np.asarray(target_normals, np.float64).reshape(-1, 3)
    # Work relative to the target's centre: float32 keeps sub-micron precision there.
    centre = 0.5 * (target.min(axis=0) + target.max(axis=0))
    tgt = target - centre
    regions = hand_regions(s)
    reach = max(r for _, r, _ in regions) + max(hs for hs, _, _ in regions)
    size = float(np.max(np.linalg.norm(tgt, axis=1)))
    cloud = crop_ball(
        np.asarray(scene, np.float64).reshape(-1, 3) - centre, np.zeros(3), size + reach
    )
    # Thin the surroundings for speed; the target keeps every point (it blocks the palm even
    # if `scene` lacks it, and its points decide the fingers' inner faces).
    cloud = np.vstack([voxel_thin(cloud, s.gpd_collision_voxel), tgt])

    idx = sample_indices(len(tgt), s.gpd_samples, rng)
    samples = tgt[idx]
    normal, axis = local_frames(tgt, normals, idx, s)
    angles = orientation_angles(s.gpd_orientations)
    grid = ClosingGrid(s)

    # Collisions and depth: scene points where the hand could be.
    sid, _, h, u, v = slab_pairs(cloud, samples, normal, axis, regions)
    tips = deepest_tips(h, u, v, sid, len(idx), angles, grid, s)
    tips = tips.reshape(len(idx) * len(angles), -1)
    has, k = middle_placement(np.isfinite(tips))
    offset = np.where(has, grid.offsets[k], np.nan).astype(np.float32)
    tip = np.where(has, tips[np.arange(len(tips)), k], np.nan).astype(np.float32)

    # The pads' contents: target points where the pads could be.
    pad_reach = math.hypot(s.width_max, s.finger_length)
    tsid, tpid, _, tu, tv = slab_pairs(
        tgt, samples, normal, axis, [(s.pad_width / 2, pad_reach, np.inf)]
    )
    n = normals[tpid].astype(np.float32)
    nu = -np.einsum("ij,ij->i", n, normal[tsid].astype(np.float32))
    nv = np.einsum("ij,ij->i", n, np.cross(axis, -normal)[tsid].astype(np.float32))
    width, ok = closing_region(tu, tv, nu, nv, tsid * len(angles), angles, offset, tip, s)
    good = np.flatnonzero(ok & has)
    poses = grasp_poses(samples, normal, axis, angles, good, offset[good], tip[good], s)
    poses[:, :3, 3] += centre
    return [Grasp(pose=T, width=float(w)) for T, w in zip(poses, width[good], strict=True)]


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
