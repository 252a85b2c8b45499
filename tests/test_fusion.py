"""Fusion (pipeline/cloud.py): geometry against the known table, and the fast `fuse` against a
slow, obviously-correct reference, so its speed-up provably changes nothing."""

from __future__ import annotations

import numpy as np
import pytest

from laserpick.pipeline.cloud import fuse, voxel_downsample
from laserpick.robot.sim.truth import capture
from laserpick.settings import PerceptionSettings
from laserpick.types import FusedCloud

TABLE_TOP = 0.46  #: m, isolation scene (scene_files/isolation.yaml)
#: The table's top (x 1.3..1.9, y -0.65..0.35 in the scene file), inset 5 cm.
TABLE_XY = ((1.35, 1.85), (-0.6, 0.3))


@pytest.fixture(scope="module")
def captured():
    c = capture("isolation")
    yield c
    c.close()


def reference_fuse(frames, s: PerceptionSettings) -> FusedCloud:
    """The slow reference: full (h, w, 3) images, np.cross and np.linalg.norm, then crop."""
    lo = np.asarray(s.workspace_min, np.float32)
    hi = np.asarray(s.workspace_max, np.float32)
    st = s.pixel_stride
    pts, nrm, cam, pix = [], [], [], []
    for i, f in enumerate(frames):
        H, W = f.depth.shape
        z = f.depth[::st, ::st].astype(np.float32)
        u = (np.arange(0, W, st, dtype=np.float32) - f.K[0, 2]) / f.K[0, 0]
        v = (np.arange(0, H, st, dtype=np.float32) - f.K[1, 2]) / f.K[1, 1]
        P = np.stack(np.broadcast_arrays(u[None, :] * z, v[:, None] * z, z), axis=-1)
        dx = np.zeros_like(P)
        dy = np.zeros_like(P)
        dx[:, 1:-1] = P[:, 2:] - P[:, :-2]
        dy[1:-1, :] = P[2:, :] - P[:-2, :]
        n = np.cross(dy, dx)
        valid = z > 0
        ok = valid.copy()
        ok[:, 1:-1] &= valid[:, 2:] & valid[:, :-2]
        ok[1:-1, :] &= valid[2:, :] & valid[:-2, :]
        ok[:, [0, -1]] = False
        ok[[0, -1], :] = False
        ok &= (np.abs(dx[..., 2]) < 0.05 * z) & (np.abs(dy[..., 2]) < 0.05 * z)
        norm = np.linalg.norm(n, axis=-1)
        ok &= norm > 0
        vv, uu = np.nonzero(ok)
        R = f.T_base_cam[:3, :3].astype(np.float32)
        p = P[ok] @ R.T + f.T_base_cam[:3, 3].astype(np.float32)
        nb = (n[ok] / norm[ok][:, None]) @ R.T
        keep = np.all((p >= lo) & (p <= hi), axis=1)
        pts.append(p[keep])
        nrm.append(nb[keep])
        cam.append(np.full(int(keep.sum()), i, np.uint8))
        pix.append(((vv * st) * W + uu * st)[keep].astype(np.int32))
    return FusedCloud(
        np.concatenate(pts),
        np.concatenate(nrm),
        np.concatenate(cam),
        np.concatenate(pix),
        tuple(f.camera for f in frames),
    )


def _keys(c: FusedCloud) -> np.ndarray:
    return c.camera.astype(np.int64) << 32 | c.pixel.astype(np.int64)


