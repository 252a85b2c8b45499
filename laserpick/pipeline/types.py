"""Core data types that cross the robot/pipeline seam.

Everything here is what a real robot's sensors could produce: images, intrinsics,
extrinsics, joint state. Nothing here carries simulator ground truth.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class DepthFrame:
    """One depth sensor's frame.

    depth: (H, W) float32 metres along the optical axis, 0 where the sensor read nothing.
    ir: (H, W) uint8 infrared intensity; laser dots show as saturated blobs.
    K: (3, 3) pinhole intrinsics in pixels (OpenCV convention: x right, y down, z forward).
    T_base_cam: (4, 4) pose of the optical frame in `base`.
    camera: the sensor's name, e.g. "left_25".
    stamp: capture time in seconds of simulation (or robot) time.
    """

    depth: np.ndarray
    ir: np.ndarray
    K: np.ndarray
    T_base_cam: np.ndarray
    camera: str
    stamp: float

    @property
    def shape(self) -> tuple[int, int]:
        return self.depth.shape  # type: ignore[return-value]
