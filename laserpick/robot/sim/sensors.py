"""The five simulated depth sensors (paper 004, section 5.1): depth and IR frames.

Each capture renders every camera once with MuJoCo's offscreen renderer in segmentation mode,
which gives, from one pass, the z-buffer (metric depth) and a geom id per pixel. A noise model
fitted loosely to structured-light sensors (Occipital Structure) then turns the exact depth
into what the pipeline gets, and an IR intensity image is synthesised with the laser dots in it.

What the sensors see, by geom group (see `laserpick.robot.sim.objects`):

* 0 surfaces and opaque objects, 1 the robot: seen, with noise.
* 2 transparent objects: not seen at all. Structured light passes through clear plastic, so
  the depth image shows the table behind them (and so does the laser, see `laser.py`).
* 3 specular objects: seen with about `specular_dropout` of their pixels missing, in blobs.
* 4 and 5 (markers, sites): hidden.

Noise model, in this order, per camera and capture (parameters in `SensorSettings`):

1. Edge dropouts: a pixel whose exact depth differs from a 4-neighbour's by more than
   `edge_dropout_jump` (m) is dropped with chance `edge_dropout_prob`, as a structured-light
   sensor loses the pattern at depth discontinuities.
2. Specular dropouts: a smooth random field (Gaussian noise on a grid of `specular_blob_px`
   cells, interpolated bilinearly) is thresholded per specular geom at its `specular_dropout`
   quantile over that geom's pixels, so each shiny object loses that fraction of its pixels in
   blobs about a cell across, like the highlights that blind a real sensor.
3. Depth noise: Gaussian, sigma = `depth_noise_k` * z^2 (m), the structured-light law.
   The per-pixel standard normals (for this, the edge dropouts and the IR noise) are slices at
   random offsets of one pool drawn at the first capture, because drawing 300k fresh normals
   costs ~5 ms each time; pixels within a frame stay independent.
4. Range: readings below `dims.DEPTH_MIN` or beyond `dims.DEPTH_MAX` become 0 (missing).

The IR image: a surface's brightness falls with the square of distance and with the cosine of
the angle between its normal and the viewing ray (from the depth image's gradients), scaled by a
per-geom reflectance from its colour, plus `ir_noise`. It is 0 where no surface lies within
range, and mostly 25-165 elsewhere, so a saturated laser dot stands out. Each laser hit that a
camera sees unoccluded is drawn as a Gaussian dot saturated (255) out to
`laser_spot_radius_px`. The IR image shows surfaces where depth dropped out (edges, specular
blobs): the IR camera sees them; only the pattern decoding failed there.

Frames: `DepthFrame.K` follows OpenCV (pixel centres at integer coordinates, x right, y down),
so the principal point is ((W-1)/2, (H-1)/2): MuJoCo renders the optical axis through the
centre of the image, i.e. the corner between the four middle pixels. `T_base_cam` is the
optical frame in `base`: MuJoCo's camera frame (looking along -z, +y up) times diag(1, -1, -1).

Threading: the OpenGL context belongs to the thread that creates it, and this class creates
it lazily on the first capture. Use one `DepthCameras` from one thread only (the capture
thread); it raises if called from another. `MUJOCO_GL` (egl for headless) must be set before
mujoco is first imported.
"""

from __future__ import annotations

import copy
import math
import threading
from collections.abc import Sequence
from statistics import NormalDist

import mujoco
import numpy as np

from laserpick.description import dims
from laserpick.robot.sim.model import SCOOTER_BODY, depth_intrinsics
from laserpick.robot.sim.objects import GROUP_OPAQUE, GROUP_ROBOT, GROUP_SPECULAR, GROUP_TRANSPARENT
from laserpick.settings import SensorSettings, get_settings
from laserpick.transforms import invert, make_transform, pinhole_intrinsics
from laserpick.types import DepthFrame

