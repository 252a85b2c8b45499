"""Arm poses and surfaces shared by the collision-model and planning tests. Frames: `base`
(x forward, y left, z up), metres."""

from __future__ import annotations

import numpy as np

EMPTY = np.zeros((0, 3))  #: no points: a cloud with nothing in it


def top_grasp(x: float, y: float, z: float, yaw: float = 0.0) -> np.ndarray:
    """A TCP pose at (x, y, z) in `base` with the approach straight down."""
    c, s = np.cos(yaw), np.sin(yaw)
    T = np.eye(4)
    T[:3, :3] = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ np.diag([1.0, -1.0, -1.0])
    T[:3, 3] = [x, y, z]
    return T


def table(z: float = 0.46, x=(1.3, 1.9), y=(-0.65, 0.35), step: float = 0.01) -> np.ndarray:
    """A table top's points at height z (m), over x and y (m), every `step` m."""
    xs, ys = np.meshgrid(np.arange(*x, step), np.arange(*y, step))
    return np.c_[xs.ravel(), ys.ravel(), np.full(xs.size, z)]
