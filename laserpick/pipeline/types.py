"""Core data types that cross the robot/pipeline seam.

Everything here is what a real robot's sensors could produce: images, intrinsics,
extrinsics, joint state. Nothing here carries simulator ground truth.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

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


FailureKind = Literal[
    "detect_laser", "detect_grasp", "ik_plan", "wrong_object", "execute", "precondition"
]


@dataclass(frozen=True)
class Failure:
    """Why a step did not work: a typed kind and one sentence a user can read."""

    kind: FailureKind
    message: str

    def __str__(self) -> str:
        return self.message


@dataclass(frozen=True)
class FusedCloud:
    """The five sensors' points in `base`.

    points: (N, 3) float32 metres in `base`.
    normals: (N, 3) float32 unit normals, each pointing toward the camera that saw the point.
    camera: (N,) uint8 index into `cameras` of the sensor that saw each point.
    pixel: (N,) int32 flat pixel index (v * W + u) in that sensor's image.
    cameras: sensor names, in frame order.
    """

    points: np.ndarray
    normals: np.ndarray
    camera: np.ndarray
    pixel: np.ndarray
    cameras: tuple[str, ...]

    def __len__(self) -> int:
        return len(self.points)

    def subset(self, index: np.ndarray) -> FusedCloud:
        """The points selected by a boolean mask or an index array."""
        return FusedCloud(
            self.points[index],
            self.normals[index],
            self.camera[index],
            self.pixel[index],
            self.cameras,
        )


MarkState = Literal["aiming", "confirmed"]


@dataclass(frozen=True)
class LaserMark:
    """Where the user points, in `base` (m).

    state: "confirmed" when both beams are seen (or the point came from the API), "aiming"
    while only one beam is on. views: how many sensors agree on the point (0 for a point given
    directly, e.g. from a touch screen or the REST API).
    """

    point: np.ndarray
    state: MarkState
    views: int
    source: Literal["laser", "direct"] = "laser"


SegmentMethod = Literal["cluster", "ball", "merged_radius", "grid"]


@dataclass(frozen=True)
class SupportSurface:
    """The horizontal surface under the target: its top height z (m, in `base`) and plane.

    plane: (a, b, c, d) with a*x + b*y + c*z + d = 0 and (a, b, c) a unit normal pointing up.
    """

    height: float
    plane: np.ndarray


@dataclass(frozen=True)
class Segmentation:
    """The target object's points.

    indices: indices into the FusedCloud of the target's points.
    method: how it was found: the Euclidean cluster at the mark, the fallback ball around the
    mark (cluster too small), the 8 cm radius (segment merged with its support, paper 002), or
    EL-E's occupancy grid.
    surface: the support surface under the mark, when one was found.
    """

    indices: np.ndarray
    method: SegmentMethod
    surface: SupportSurface | None
