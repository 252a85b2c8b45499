"""Fusion: five depth frames into one point cloud in `base`, with normals and provenance.

Normals come from the depth image itself (the cross product of neighbouring pixels' 3D
offsets), which costs a few array operations instead of a KD-tree search per point, and is
oriented toward the camera by construction: the sensor sees only surfaces that face it.

Speed (about 4x the straightforward version): every test that needs only the depth image
(validity, depth jumps) runs on the (h, w) depth grid; the pixels that pass are gathered once,
cropped to the workspace, and only the survivors get their neighbours' 3D offsets and a
normal, computed component by component in float32 on (N,) arrays. No (h, w, 3) image, no
np.cross or np.linalg.norm, no float64 temporaries.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache

import numpy as np

from laserpick.settings import PerceptionSettings, get_settings
from laserpick.types import DepthFrame, FusedCloud

#: A neighbour whose depth differs by more than this fraction of the pixel's depth lies across
#: a depth edge, where the finite-difference normal means nothing.
EDGE_JUMP = 0.05


def _frame_points(
    frame: DepthFrame, stride: int, lo: np.ndarray, hi: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One frame's points and unit normals (toward the camera) in `base`, float32 (N, 3), and
    their flat pixel indices (v * W + u) in the full image, for pixels inside the box lo..hi.

    Works on the interior of the strided depth grid, one 2D array per component; neighbours
    are shifted views of the same grid, so nothing is gathered until the final compaction.
    """
    H, W = frame.depth.shape
    z = np.ascontiguousarray(frame.depth[::stride, ::stride], dtype=np.float32)
    w = z.shape[1]
    a, b = _rays(frame.K, W, H, stride)
    R = frame.T_base_cam[:3, :3].astype(np.float32)
    t = frame.T_base_cam[:3, 3].astype(np.float32)

    c = z[1:-1, 1:-1]
    zl, zr = z[1:-1, :-2], z[1:-1, 2:]
    zu, zd = z[:-2, 1:-1], z[2:, 1:-1]
    ac, bc = a[None, 1:-1], b[1:-1, None]
    # Valid: the four neighbours read depth (then c > 0 follows from the jump test) and
    # neither central difference crosses a depth edge.
    dzx = zr - zl
    dzy = zd - zu
    jump = np.float32(EDGE_JUMP) * c
    ok = (zl > 0) & (zr > 0) & (zu > 0) & (zd > 0)
    ok &= np.abs(dzx) < jump
    ok &= np.abs(dzy) < jump
    # The point in `base`, and the workspace crop.
    xo, yo = ac * c, bc * c
    p = []
    for k in range(3):
        pk = R[k, 0] * xo
        pk += R[k, 1] * yo
        pk += R[k, 2] * c
        pk += t[k]
        ok &= (pk >= lo[k]) & (pk <= hi[k])
        p.append(pk)
    # Central differences along the image's x (dx) and y (dy) in the optical frame, and
    # n = dy x dx, which for x right, y down, z forward points back at the camera.
    dx0 = a[None, 2:] * zr - a[None, :-2] * zl
    dx1 = bc * dzx
    dy0 = ac * dzy
    dy1 = b[2:, None] * zd - b[:-2, None] * zu
    n0 = dy1 * dzx - dzy * dx1
    n1 = dzy * dx0 - dy0 * dzx
    n2 = dy0 * dx1 - dy1 * dx0
    norm2 = n0 * n0 + n1 * n1 + n2 * n2
    ok &= norm2 > 0
    sel = np.flatnonzero(ok)
    inv = 1.0 / np.sqrt(norm2.reshape(-1)[sel])
    n0, n1, n2 = (n.reshape(-1)[sel] * inv for n in (n0, n1, n2))
    pts = np.empty((len(sel), 3), np.float32)
    nrm = np.empty((len(sel), 3), np.float32)
    for k in range(3):
        pts[:, k] = p[k].reshape(-1)[sel]
        nrm[:, k] = R[k, 0] * n0 + R[k, 1] * n1 + R[k, 2] * n2
    # sel indexes the (h - 2, w - 2) interior; back to the full image's flat pixel index.
    row, col = np.divmod(sel, w - 2)
    pixel = ((row + 1) * (stride * W) + (col + 1) * stride).astype(np.int32)
    return pts, nrm, pixel


@lru_cache(maxsize=16)
def _rays_cached(
    fx: float, fy: float, cx: float, cy: float, W: int, H: int, stride: int
) -> tuple[np.ndarray, np.ndarray]:
    a = (np.arange(0, W, stride, dtype=np.float32) - np.float32(cx)) / np.float32(fx)
    b = (np.arange(0, H, stride, dtype=np.float32) - np.float32(cy)) / np.float32(fy)
    a.flags.writeable = False
    b.flags.writeable = False
    return a, b


def _rays(K: np.ndarray, W: int, H: int, stride: int) -> tuple[np.ndarray, np.ndarray]:
    """Normalised image coordinates x/z of the strided columns and y/z of the strided rows."""
    return _rays_cached(
        float(K[0, 0]), float(K[1, 1]), float(K[0, 2]), float(K[1, 2]), W, H, stride
    )


