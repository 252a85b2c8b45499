"""The simulated depth cameras and the dual laser pointer.

One small world: the robot at home in front of a table with an opaque box, a transparent
cylinder (group 2) and a specular cylinder (group 3) on it. Each scenario is rendered once
(module-scoped fixtures) and the tests read the frames.
"""

from __future__ import annotations

import math
import threading

import mujoco
import numpy as np
import pytest
from scipy import ndimage

from laserpick.description import dims
from laserpick.robot.sim.laser import SimLaser
from laserpick.robot.sim.model import ModelInfo, build_sim_spec
from laserpick.robot.sim.sensors import DepthCameras
from laserpick.settings import SensorSettings
from laserpick.transforms import rotz
from laserpick.types import DepthFrame

G = mujoco.mjtGeom
TABLE_POS = np.array([1.5, 0.0, 0.70])
TABLE_HALF = np.array([0.35, 0.5, 0.02])
TABLE_TOP = TABLE_POS[2] + TABLE_HALF[2]
BOX_POS = np.array([1.45, 0.12, TABLE_TOP + 0.05])
BOX_HALF = np.array([0.03, 0.04, 0.05])
BOX_TOP = BOX_POS + np.array([0.0, 0.0, BOX_HALF[2]])  #: centre of the box's top face
CLEAR_POS = np.array([1.55, -0.10, TABLE_TOP + 0.07])
CLEAR_SIZE = (0.04, 0.07)  #: radius, half height
SHINY_POS = np.array([1.70, 0.05, TABLE_TOP + 0.06])
CLEAN = SensorSettings(depth_noise_k=0.0, edge_dropout_prob=0.0, specular_dropout=0.0, ir_noise=0)
NOISY = SensorSettings(seed=7)


@pytest.fixture(scope="module")
def world() -> tuple[mujoco.MjModel, mujoco.MjData]:
    spec = build_sim_spec(None)
    w = spec.worldbody
    w.add_geom(name="t_table", type=G.mjGEOM_BOX, size=TABLE_HALF, pos=TABLE_POS)
    w.add_geom(name="t_box", type=G.mjGEOM_BOX, size=BOX_HALF, pos=BOX_POS, rgba=[0.8, 0.1, 0.1, 1])
    w.add_geom(
        name="t_clear",
        type=G.mjGEOM_CYLINDER,
        size=[*CLEAR_SIZE, 0],
        pos=CLEAR_POS,
        rgba=[0.7, 0.85, 0.95, 0.3],
        group=2,
    )
    w.add_geom(
        name="t_shiny",
        type=G.mjGEOM_CYLINDER,
        size=[0.045, 0.06, 0],
        pos=SHINY_POS,
        rgba=[0.75, 0.76, 0.78, 1],
        group=3,
    )
    model = spec.compile()
    data = mujoco.MjData(model)
    data.qpos[ModelInfo.of(model).arm_qpos] = dims.UR5_HOME_Q
    mujoco.mj_forward(model, data)
    return model, data


def gid(model: mujoco.MjModel, name: str) -> int:
    return model.geom(name).id


@pytest.fixture(scope="module")
def clean(world) -> tuple[list[DepthFrame], list[np.ndarray]]:
    model, data = world
    with DepthCameras(model, CLEAN) as cams:
        return cams.capture_with_labels(data.qpos.copy(), 1.0)


@pytest.fixture(scope="module")
def noisy(world) -> tuple[list[DepthFrame], list[np.ndarray]]:
    model, data = world
    with DepthCameras(model, NOISY) as cams:
        return cams.capture_with_labels(data.qpos.copy(), 1.0)


@pytest.fixture(scope="module")
def laser_frames(world) -> dict[str, tuple[list, list[DepthFrame]]]:
    """Frames with the laser on the box's top: one beam, both beams, and off."""
    model, data = world
    laser = SimLaser(model)
    out = {}
    with DepthCameras(model, NOISY) as cams:
        laser.aim_at(BOX_TOP)
        hits = laser.cast_hits(model, data)
        out["one"] = (hits, cams.capture(data.qpos.copy(), 2.0, [h.point_world for h in hits]))
        laser.confirm()
        hits = laser.cast_hits(model, data)
        out["two"] = (hits, cams.capture(data.qpos.copy(), 2.0, [h.point_world for h in hits]))
        laser.off()
        hits = laser.cast(model, data)
        out["off"] = (hits, cams.capture(data.qpos.copy(), 2.0, hits))
    return out