@pytest.mark.parametrize("stride", [1, 2, 3])
def test_fuse_equals_the_slow_reference(captured, stride):
    s = PerceptionSettings(pixel_stride=stride)
    fast, slow = fuse(captured.frames, s), reference_fuse(captured.frames, s)
    assert fast.cameras == slow.cameras
    # Same points, same order. Float rounding differs (component-wise vs matmul), so a pixel
    # within a hair of a threshold (the crop box, the depth-jump test) may flip: allow one in
    # 100 000, and compare the rest exactly by key.
    kf, ks = _keys(fast), _keys(slow)
    flipped = len(np.setxor1d(kf, ks))
    assert flipped <= max(1, len(ks) // 100_000), f"{flipped} pixels differ"
    common, i_fast, i_slow = np.intersect1d(kf, ks, return_indices=True)
    assert len(common) >= len(ks) - flipped
    assert np.all(np.diff(i_fast) > 0) and np.all(np.diff(i_slow) > 0)  # same order
    np.testing.assert_allclose(fast.points[i_fast], slow.points[i_slow], atol=1e-5)
    np.testing.assert_allclose(fast.normals[i_fast], slow.normals[i_slow], atol=1e-4)
    assert fast.points.dtype == fast.normals.dtype == np.float32
    assert fast.camera.dtype == np.uint8 and fast.pixel.dtype == np.int32


def test_each_camera_sees_the_table_top_at_its_height(captured):
    cloud = fuse(captured.frames, PerceptionSettings(pixel_stride=2))
    objects = list(captured.robot.sim.info.object_bodies.values())
    not_object = ~np.isin(captured.point_bodies(cloud), objects)
    (x0, x1), (y0, y1) = TABLE_XY
    for i, name in enumerate(cloud.cameras):
        mine = cloud.camera == i
        p, n = cloud.points[mine], cloud.normals[mine]
        on = (p[:, 0] > x0) & (p[:, 0] < x1) & (p[:, 1] > y0) & (p[:, 1] < y1)
        on &= not_object[mine] & (np.abs(p[:, 2] - TABLE_TOP) < 0.03)
        assert on.sum() > 2000, f"{name} barely sees the table"
        err = np.median(np.abs(p[on, 2] - TABLE_TOP))
        assert err < 0.003, f"{name}: table top off by {err * 1000:.1f} mm (median)"
        # On average the normals point straight up...
        mean = n[on].mean(axis=0)
        assert mean[2] / np.linalg.norm(mean) > 0.99, f"{name}: table normals do not point up"
        # ...but each is a finite difference over 2 strided pixels, noisy as depth noise grows
        # with z^2: the median is above 0.97 for the low sensors and ~0.94 for high_44.
        assert np.median(n[on, 2]) > 0.9, f"{name}: table normals too noisy"


def test_normals_face_the_camera_that_saw_them(captured):
    cloud = fuse(captured.frames)
    cam_pos = np.array([f.T_base_cam[:3, 3] for f in captured.frames])
    to_cam = cam_pos[cloud.camera] - cloud.points
    assert np.all(np.einsum("ij,ij->i", cloud.normals, to_cam) > 0)
    np.testing.assert_allclose(np.linalg.norm(cloud.normals, axis=1), 1.0, atol=1e-4)


def test_crop_keeps_only_points_inside_the_box(captured):
    s = PerceptionSettings(workspace_min=(1.4, -0.3, 0.4), workspace_max=(1.7, 0.1, 0.6))
    cloud = fuse(captured.frames, s)
    assert len(cloud) > 1000
    assert np.all(cloud.points >= np.float32(s.workspace_min))
    assert np.all(cloud.points <= np.float32(s.workspace_max))
    # And nothing inside the box was lost: the wide cloud cropped afterwards is the same set.
    wide = fuse(captured.frames, PerceptionSettings(workspace_min=(-9, -9, -9)))
    inside = np.all((wide.points >= s.workspace_min) & (wide.points <= s.workspace_max), axis=1)
    np.testing.assert_array_equal(_keys(wide.subset(inside)), _keys(cloud))


def test_provenance_deprojects_back_to_the_point(captured):
    cloud = fuse(captured.frames)
    rng = np.random.default_rng(0)
    for j in rng.choice(len(cloud), 200, replace=False):
        f = captured.frames[cloud.camera[j]]
        v, u = divmod(int(cloud.pixel[j]), f.depth.shape[1])
        z = f.depth[v, u]
        q = np.array([(u - f.K[0, 2]) / f.K[0, 0] * z, (v - f.K[1, 2]) / f.K[1, 1] * z, z])
        p = f.T_base_cam[:3, :3] @ q + f.T_base_cam[:3, 3]
        np.testing.assert_allclose(p, cloud.points[j], atol=1e-5)


def test_voxel_downsample_keeps_the_first_point_per_voxel(captured):
    cloud = fuse(captured.frames)
    thin = voxel_downsample(cloud, 0.01)
    keys = np.floor(cloud.points / np.float32(0.01)).astype(np.int64)
    _, first = np.unique(keys, axis=0, return_index=True)
    np.testing.assert_array_equal(_keys(thin), _keys(cloud.subset(np.sort(first))))
    assert 0 < len(thin) < len(cloud) / 4
