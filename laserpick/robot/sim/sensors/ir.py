"""The IR image: surfaces shaded by distance, incidence and reflectance, and the laser dots a
camera sees drawn into it, saturated."""

from __future__ import annotations

import math
from collections.abc import Sequence

import mujoco
import numpy as np

from laserpick.description import dims
from laserpick.robot.sim.sensors.noise import SensorNoise

#: A laser dot is drawn if the rendered depth near it is within this of the dot's depth (m).
LASER_VISIBLE_TOL = 0.02

# IR intensity model: ambient + gain * reflectance * cos(incidence) * min(1, (IR_REF_Z / z)^2).
IR_AMBIENT = 25.0
IR_GAIN = 140.0
IR_REF_Z = 0.8  #: m, nearer than this a surface is as bright as it gets
IR_MAX_SCENE = 200  #: cap for scene intensities, well below the 250 a laser dot reaches
IR_STEP = 2  #: the IR shading is computed on every IR_STEP-th pixel (see `IrShading.image`)


class IrShading:
    """What the IR shading needs per model and camera intrinsics: each geom's reflectance and
    the viewing rays of the pixels it is computed at."""

    def __init__(self, model: mujoco.MjModel, K: np.ndarray, width: int, height: int) -> None:
        # IR reflectance per geom from its colour's luminance, in [0.45, 1]; index -1 = none.
        rgba = model.geom_rgba
        lum = 0.2126 * rgba[:, 0] + 0.7152 * rgba[:, 1] + 0.0722 * rgba[:, 2]
        self._reflectance = np.append(0.45 + 0.55 * np.clip(lum, 0, 1), 0.0).astype(np.float32)
        # Ray directions (x/z, y/z) in the optical frame of the pixels the IR shading is
        # computed at (every IR_STEP-th); all cameras share K.
        u = (np.arange(0, width, IR_STEP, dtype=np.float32) - K[0, 2]) / K[0, 0]
        v = (np.arange(0, height, IR_STEP, dtype=np.float32) - K[1, 2]) / K[1, 1]
        self._ray_a, self._ray_b = np.meshgrid(u, v)
        self._ray_norm = np.sqrt(self._ray_a**2 + self._ray_b**2 + 1.0)
        self._f_ir = np.float32(K[0, 0] / IR_STEP)

    def image(
        self, z_true: np.ndarray, seg: np.ndarray, noise: SensorNoise, ir_noise: float
    ) -> np.ndarray:
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
        if ir_noise > 0:
            ir += noise.normal(z.shape) * np.float32(ir_noise)
        np.clip(ir, 0, IR_MAX_SCENE, out=ir)
        small = ir.astype(np.uint8)
        full = np.repeat(np.repeat(small, IR_STEP, axis=0), IR_STEP, axis=1)[:H, :W]
        surface = (z_true >= dims.DEPTH_MIN) & (z_true <= dims.DEPTH_MAX)
        return full * surface.view(np.uint8)


def draw_laser_dots(
    ir: np.ndarray,
    z_true: np.ndarray,
    K: np.ndarray,
    T_cam_world: np.ndarray,
    hits: Sequence[np.ndarray],
    radius_px: float,
) -> None:
    """Draw each visible laser hit (world, m) into `ir` in place as a saturated dot."""
    H, W = ir.shape
    R = radius_px
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