def deproject(frame: DepthFrame, mask: np.ndarray | None = None):
    """Valid pixels (optionally within mask) as (points in base (N, 3), depths, (v, u))."""
    ok = frame.depth > 0
    if mask is not None:
        ok &= mask
    v, u = np.nonzero(ok)
    z = frame.depth[v, u].astype(float)
    K = frame.K
    P = np.stack([(u - K[0, 2]) / K[0, 0] * z, (v - K[1, 2]) / K[1, 1] * z, z], axis=1)
    T = frame.T_base_cam
    return P @ T[:3, :3].T + T[:3, 3], z, (v, u)


def table_top_points(frame: DepthFrame, labels: np.ndarray, model: mujoco.MjModel):
    """Deprojected table pixels well inside the top face (side faces excluded by x, y)."""
    P, z, _ = deproject(frame, labels == gid(model, "t_table"))
    inside = np.all(np.abs(P[:, :2] - TABLE_POS[:2]) < TABLE_HALF[:2] - 0.02, axis=1)
    return P[inside], z[inside]


# --- frames and geometry ----------------------------------------------------------------------


def test_frames_shape_and_extrinsics(clean):
    frames, labels = clean
    assert [f.camera for f in frames] == [c.name for c in dims.CAMERA_MOUNTS]
    for f, lab, mount in zip(frames, labels, dims.CAMERA_MOUNTS, strict=True):
        assert f.depth.shape == (dims.DEPTH_HEIGHT, dims.DEPTH_WIDTH) == f.ir.shape == lab.shape
        assert f.depth.dtype == np.float32 and f.ir.dtype == np.uint8 and lab.dtype == np.int32
        assert f.stamp == 1.0
        valid = f.depth[f.depth > 0]
        assert valid.min() >= dims.DEPTH_MIN and valid.max() <= dims.DEPTH_MAX
        # The optical frame sits at the mount and looks along its pitch and yaw.
        np.testing.assert_allclose(f.T_base_cam[:3, 3], mount.pos, atol=1e-9)
        R = f.T_base_cam[:3, :3]
        cp = math.cos(mount.pitch_down)
        look = rotz(mount.yaw) @ np.array([cp, 0.0, -math.sin(mount.pitch_down)])
        np.testing.assert_allclose(R[:, 2], look, atol=1e-9)
        assert R[2, 1] < 0  # image y (down) points down in base
        np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-9)


def test_table_top_geometry_noise_free(world, clean):
    """Deprojected table-top pixels lie on the table top to 0.1 mm: K, T_base_cam and depth
    (z along the optical axis, not range along the ray) agree."""
    model, _ = world
    seen = 0
    for f, lab in zip(*clean, strict=True):
        P, _ = table_top_points(f, lab, model)
        if len(P) < 500:
            continue
        seen += 1
        assert np.abs(P[:, 2] - TABLE_TOP).max() < 1e-4, f.camera
    assert seen >= 3


def test_table_top_geometry_with_noise(world, noisy):
    model, _ = world
    for f, lab in zip(*noisy, strict=True):
        P, z = table_top_points(f, lab, model)
        if len(P) < 500:
            continue
        # Height error = depth error times the ray's vertical component per unit z, <= |ray|.
        sigma = NOISY.depth_noise_k * z**2 * np.linalg.norm(P - f.T_base_cam[:3, 3], axis=1) / z
        within = np.abs(P[:, 2] - TABLE_TOP) < 3 * sigma + 1e-4
        assert within.mean() > 0.99, f.camera


def test_noise_grows_with_z_squared(world, noisy):
    """Depth residuals against the exact table-top plane have std = k z^2, near and far."""
    model, _ = world
    ratios = {}
    for f, lab in zip(*noisy, strict=True):
        P, z = table_top_points(f, lab, model)
        if len(P) < 2000:
            continue
        # Exact depth of each pixel's ray on the plane z = TABLE_TOP: scale the measured point
        # about the camera centre until it meets the plane.
        c = f.T_base_cam[:3, 3]
        z_exact = z * (TABLE_TOP - c[2]) / (P[:, 2] - c[2])
        res = z - z_exact
        near, far = np.quantile(z, [0.25, 0.75])
        for name, sel in (("near", z < near), ("far", z > far)):
            ratios[(f.camera, name)] = res[sel].std() / (NOISY.depth_noise_k * np.mean(z[sel] ** 2))
        zn, zf = z[z < near].mean(), z[z > far].mean()
        if zf / zn > 1.3:
            assert res[z > far].std() > res[z < near].std() * 0.8 * (zf / zn) ** 2
    assert ratios
    for key, r in ratios.items():
        assert 0.85 < r < 1.15, (key, r)


