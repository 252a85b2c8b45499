"""Fusion: five depth frames into one point cloud in `base`, with normals and provenance.

Normals come from the depth image itself (the cross product of neighbouring pixels' 3D
offsets), which costs a few array operations instead of a KD-tree search per point, and is
oriented toward the camera by construction: the sensor sees only surfaces that face it.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from laserpick.pipeline.types import DepthFrame, FusedCloud
from laserpick.settings import PerceptionSettings, get_settings


def _frame_points(frame: DepthFrame, stride: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points (in the optical frame), unit normals toward the camera, and flat pixel indices."""
    H, W = frame.depth.shape
    z = frame.depth[::stride, ::stride].astype(np.float32)
    h, w = z.shape
    K = frame.K
    u = (np.arange(0, W, stride, dtype=np.float32) - K[0, 2]) / K[0, 0]
    v = (np.arange(0, H, stride, dtype=np.float32) - K[1, 2]) / K[1, 1]
    P = np.empty((h, w, 3), np.float32)
    P[..., 0] = u[None, :] * z
    P[..., 1] = v[:, None] * z
    P[..., 2] = z
    # Central differences where both neighbours are valid; one-sided at the borders.
    dx = np.zeros_like(P)
    dy = np.zeros_like(P)
    dx[:, 1:-1] = P[:, 2:] - P[:, :-2]
    dy[1:-1, :] = P[2:, :] - P[:-2, :]
    n = np.cross(dy, dx)  # for x right, y down, z forward this points back at the camera
    valid = z > 0
    ok = valid.copy()
    ok[:, 1:-1] &= valid[:, 2:] & valid[:, :-2]
    ok[1:-1, :] &= valid[2:, :] & valid[:-2, :]
    ok[:, [0, -1]] = False
    ok[[0, -1], :] = False
    # A neighbour across a depth edge gives a meaningless normal: drop such pixels.
    jump = 0.05 * z
    ok &= np.abs(dx[..., 2]) < jump
    ok &= np.abs(dy[..., 2]) < jump
    norm = np.linalg.norm(n, axis=-1)
    ok &= norm > 0
    n = n[ok] / norm[ok][:, None]
    vv, uu = np.nonzero(ok)
    pixel = (vv * stride) * W + uu * stride
    return P[ok], n, pixel.astype(np.int32)


def fuse(frames: Sequence[DepthFrame], settings: PerceptionSettings | None = None) -> FusedCloud:
    """All frames' points in `base`, cropped to the workspace box, optionally voxel-thinned.

    Each point keeps the index of its camera and its pixel, so IR detections and image
    regions can be tied back to points.
    """
    s = settings or get_settings().perception
    lo = np.asarray(s.workspace_min, np.float32)
    hi = np.asarray(s.workspace_max, np.float32)
    pts, nrm, cam, pix = [], [], [], []
    for i, f in enumerate(frames):
        p, n, px = _frame_points(f, s.pixel_stride)
        R = f.T_base_cam[:3, :3].astype(np.float32)
        t = f.T_base_cam[:3, 3].astype(np.float32)
        p = p @ R.T + t
        n = n @ R.T
        keep = np.all((p >= lo) & (p <= hi), axis=1)
        pts.append(p[keep])
        nrm.append(n[keep])
        cam.append(np.full(int(keep.sum()), i, np.uint8))
        pix.append(px[keep])
    cloud = FusedCloud(
        points=np.concatenate(pts) if pts else np.zeros((0, 3), np.float32),
        normals=np.concatenate(nrm) if nrm else np.zeros((0, 3), np.float32),
        camera=np.concatenate(cam) if cam else np.zeros(0, np.uint8),
        pixel=np.concatenate(pix) if pix else np.zeros(0, np.int32),
        cameras=tuple(f.camera for f in frames),
    )
    if s.voxel_size > 0:
        cloud = voxel_downsample(cloud, s.voxel_size)
    return cloud


def voxel_downsample(cloud: FusedCloud, size: float) -> FusedCloud:
    """Keep the first point of each occupied voxel of edge `size` (m)."""
    keys = np.floor(cloud.points / size).astype(np.int64)
    _, first = np.unique(keys, axis=0, return_index=True)
    return cloud.subset(np.sort(first))
