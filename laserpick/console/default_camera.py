"""The 3D view's default camera, placed for the scooter's pose, and where a point appears in it.

Frames and units: the camera is given in `base` (x forward, y left, z up), metres; the view
is in `world`. The field of view is vertical, in radians.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "CAMERA_FOV",
    "CAMERA_LOOK_AT_BASE",
    "CAMERA_POSITION_BASE",
    "base_to_world",
    "default_view_pixel",
]

#: Default camera in `base` (m): behind-left of the scooter and high enough to look over the
#: basket and sensor posts at the workspace in front of it.
CAMERA_POSITION_BASE = (1.95, 1.25, 1.45)
CAMERA_LOOK_AT_BASE = (1.45, -0.25, 0.45)
#: Vertical field of view of the default camera (rad).
CAMERA_FOV = math.radians(50.0)


def base_to_world(base_pose: np.ndarray, p: tuple[float, float, float]) -> np.ndarray:
    """A point given in `base` (m) in `world`, for the scooter at (x, y, yaw) (m, rad)."""
    x, y, yaw = (float(v) for v in base_pose)
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([x + c * p[0] - s * p[1], y + s * p[0] + c * p[1], p[2]])


def default_view_pixel(point_base: np.ndarray, width: float, height: float) -> tuple[float, float]:
    """Where a point (m, `base`) appears in the default camera's view of `width` x `height`
    px (a pinhole with the vertical field of view CAMERA_FOV, as three.js draws it): (x, y)
    px from the top-left. For scripted clicks in tests and benchmarks."""
    eye, at = np.array(CAMERA_POSITION_BASE), np.array(CAMERA_LOOK_AT_BASE)
    forward = (at - eye) / np.linalg.norm(at - eye)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    d = np.asarray(point_base, dtype=float) - eye
    x, y, z = d @ right, d @ up, d @ forward
    t = math.tan(CAMERA_FOV / 2)
    return (0.5 + 0.5 * x / (z * t * width / height)) * width, (0.5 - 0.5 * y / (z * t)) * height