def test_transparent_object_absent_from_depth(world, clean):
    model, _ = world
    clear = gid(model, "t_clear")
    seen = 0
    for f, lab in zip(*clean, strict=True):
        mask = lab == clear
        if mask.sum() < 200:
            continue
        seen += 1
        P, _, _ = deproject(f, mask)
        assert len(P) > 0.9 * mask.sum()  # the table behind reads fine
        # What shows there lies behind the cylinder: the table top, the floor past its edge or
        # another object; never the cylinder's own surface.
        r, h = CLEAR_SIZE
        d = P - CLEAR_POS
        # (The table top under its base, at d_z = -h, shows through and is fine.)
        on_cylinder = (np.hypot(d[:, 0], d[:, 1]) < r + 2e-3) & (np.abs(d[:, 2]) < h - 2e-3)
        on_cylinder |= (np.hypot(d[:, 0], d[:, 1]) < r - 2e-3) & (np.abs(d[:, 2] - h) < 2e-3)
        assert not on_cylinder.any(), f.camera
        on_table = np.abs(P[:, 2] - TABLE_TOP) < 2e-3
        assert on_table.mean() > 0.5, f.camera
    assert seen >= 2


def test_specular_object_partly_missing_in_blobs(world, noisy):
    model, _ = world
    shiny = gid(model, "t_shiny")
    seen = 0
    for f, lab in zip(*noisy, strict=True):
        mask = lab == shiny
        if mask.sum() < 300:
            continue
        seen += 1
        frac = (f.depth[mask] > 0).mean()
        assert 0.2 <= frac <= 0.8, (f.camera, frac)
        # Blobs, not salt and pepper: the missing pixels form a few large connected regions.
        _, n = ndimage.label(mask & (f.depth == 0))
        assert n < 0.02 * mask.sum(), (f.camera, n)
    assert seen >= 2


def test_ir_image_plausible(clean):
    for f in clean[0]:
        lit = f.ir[f.ir > 0]
        assert f.ir.max() < 250  # no laser: nothing saturates
        assert np.median(lit) > 30 and np.percentile(lit, 99) <= 200
        # Noise-free, depth is missing exactly where no surface lies within range: IR is dark.
        assert np.all(f.ir[f.depth == 0] == 0) and np.all(f.ir[f.depth > 0] > 0)


# --- the laser --------------------------------------------------------------------------------


def spots(f: DepthFrame) -> list[tuple[float, float]]:
    """Centroids (u, v) of the saturated blobs in an IR image."""
    lab, n = ndimage.label(f.ir >= 250)
    cms = ndimage.center_of_mass(np.ones_like(f.ir), lab, range(1, n + 1))
    return [(c[1], c[0]) for c in cms]


def spot_point(f: DepthFrame, u: float, v: float) -> np.ndarray | None:
    """Deproject a spot centroid with the median valid depth around it (base, m)."""
    iu, iv = round(u), round(v)
    win = f.depth[iv - 3 : iv + 4, iu - 3 : iu + 4]
    if not (win > 0).any():
        return None
    z = float(np.median(win[win > 0]))
    K, T = f.K, f.T_base_cam
    p = np.array([(u - K[0, 2]) / K[0, 0] * z, (v - K[1, 2]) / K[1, 1] * z, z])
    return T[:3, :3] @ p + T[:3, 3]


def test_laser_hits_the_box(world, laser_frames):
    model, _ = world
    hits, _ = laser_frames["one"]
    assert len(hits) == 1 and hits[0].geom == gid(model, "t_box")
    np.testing.assert_allclose(hits[0].point_base, BOX_TOP, atol=1e-6)


def test_single_beam_seen_in_ir(laser_frames):
    hits, frames = laser_frames["one"]
    target = hits[0].point_base
    good = 0
    for f in frames:
        found = spots(f)
        assert len(found) <= 1, f.camera
        if found:
            p = spot_point(f, *found[0])
            assert p is not None
            assert np.linalg.norm(p - target) < 0.01, f.camera
            good += 1
    assert good >= 2


