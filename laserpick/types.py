"""The values every room shares: what a robot's sensors and controllers produce, and what the
pipeline hands back. `robot/` and `pipeline/` both import this module and never each other.

Nothing here carries simulator ground truth. Units are SI; points and poses are in `base`
(x forward, y left, z up, origin on the floor under the rear axle) unless a field says otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np

from laserpick.transforms import pinhole_project

__all__ = [
    "DepthFrame",
    "Failure",
    "FailureKind",
    "FusedCloud",
    "Grasp",
    "GraspScores",
    "GripperAction",
    "GripperEvent",
    "LaserMark",
    "MarkState",
    "Projector",
    "SegmentMethod",
    "Segmentation",
    "SupportSurface",
    "Trajectory",
]


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
    """Why a step did not work: a typed kind and one sentence a user can read.

    back_up: how far (m) the scooter should back up, straight, for the arm to do what it
    could not from where it stands, when the robot worked that out (the sentence says so
    too); None otherwise.
    park_left: how far (m) to its left (negative: its right) the scooter should park for
    its cameras to see the way the arm needs, when the robot worked that out (the sentence
    says so too); None otherwise.
    """

    kind: FailureKind
    message: str
    back_up: float | None = None
    park_left: float | None = None

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


@dataclass(frozen=True)
class GraspScores:
    """The five factors of paper 004's grasp objective, eq. 2: C = Cw * Cj * Ca * Cs * Cp.

    Cw: width away from the stroke's ends (eq. 3); Cj: short joint-space reach (eq. 4);
    Ca: top grasps, then side grasps from the front (eq. 5); Cs: near the segmented cloud
    (eq. 6); Cp: near the laser mark (eq. 7). Each lies in [0, 1].
    """

    Cw: float
    Cj: float
    Ca: float
    Cs: float
    Cp: float

    @property
    def total(self) -> float:
        return self.Cw * self.Cj * self.Ca * self.Cs * self.Cp


@dataclass(frozen=True)
class Grasp:
    """A 6-DOF grasp of the parallel gripper.

    pose: (4, 4) TCP pose in `base`. Its columns are the hand axis (x), the closing axis (y,
    between the fingers) and the approach axis (z, from the palm toward the object), as in
    GPD; the TCP lies midway between the pads' centres, pad_depth / 2 behind the fingertips
    (`description.dims.GRIPPER_TCP_OFFSET`).
    width: the object's extent between the fingers (m).
    scores: the selection factors, once scored.
    cluster: index of the position cluster for manual selection (-1 before clustering).
    ik: the chosen joint solution (6,), or None with `ik_failure` saying why.
    pads_centred: whether each pad meets the object along its face, about its middle
    (`pipeline.gpd.antipodal.closing_region`): False for a GPD candidate whose pad meets it only
    toward an edge, offered after the others (`selection.group`).
    """

    pose: np.ndarray
    width: float
    scores: GraspScores | None = None
    cluster: int = -1
    ik: np.ndarray | None = None
    ik_failure: str | None = None
    pads_centred: bool = True

    @property
    def position(self) -> np.ndarray:
        return self.pose[:3, 3]

    @property
    def approach(self) -> np.ndarray:
        return self.pose[:3, 2]

    @property
    def closing(self) -> np.ndarray:
        return self.pose[:3, 1]

    @property
    def axis(self) -> np.ndarray:
        return self.pose[:3, 0]

    def in_hand(self, points: np.ndarray) -> np.ndarray:
        """`points` (N, 3; m, `base`) in this grasp's TCP frame: where they are held."""
        return (points - self.position) @ self.pose[:3, :3]

    @property
    def score(self) -> float:
        return self.scores.total if self.scores is not None else 0.0


GripperAction = Literal["open", "close"]


@dataclass(frozen=True)
class GripperEvent:
    """Open or close the gripper `t` seconds after the trajectory starts."""

    t: float
    action: GripperAction


@dataclass(frozen=True)
class Trajectory:
    """Arm joint positions over time.

    times: (T,) seconds from the start, strictly increasing, times[0] == 0.
    q: (T, 6) joint angles (rad) of the UR5, shoulder_pan .. wrist_3.
    gripper: events fired when the trajectory clock passes their time.
    guard_force: if set, the robot stops the motion (and reports it failed) as soon as the
    contact force on the arm or the gripper exceeds this many newtons: a guarded move.
    """

    times: np.ndarray
    q: np.ndarray
    gripper: tuple[GripperEvent, ...] = field(default_factory=tuple)
    guard_force: float | None = None

    def __post_init__(self) -> None:
        t, q = np.asarray(self.times, float), np.asarray(self.q, float)
        if t.ndim != 1 or q.shape != (len(t), 6) or len(t) < 1:
            raise ValueError(f"trajectory needs times (T,) and q (T, 6); got {t.shape}, {q.shape}")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(q))):
            raise ValueError("trajectory contains non-finite values")
        if self.guard_force is not None and not self.guard_force > 0:
            raise ValueError(f"guard_force must be positive, got {self.guard_force}")
        if abs(t[0]) > 1e-12 or np.any(np.diff(t) <= 0):
            raise ValueError("trajectory times must start at 0 and strictly increase")
        object.__setattr__(self, "times", t)
        object.__setattr__(self, "q", q)

    @property
    def duration(self) -> float:
        return float(self.times[-1])

    def guarded(self, force: float | None) -> Trajectory:
        """This trajectory as a guarded move that stops where the contact force exceeds
        `force` (N; None: unguarded)."""
        return replace(self, guard_force=force)

    def sample(self, t: float) -> np.ndarray:
        """Joint angles at time t (s), linearly interpolated and held at the ends."""
        return np.array([np.interp(t, self.times, self.q[:, j]) for j in range(6)])


#: Nearer than this (m) along the optical axis a point is not drawn: it is behind the lens or
#: too close to light meaningfully.
NEAR = 0.05


@dataclass(frozen=True)
class Projector:
    """A projector as a virtual camera: K (3x3, px), T_base_proj (4x4, optical frame in
    `base`, OpenCV convention), and its image size in pixels."""

    K: np.ndarray
    T_base_proj: np.ndarray
    width: int
    height: int

    def project(self, points_base: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pixel coordinates (N, 2) (u, v) of `points_base` (N, 3) m, and a mask of the points
        in front of the lens (z > NEAR m); coordinates of the others are meaningless."""
        uv, _, front = pinhole_project(points_base, self.K, self.T_base_proj, NEAR)
        return uv, front