def fuse(frames: Sequence[DepthFrame], settings: PerceptionSettings | None = None) -> FusedCloud:
    """All frames' points in `base`, cropped to the workspace box, optionally voxel-thinned.

    Each point keeps the index of its camera and its pixel, so IR detections and image
    regions can be tied back to points. Points come frame by frame, and within a frame in
    row-major pixel order.
    """
    s = settings or get_settings().perception
    lo = np.asarray(s.workspace_min, np.float32)
    hi = np.asarray(s.workspace_max, np.float32)
    parts = [_frame_points(f, s.pixel_stride, lo, hi) for f in frames]
    if parts:
        points = np.concatenate([p for p, _, _ in parts])
        normals = np.concatenate([n for _, n, _ in parts])
        pixel = np.concatenate([px for _, _, px in parts])
        camera = np.repeat(np.arange(len(parts), dtype=np.uint8), [len(px) for _, _, px in parts])
    else:
        points = np.zeros((0, 3), np.float32)
        normals = np.zeros((0, 3), np.float32)
        pixel = np.zeros(0, np.int32)
        camera = np.zeros(0, np.uint8)
    cloud = FusedCloud(points, normals, camera, pixel, tuple(f.camera for f in frames))
    if s.voxel_size > 0:
        cloud = voxel_downsample(cloud, s.voxel_size)
    return cloud


#: Largest voxel table `voxel_first` allocates (int32 entries); bigger boxes sort instead.
DENSE_VOXELS_MAX = 16_000_000


def voxel_first(points: np.ndarray, size: float) -> np.ndarray:
    """Sorted indices of the first point (in array order) of each occupied voxel of edge
    `size` (m), voxels aligned on multiples of `size`.

    The three integer voxel coordinates are packed into one int64 key. Over a box of up to
    DENSE_VOXELS_MAX voxels a table indexed by key takes each voxel's smallest point index
    in linear time (a sort-based unique is several times slower on a full cloud); beyond
    it, np.unique sorts the keys.
    """
    n = len(points)
    if n == 0:
        return np.zeros(0, np.int64)
    keys = np.floor(np.asarray(points, np.float32) / np.float32(size)).astype(np.int64)
    keys -= keys.min(axis=0)
    span = keys.max(axis=0) + 1
    packed = (keys[:, 0] * span[1] + keys[:, 1]) * span[2] + keys[:, 2]
    cells = int(np.prod(span))
    if cells <= DENSE_VOXELS_MAX:
        index = np.int32 if n < np.iinfo(np.int32).max else np.int64  # int32 fills faster
        table = np.full(cells, n, index)
        np.minimum.at(table, packed, np.arange(n, dtype=index))
        return np.sort(table[table < n]).astype(np.int64)
    if np.any(span >= 1 << 21):  # the packed key could overflow: sort rows
        _, first = np.unique(keys, axis=0, return_index=True)
    else:
        _, first = np.unique(packed, return_index=True)
    return np.sort(first)


def thin(points: np.ndarray, voxel: float) -> np.ndarray:
    """Mask of one point (the first) per occupied voxel of edge `voxel` (m)."""
    keep = np.zeros(len(points), bool)
    keep[voxel_first(points, voxel)] = True
    return keep


def voxel_downsample(cloud: FusedCloud, size: float) -> FusedCloud:
    """Keep the first point (in cloud order) of each occupied voxel of edge `size` (m)."""
    return cloud.subset(voxel_first(cloud.points, size))


def _unit(direction: np.ndarray) -> np.ndarray:
    d = np.asarray(direction, dtype=np.float64)
    norm = float(np.linalg.norm(d))
    if not np.isfinite(norm) or norm == 0.0:
        raise ValueError("the ray's direction must be a finite, non-zero vector")
    return d / norm


def ray_distance(point: np.ndarray, origin: np.ndarray, direction: np.ndarray) -> float:
    """How far (m) `point` (3,) lies from the ray from `origin` (3,) along `direction` (3,):
    from the line ahead of the origin, or from the origin for a point behind it. A second
    click on the laser's dot passes through the aimed point. All in one frame."""
    d = _unit(direction)
    rel = np.asarray(point, dtype=np.float64) - np.asarray(origin, dtype=np.float64)
    return float(np.linalg.norm(rel - max(float(rel @ d), 0.0) * d))


def ray_hit(
    points: np.ndarray, origin: np.ndarray, direction: np.ndarray, radius: float = 0.01
) -> np.ndarray | None:
    """Where a ray first meets a cloud: of the points (N, 3) m within `radius` (m) of the ray
    from `origin` (3,) along `direction` (3,), the one nearest the origin along the ray, as
    a (3,) float64 point; None if the ray passes every point. A click in the 3D view gives a
    ray; this turns it into the point the user meant. All in one frame (e.g. `base`)."""
    d = _unit(direction)
    rel = np.asarray(points, dtype=np.float64) - np.asarray(origin, dtype=np.float64)
    along = rel @ d
    off2 = np.einsum("ij,ij->i", rel, rel) - along**2
    near = np.flatnonzero((along > 0.0) & (off2 <= radius * radius))
    if len(near) == 0:
        return None
    return rel[near[np.argmin(along[near])]] + np.asarray(origin, dtype=np.float64)