#: Geom groups the depth sensor sees: surfaces/opaque (0), robot (1), specular (3).
DEPTH_GEOMGROUP = tuple(int(g in (GROUP_OPAQUE, GROUP_ROBOT, GROUP_SPECULAR)) for g in range(6))
#: Geom groups in the ground-truth label image: everything physical, transparent included.
_PHYSICAL = (GROUP_OPAQUE, GROUP_ROBOT, GROUP_TRANSPARENT, GROUP_SPECULAR)
LABEL_GEOMGROUP = tuple(int(g in _PHYSICAL) for g in range(6))
#: MuJoCo camera frame (looks along -z, +y up) to the OpenCV optical frame (z forward, y down).
CAM_TO_OPTICAL = np.diag([1.0, -1.0, -1.0])
#: Size of the pool of Gaussian samples the per-pixel noise is sliced from (see _normal).
NOISE_POOL = 1 << 22
#: A laser dot is drawn if the rendered depth near it is within this of the dot's depth (m).
LASER_VISIBLE_TOL = 0.02

# IR intensity model: ambient + gain * reflectance * cos(incidence) * min(1, (IR_REF_Z / z)^2).
IR_AMBIENT = 25.0
IR_GAIN = 140.0
IR_REF_Z = 0.8  #: m, nearer than this a surface is as bright as it gets
IR_MAX_SCENE = 200  #: cap for scene intensities, well below the 250 a laser dot reaches
IR_STEP = 2  #: the IR shading is computed on every IR_STEP-th pixel (see _ir_image)


def _option(groups: tuple[int, ...]) -> mujoco.MjvOption:
    opt = mujoco.MjvOption()
    opt.geomgroup[:] = groups
    opt.sitegroup[:] = 0
    opt.jointgroup[:] = 0
    opt.tendongroup[:] = 0
    opt.actuatorgroup[:] = 0
    opt.flexgroup[:] = 0
    opt.skingroup[:] = 0
    opt.flags[mujoco.mjtVisFlag.mjVIS_RANGEFINDER] = False
    return opt


class _Render:
    """One offscreen GL context, scene and MjrContext: depth + geom ids from one pass."""

    def __init__(self, model: mujoco.MjModel, width: int, height: int) -> None:
        self.width, self.height = width, height
        self.gl = mujoco.GLContext(width, height)
        self.gl.make_current()
        self.con = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_100)
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self.con)
        # Reversed z with a float buffer: precise metric depth far away.
        self.con.readDepthMap = mujoco.mjtDepthMap.mjDEPTH_ZEROFAR
        self.scene = mujoco.MjvScene(model, maxgeom=max(1000, 2 * model.ngeom))
        flags = self.scene.flags
        flags[mujoco.mjtRndFlag.mjRND_SEGMENT] = True
        flags[mujoco.mjtRndFlag.mjRND_IDCOLOR] = True
        for f in ("mjRND_SHADOW", "mjRND_REFLECTION", "mjRND_SKYBOX", "mjRND_FOG", "mjRND_HAZE"):
            flags[getattr(mujoco.mjtRndFlag, f)] = False
        self.rect = mujoco.MjrRect(0, 0, width, height)
        self.camera = mujoco.MjvCamera()
        self.camera.type = mujoco.mjtCamera.mjCAMERA_FIXED
        self.rgb = np.empty((height, width, 3), np.uint8)
        self.zbuf = np.empty((height, width), np.float32)
        extent = model.stat.extent
        near = np.float32(model.vis.map.znear * extent)
        far = np.float32(model.vis.map.zfar * extent)
        # Undo the reversed-z perspective projection (as mujoco.Renderer does).
        c = -(far + near) / (far - near)
        d = -(np.float32(2) * far * near) / (far - near)
        self.c_coef = float(np.float32(-0.5) * c - np.float32(0.5))
        self.d_coef = float(np.float32(-0.5) * d)
        self.far = float(far)

    def render(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        cam_id: int,
        opt: mujoco.MjvOption,
        want_depth: bool = True,
    ) -> tuple[np.ndarray | None, np.ndarray]:
        """z-depth (H, W) float32 m (the far plane where empty) and geom ids (H, W) int32."""
        self.camera.fixedcamid = cam_id
        mujoco.mjv_updateScene(
            model, data, opt, None, self.camera, mujoco.mjtCatBit.mjCAT_ALL, self.scene
        )
        mujoco.mjr_render(self.rect, self.scene, self.con)
        mujoco.mjr_readPixels(self.rgb, self.zbuf if want_depth else None, self.rect, self.con)
        # The segment colour of a pixel is its scene geom index + 1 (0: background).
        n = self.scene.ngeom
        lut = np.full(n + 1, -1, dtype=np.int32)
        for i in range(n):
            g = self.scene.geoms[i]
            if g.segid >= 0 and g.objtype == mujoco.mjtObj.mjOBJ_GEOM:
                lut[g.segid + 1] = g.objid
        if n < 255:
            seg = self.rgb[..., 0]  # the id fits in the red byte: skip decoding the rest
        else:
            rgb = self.rgb.astype(np.int32)
            seg = rgb[..., 0] | (rgb[..., 1] << 8) | (rgb[..., 2] << 16)
            np.clip(seg, 0, n, out=seg)
        labels = np.flipud(np.take(lut, seg))  # GL rows run bottom-up
        if not want_depth:
            return None, labels
        # float32 is enough here: reversed z keeps ~1e-7 relative precision at any depth.
        z = np.float32(self.d_coef) / (self.zbuf + np.float32(self.c_coef))
        return np.ascontiguousarray(np.flipud(z)), labels

    def close(self) -> None:
        self.gl.make_current()
        self.con.free()
        self.gl.free()


