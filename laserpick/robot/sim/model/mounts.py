"""The sensors fixed to the scooter: five depth cameras, the projector camera and the laser."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from laserpick.description import dims
from laserpick.robot.sim.model.geoms import quat_list
from laserpick.robot.sim.model.names import LASER_SITE, PROJECTOR_CAMERA
from laserpick.transforms import pinhole_intrinsics, roty, rotz


def camera_rotation(pitch_down: float, yaw: float) -> np.ndarray:
    """Rotation of a MuJoCo camera frame (looks along -z, +y up) in `base`.

    At zero pitch and yaw the camera looks along +x of `base` with its image's up along +z.
    """
    look_forward = np.array([[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    return rotz(yaw) @ roty(pitch_down) @ look_forward


def depth_intrinsics() -> np.ndarray:
    """K (3x3, pixels) of every depth camera, from dims' resolution and vertical field of view."""
    return pinhole_intrinsics(dims.DEPTH_WIDTH, dims.DEPTH_HEIGHT, dims.DEPTH_FOVY)


def add_mounts(body: mujoco.MjsBody) -> None:
    """The five depth cameras, the projector camera and the laser origin, fixed to `body`."""
    for mount in dims.CAMERA_MOUNTS:
        cam = body.add_camera(
            name=mount.name,
            pos=list(mount.pos),
            quat=quat_list(camera_rotation(mount.pitch_down, mount.yaw)),
        )
        cam.fovy = math.degrees(dims.DEPTH_FOVY)
    proj = body.add_camera(
        name=PROJECTOR_CAMERA,
        pos=list(dims.PROJECTOR_POS),
        quat=quat_list(camera_rotation(dims.PROJECTOR_PITCH_DOWN, dims.PROJECTOR_YAW)),
    )
    proj.fovy = math.degrees(dims.PROJECTOR_FOVY)
    body.add_site(name=LASER_SITE, pos=list(dims.LASER_ORIGIN), size=[0.01, 0, 0], group=5)
