"""The five depth cameras: one capture renders each and turns it into depth and IR frames."""

from __future__ import annotations

import copy
import math
import threading
from collections.abc import Sequence

import mujoco
import numpy as np

from laserpick.description import dims
from laserpick.robot.sim.model import SCOOTER_BODY, depth_intrinsics
from laserpick.robot.sim.objects import GROUP_SPECULAR
from laserpick.robot.sim.sensors.ir import IrShading, draw_laser_dots
from laserpick.robot.sim.sensors.noise import SensorNoise, noisy_depth
from laserpick.robot.sim.sensors.render import (
    DEPTH_GEOMGROUP,
    LABEL_GEOMGROUP,
    SegmentationRenderer,
    render_option,
)
from laserpick.settings import SensorSettings, get_settings
from laserpick.transforms import invert, make_transform, pinhole_intrinsics
from laserpick.types import DepthFrame

#: MuJoCo camera frame (looks along -z, +y up) to the OpenCV optical frame (z forward, y down).
CAM_TO_OPTICAL = np.diag([1.0, -1.0, -1.0])


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
        self._noise = SensorNoise(self.settings.seed)
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
        self._opt_depth = render_option(DEPTH_GEOMGROUP)
        self._opt_labels = render_option(LABEL_GEOMGROUP)
        groups = self._model.geom_group
        self._specular = np.append(groups == GROUP_SPECULAR, False)  # (ngeom + 1,) bool
        self._has_specular = bool(self._specular.any())
        # All cameras share K.
        self._ir = IrShading(self._model, self.K[self.names[0]], self.width, self.height)
        self._render: SegmentationRenderer | None = None
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

    def reseed(self, seed: int | np.random.SeedSequence) -> None:
        """Draw the noise from here on as freshly built cameras seeded with `seed` would."""
        self._noise.reseed(seed)

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

    def _renderer(self) -> SegmentationRenderer:
        me = threading.get_ident()
        if self._render is None:
            self._render = SegmentationRenderer(self._model, self.width, self.height)
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
            depth = noisy_depth(
                z_true, seg, self.settings, self._noise, self._specular, self._has_specular
            )
            ir = self._ir.image(z_true, seg, self._noise, self.settings.ir_noise)
            radius = self.settings.laser_spot_radius_px
            draw_laser_dots(ir, z_true, self.K[name], invert(T_world_cam), hits, radius)
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