class DepthCameras:
    """The five depth sensors of `dims.CAMERA_MOUNTS`, rendered from a qpos.

    Owns a private copy of the model (rendered without multisampling, so geom ids and depth
    edges are exact), a private MjData and a noise generator seeded from `settings.seed`:
    the same seed and the same sequence of calls give identical frames. Changes made to the
    caller's model after construction (colours, static geom poses) are not seen.
    """

    def __init__(self, model: mujoco.MjModel, settings: SensorSettings | None = None) -> None:
        self.settings = settings if settings is not None else get_settings().sensor
        self._model = copy.copy(model)
        # Multisampling would average segment colours (wrong ids) and depths at edges.
        self._model.vis.quality.offsamples = 0
        self._data = mujoco.MjData(self._model)
        self._rng = np.random.default_rng(self.settings.seed)
        self.width, self.height = dims.DEPTH_WIDTH, dims.DEPTH_HEIGHT
        self.names = tuple(c.name for c in dims.CAMERA_MOUNTS)
        self._cam_ids = [self._model.camera(n).id for n in self.names]
        self._scooter = self._model.body(SCOOTER_BODY).id
        self.K: dict[str, np.ndarray] = {}
        for name, cid in zip(self.names, self._cam_ids, strict=True):
            fovy = math.radians(float(self._model.cam_fovy[cid]))
            K = pinhole_intrinsics(self.width, self.height, fovy)
            if not np.isclose(K[0, 0], depth_intrinsics()[0, 0], rtol=1e-6):
                raise ValueError(f"camera {name}: fovy disagrees with dims.DEPTH_FOVY")
            self.K[name] = K
        self._opt_depth = _option(DEPTH_GEOMGROUP)
        self._opt_labels = _option(LABEL_GEOMGROUP)
        groups = self._model.geom_group
        self._specular = np.append(groups == GROUP_SPECULAR, False)  # (ngeom + 1,) bool
        self._has_specular = bool(self._specular.any())
        # IR reflectance per geom from its colour's luminance, in [0.45, 1]; index -1 = none.
        rgba = self._model.geom_rgba
        lum = 0.2126 * rgba[:, 0] + 0.7152 * rgba[:, 1] + 0.0722 * rgba[:, 2]
        self._reflectance = np.append(0.45 + 0.55 * np.clip(lum, 0, 1), 0.0).astype(np.float32)
        # Ray directions (x/z, y/z) in the optical frame of the pixels the IR shading is
        # computed at (every IR_STEP-th); all cameras share K.
        K0 = self.K[self.names[0]]
        u = (np.arange(0, self.width, IR_STEP, dtype=np.float32) - K0[0, 2]) / K0[0, 0]
        v = (np.arange(0, self.height, IR_STEP, dtype=np.float32) - K0[1, 2]) / K0[1, 1]
        self._ray_a, self._ray_b = np.meshgrid(u, v)
        self._ray_norm = np.sqrt(self._ray_a**2 + self._ray_b**2 + 1.0)
        self._f_ir = np.float32(K0[0, 0] / IR_STEP)
        self._pool: np.ndarray | None = None  # see _normal
        self._render: _Render | None = None
        self._thread: int | None = None
        # The cameras ride on the scooter, so their poses in `base` do not depend on qpos.
        self._set_state(self._model.qpos0)
        #: T_base_cam (4x4) of each camera's optical frame.
        self.T_base_cam = {
            n: self._T_base_cam(c) for n, c in zip(self.names, self._cam_ids, strict=True)
        }

    # --- public -----------------------------------------------------------------------------

    def capture(
        self, qpos: np.ndarray, stamp: float, laser_hits: Sequence[np.ndarray] = ()
    ) -> list[DepthFrame]:
        """One frame per camera, in `dims.CAMERA_MOUNTS` order, at joint positions `qpos`.

        laser_hits: world points (m) where lit beams land (`SimLaser.cast`); each is drawn
        into the IR image of every camera that sees it. None entries are skipped.
        """
        return self._capture(qpos, stamp, laser_hits, labels=False)[0]

    def capture_with_labels(
        self, qpos: np.ndarray, stamp: float, laser_hits: Sequence[np.ndarray] = ()
    ) -> tuple[list[DepthFrame], list[np.ndarray]]:
        """`capture`, plus per camera an (H, W) int32 geom id image (-1: nothing).

        The labels are simulator ground truth for tests and bench/ only; they include
        transparent objects (group 2), which the depth image does not show. This costs one
        more render per camera, and consumes the noise generator exactly as `capture` does.
        """
        return self._capture(qpos, stamp, laser_hits, labels=True)

    def close(self) -> None:
        """Free the GL context. Call from the capture thread."""
        if self._render is not None:
            self._render.close()
            self._render = None

    def __enter__(self) -> DepthCameras:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- internals --------------------------------------------------------------------------

    def _set_state(self, qpos: np.ndarray) -> None:
        m, d = self._model, self._data
        d.qpos[:] = qpos
        # Positions only: bodies, geoms, then cameras (mj_camlight needs the com for tracking
        # cameras, so mj_comPos runs too). No dynamics are needed to render.
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        mujoco.mj_camlight(m, d)

    def _T_base_cam(self, cam_id: int) -> np.ndarray:
        d = self._data
        T_world_cam = make_transform(
            d.cam_xmat[cam_id].reshape(3, 3) @ CAM_TO_OPTICAL, d.cam_xpos[cam_id]
        )
        T_world_base = make_transform(d.xmat[self._scooter].reshape(3, 3), d.xpos[self._scooter])
        return invert(T_world_base) @ T_world_cam

    def _renderer(self) -> _Render:
        me = threading.get_ident()
        if self._render is None:
            self._render = _Render(self._model, self.width, self.height)
            self._thread = me
        elif self._thread != me:
            raise RuntimeError(
                "DepthCameras is bound to the thread that first captured; "
                "use one DepthCameras per thread"
            )
        else:
            self._render.gl.make_current()
        return self._render

    def _capture(
        self, qpos: np.ndarray, stamp: float, laser_hits: Sequence[np.ndarray], labels: bool
    ) -> tuple[list[DepthFrame], list[np.ndarray]]:
        r = self._renderer()
        m, d = self._model, self._data
        self._set_state(np.asarray(qpos, dtype=float))
        hits = [np.asarray(h, dtype=float) for h in laser_hits if h is not None]
        frames: list[DepthFrame] = []
        label_images: list[np.ndarray] = []
        for name, cid in zip(self.names, self._cam_ids, strict=True):
            z_true, seg = r.render(m, d, cid, self._opt_depth)
            assert z_true is not None
            T_base_cam = self._T_base_cam(cid)
            T_world_cam = make_transform(
                d.cam_xmat[cid].reshape(3, 3) @ CAM_TO_OPTICAL, d.cam_xpos[cid]
            )
            depth = self._noisy_depth(z_true, seg)
            ir = self._ir_image(z_true, seg)
            self._draw_laser(ir, z_true, self.K[name], invert(T_world_cam), hits)
            frames.append(
                DepthFrame(
                    depth=depth,
                    ir=ir,
                    K=self.K[name].copy(),
                    T_base_cam=T_base_cam,
                    camera=name,
                    stamp=float(stamp),
                )
            )
            if labels:
                label_images.append(r.render(m, d, cid, self._opt_labels, want_depth=False)[1])
        return frames, label_images

    def _noisy_depth(self, z_true: np.ndarray, seg: np.ndarray) -> np.ndarray:
        """The sensor's depth (H, W) float32 m, 0 = missing, from the exact z-depth."""
        s = self.settings
        H, W = z_true.shape
        drop = np.zeros((H, W), dtype=bool)
        # 1. Edges: both pixels of a neighbour pair across a jump (the empty far plane counts
        #    as far away, so silhouettes against nothing are edges too).
        if s.edge_dropout_prob > 0:
            jx = np.abs(np.diff(z_true, axis=1)) > s.edge_dropout_jump
            jy = np.abs(np.diff(z_true, axis=0)) > s.edge_dropout_jump
            edge = np.zeros((H, W), dtype=bool)
            edge[:, 1:] |= jx
            edge[:, :-1] |= jx
            edge[1:, :] |= jy
            edge[:-1, :] |= jy
            # An edge pixel drops with chance p: a standard normal below Phi^-1(p).
            p = s.edge_dropout_prob
            cut = np.float32(NormalDist().inv_cdf(p)) if p < 1 else np.float32(np.inf)
            drop = edge & (self._normal((H, W)) < cut)
        # 2. Specular blobs.
        if self._has_specular and s.specular_dropout > 0:
            spec_px = np.flatnonzero(np.take(self._specular, seg))  # -1 picks the last False
            if spec_px.size:
                field = self._blob_field(spec_px, H, W)
                ids = seg.flat[spec_px]
                for g in np.unique(ids):
                    sel = ids == g
                    thr = np.quantile(field[sel], s.specular_dropout)
                    drop.flat[spec_px[sel][field[sel] <= thr]] = True
        # 3. Noise grows with z^2.
        z = z_true
        if s.depth_noise_k > 0:
            noise = self._normal((H, W))
            z = z_true + noise * (np.float32(s.depth_noise_k) * z_true * z_true)
        # 4. Range.
        valid = (z >= dims.DEPTH_MIN) & (z <= dims.DEPTH_MAX) & ~drop
        return z * valid  # multiplying by the mask is 10x faster than np.where here

    def reseed(self, seed: int | np.random.SeedSequence) -> None:
        """Draw the noise from here on as freshly built cameras seeded with `seed` would."""
        self._rng = np.random.default_rng(seed)
        self._pool = None

    def _normal(self, shape: tuple[int, int]) -> np.ndarray:
        """Standard normal float32 noise of `shape`: a slice at a random offset of a pool drawn
        once. Drawing 300k normals costs ~5 ms, twice per camera; the slice costs nothing.
        Pixels within a frame stay independent; frames reuse the pool at shifted offsets."""
        n = shape[0] * shape[1]
        if self._pool is None:
            self._pool = self._rng.standard_normal(NOISE_POOL, dtype=np.float32)
        o = int(self._rng.integers(0, self._pool.size - n))
        return self._pool[o : o + n].reshape(shape)

    def _blob_field(self, pixels: np.ndarray, H: int, W: int) -> np.ndarray:
        """A smooth random field sampled at flat pixel indices: Gaussian values on a grid of
        `specular_blob_px` cells, interpolated bilinearly. Draws the whole grid each time so
        the generator advances by the same amount whatever the pixels are."""
        cell = float(self.settings.specular_blob_px)
        gh, gw = math.ceil(H / cell) + 2, math.ceil(W / cell) + 2
        grid = self._rng.standard_normal((gh, gw))
        y = (pixels // W) / cell
        x = (pixels % W) / cell
        y0, x0 = np.floor(y).astype(np.int64), np.floor(x).astype(np.int64)
        fy, fx = y - y0, x - x0
        return (
            grid[y0, x0] * (1 - fy) * (1 - fx)
            + grid[y0, x0 + 1] * (1 - fy) * fx
            + grid[y0 + 1, x0] * fy * (1 - fx)
            + grid[y0 + 1, x0 + 1] * fy * fx
        )

    def _ir_image(self, z_true: np.ndarray, seg: np.ndarray) -> np.ndarray:
        """The IR intensity image (H, W) uint8 without laser dots.

        The shading is smooth, so it is computed on every IR_STEP-th pixel and repeated,
        which keeps it to a few ms; the mask of where a surface is stays full resolution.
        """
        H, W = z_true.shape
        z = np.ascontiguousarray(z_true[::IR_STEP, ::IR_STEP])
        # Incidence from the depth gradient: for P = z (a, b, 1), the normal is
        # (-z_u, -z_v, a z_u + b z_v + z/f) and n . (a, b, 1) = z/f, so
        # cos = (z/f) / (|n| |(a, b, 1)|).
        zu = np.empty_like(z)
        zv = np.empty_like(z)
        np.subtract(z[:, 2:], z[:, :-2], out=zu[:, 1:-1])
        zu[:, 1:-1] *= 0.5
        zu[:, 0], zu[:, -1] = zu[:, 1], zu[:, -2]
        np.subtract(z[2:, :], z[:-2, :], out=zv[1:-1, :])
        zv[1:-1, :] *= 0.5
        zv[0, :], zv[-1, :] = zv[1, :], zv[-2, :]
        zf = z / self._f_ir
        nz = self._ray_a * zu
        nz += self._ray_b * zv
        nz += zf
        zu *= zu
        zv *= zv
        nz *= nz
        zu += zv
        zu += nz
        np.sqrt(zu, out=zu)
        zu *= self._ray_norm
        cos = np.divide(zf, zu, out=zf)
        # Inverse-square falloff beyond IR_REF_Z, flat nearer (the sensor's exposure control).
        falloff = np.float32(IR_REF_Z) / np.maximum(z, np.float32(1e-3), out=z)
        falloff *= falloff
        np.minimum(falloff, np.float32(1.0), out=falloff)
        ir = np.take(self._reflectance, seg[::IR_STEP, ::IR_STEP])  # -1 picks the trailing 0
        ir *= cos
        ir *= falloff
        ir *= np.float32(IR_GAIN)
        ir += np.float32(IR_AMBIENT)
        if self.settings.ir_noise > 0:
            ir += self._normal(z.shape) * np.float32(self.settings.ir_noise)
        np.clip(ir, 0, IR_MAX_SCENE, out=ir)
        small = ir.astype(np.uint8)
        full = np.repeat(np.repeat(small, IR_STEP, axis=0), IR_STEP, axis=1)[:H, :W]
        surface = (z_true >= dims.DEPTH_MIN) & (z_true <= dims.DEPTH_MAX)
        return full * surface.view(np.uint8)

    def _draw_laser(
        self,
        ir: np.ndarray,
        z_true: np.ndarray,
        K: np.ndarray,
        T_cam_world: np.ndarray,
        hits: Sequence[np.ndarray],
    ) -> None:
        """Draw each visible laser hit (world, m) into `ir` in place as a saturated dot."""
        H, W = ir.shape
        R = self.settings.laser_spot_radius_px
        # A Gaussian of peak 4 x 255 and this sigma is exactly 255 at R: saturated inside R,
        # then a soft rim a couple of pixels wide, as a real dot blooms on the sensor.
        sigma = R / math.sqrt(2.0 * math.log(4.0))
        half = math.ceil(R + 3.0 * sigma)
        for p_world in hits:
            p = T_cam_world[:3, :3] @ p_world + T_cam_world[:3, 3]
            if p[2] <= 1e-6:
                continue
            u = K[0, 0] * p[0] / p[2] + K[0, 2]
            v = K[1, 1] * p[1] / p[2] + K[1, 2]
            iu, iv = round(u), round(v)
            if not (0 <= iu < W and 0 <= iv < H):
                continue
            # Visible if some rendered depth next to the dot's centre is the dot's own depth;
            # a 3x3 window keeps a dot on an object's rim from counting as hidden.
            win = z_true[max(iv - 1, 0) : iv + 2, max(iu - 1, 0) : iu + 2]
            if np.min(np.abs(win - p[2])) > LASER_VISIBLE_TOL:
                continue
            u0, u1 = max(iu - half, 0), min(iu + half + 1, W)
            v0, v1 = max(iv - half, 0), min(iv + half + 1, H)
            uu = np.arange(u0, u1) - u
            vv = np.arange(v0, v1) - v
            d2 = vv[:, None] ** 2 + uu[None, :] ** 2
            spot = np.minimum(255.0, 4.0 * 255.0 * np.exp(-d2 / (2.0 * sigma * sigma)))
            patch = ir[v0:v1, u0:u1]
            np.maximum(patch, spot.astype(np.uint8), out=patch)


def _demo(scene_name: str | None = "isolation", n: int = 10) -> None:
    """Time full 5-camera captures: `python -m laserpick.robot.sim.sensors [scene]`."""
    import time

    from laserpick.robot.sim.model import ModelInfo, build_sim_model

    scene = None
    if scene_name:
        from laserpick.robot.sim.scenes import load_scene

        scene = load_scene(scene_name)
    model = build_sim_model(scene)
    qpos = model.qpos0.copy()
    qpos[ModelInfo.of(model).arm_qpos] = dims.UR5_HOME_Q
    with DepthCameras(model) as cams:
        t0 = time.perf_counter()
        cams.capture(qpos, 0.0)
        first = time.perf_counter() - t0
        times = []
        for i in range(n):
            t0 = time.perf_counter()
            frames = cams.capture(qpos, float(i))
            times.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        cams.capture_with_labels(qpos, 0.0)
        labelled = time.perf_counter() - t0
    ms = np.array(times) * 1e3
    print(f"scene {scene_name}: first capture {first * 1e3:.0f} ms (GL context, noise pool)")
    print(f"5-camera capture x{n}: mean {ms.mean():.0f} ms, min {ms.min():.0f}, max {ms.max():.0f}")
    print(f"capture_with_labels: {labelled * 1e3:.0f} ms")
    for f in frames:
        valid, ir = np.mean(f.depth > 0), np.median(f.ir)
        print(f"  {f.camera:9s} valid depth {valid:5.1%}  IR median {ir:.0f}")


if __name__ == "__main__":
    import sys

    _demo(sys.argv[1] if len(sys.argv) > 1 else "isolation")