def test_two_beams_two_blobs(laser_frames):
    hits, frames = laser_frames["two"]
    assert len(hits) == 2
    assert np.linalg.norm(hits[0].point_base - hits[1].point_base) == pytest.approx(
        dims.LASER_BEAM_SEPARATION, abs=1e-3
    )
    double = 0
    for f in frames:
        found = spots(f)
        if len(found) == 2:
            double += 1
            pts = [spot_point(f, *uv) for uv in found]
            for p in pts:
                assert p is not None
                assert min(np.linalg.norm(p - h.point_base) for h in hits) < 0.01
    assert double >= 2


def test_laser_off_no_saturation(laser_frames):
    hits, frames = laser_frames["off"]
    assert hits == []
    for f in frames:
        assert f.ir.max() < 250


def test_laser_sky_and_clamping(world):
    model, data = world
    laser = SimLaser(model)
    assert laser.beams(data) == [] and laser.cast(model, data) == []
    assert not laser.confirm().confirmed  # nothing to confirm while off
    s = laser.aim(0.0, math.radians(25))
    assert s.on and not s.confirmed
    assert laser.cast(model, data) == [None]  # empty sky above the horizon
    s = laser.aim(10.0, 10.0)
    assert s.yaw == dims.LASER_YAW_LIMIT and s.pitch == dims.LASER_PITCH_MAX
    s = laser.aim(-10.0, -10.0)
    assert s.yaw == -dims.LASER_YAW_LIMIT and s.pitch == dims.LASER_PITCH_MIN
    s = laser.aim_at(np.array([-5.0, 0.12, 0.95]))  # straight behind: yaw clamps
    assert abs(s.yaw) == dims.LASER_YAW_LIMIT
    s = laser.nudge(0.0, -10.0)
    assert s.pitch == dims.LASER_PITCH_MIN
    laser.aim(0.3, -0.5)
    laser.confirm()
    (o1, d1), (o2, d2) = laser.beams(data)
    np.testing.assert_allclose(d1, d2)
    assert np.linalg.norm(o2 - o1) == pytest.approx(dims.LASER_BEAM_SEPARATION)
    assert abs(np.dot(o2 - o1, d1)) < 1e-12 and abs(o2[2] - o1[2]) < 1e-12
    assert not laser.nudge(0.01, 0.0).confirmed  # re-aiming drops the confirmation
    assert not laser.off().on


def test_deterministic_for_a_seed(world):
    model, data = world
    hits = [BOX_TOP]
    runs = []
    for seed in (3, 3, 4):
        with DepthCameras(model, SensorSettings(seed=seed)) as cams:
            runs.append([cams.capture(data.qpos.copy(), 0.0, hits) for _ in range(2)])
    for a, b in zip(runs[0], runs[1], strict=True):
        for fa, fb in zip(a, b, strict=True):
            np.testing.assert_array_equal(fa.depth, fb.depth)
            np.testing.assert_array_equal(fa.ir, fb.ir)
    # Successive captures differ, and so does another seed.
    assert not np.array_equal(runs[0][0][0].depth, runs[0][1][0].depth)
    assert not np.array_equal(runs[0][0][0].depth, runs[2][0][0].depth)


def test_bound_to_one_thread(world):
    model, data = world
    with DepthCameras(model, CLEAN) as cams:
        cams.capture(data.qpos.copy(), 0.0)
        errors: list[BaseException] = []

        def other() -> None:
            try:
                cams.capture(data.qpos.copy(), 0.0)
            except RuntimeError as e:
                errors.append(e)

        t = threading.Thread(target=other)
        t.start()
        t.join()
        assert len(errors) == 1


def test_laser_refuses_non_finite_aims_and_keeps_its_state():
    from laserpick.robot.sim.laser import SimLaser
    from laserpick.robot.sim.model import build_sim_model

    laser = SimLaser(build_sim_model(None))
    before = laser.aim(0.1, -0.3)
    for bad in ((float("nan"), 0.0), (0.0, float("inf"))):
        with pytest.raises(ValueError, match="finite"):
            laser.aim(*bad)
    with pytest.raises(ValueError, match="finite"):
        laser.nudge(float("nan"), 0.0)
    with pytest.raises(ValueError, match="finite"):
        laser.aim_at(np.array([np.nan, 0.0, 0.5]))
    assert laser.state == before
