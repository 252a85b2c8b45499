"""The offscreen renderer: one GL context that gives metric z-depth and a geom id per pixel
from one segmentation pass, and the geom groups each kind of image shows."""

from __future__ import annotations

import threading

import mujoco
import numpy as np

from laserpick.robot.gl_backend import loaded_backend
from laserpick.robot.sim.objects import GROUP_OPAQUE, GROUP_ROBOT, GROUP_SPECULAR, GROUP_TRANSPARENT

#: Geom groups the depth sensor sees: surfaces/opaque (0), robot (1), specular (3).
DEPTH_GEOMGROUP = tuple(int(g in (GROUP_OPAQUE, GROUP_ROBOT, GROUP_SPECULAR)) for g in range(6))
#: Geom groups in the ground-truth label image: everything physical, transparent included.
_PHYSICAL = (GROUP_OPAQUE, GROUP_ROBOT, GROUP_TRANSPARENT, GROUP_SPECULAR)
LABEL_GEOMGROUP = tuple(int(g in _PHYSICAL) for g in range(6))


class RenderingUnavailable(RuntimeError):
    """MuJoCo could not set up OpenGL rendering in this process, so the cameras cannot
    render; every later renderer raises it again without a new attempt."""


#: Why the first GL setup of this process failed, once one has. A failed `MjrContext` leaves
#: a C++ static initialiser in MuJoCo half done: a second attempt aborts the process (on the
#: same thread) or hangs it holding the GIL (on another), so none is made.
_setup_failure: str | None = None
_setup_lock = threading.Lock()


def gl_setup(
    model: mujoco.MjModel, width: int, height: int
) -> tuple[mujoco.GLContext, mujoco.MjrContext]:
    """An offscreen GL context of `width` x `height` pixels, current on this thread, and
    MuJoCo's render context for `model` in it. RenderingUnavailable if that failed, now or
    before in this process."""
    global _setup_failure
    with _setup_lock:
        if _setup_failure is not None:
            raise RenderingUnavailable(_setup_failure)
        try:
            gl = mujoco.GLContext(width, height)
            gl.make_current()
            return gl, mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_100)
        except Exception as exc:
            why = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
            _setup_failure = (
                f"the cameras cannot render: MuJoCo's {loaded_backend()} backend made no OpenGL"
                f" context ({why}); restart laserpick where it can (docs/robot.md)"
            )
            raise RenderingUnavailable(_setup_failure) from exc


def render_option(groups: tuple[int, ...]) -> mujoco.MjvOption:
    """Render options that draw the geom `groups` (a 0/1 flag per group) and nothing else."""
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


class SegmentationRenderer:
    """One offscreen GL context, scene and MjrContext: depth + geom ids from one pass."""

    def __init__(self, model: mujoco.MjModel, width: int, height: int) -> None:
        self.width, self.height = width, height
        self.gl, self.con = gl_setup(model, width, height)
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
