"""What a recording holds in memory, its format's constants, and the error a bad one raises."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from laserpick.robot.interface import GripperState, JointState
from laserpick.robot.pointer import LaserState
from laserpick.types import DepthFrame, Projector

FORMAT = "laserpick-recording"
VERSION = 1
META = "meta.json"
#: The units every value is in; a recording that states others is refused.
UNITS = {"length": "m", "angle": "rad", "time": "s", "force": "N", "depth": "m", "ir": "uint8"}
#: The frame every pose and point is in.
FRAME = "base: x forward, y left, z up, origin on the floor under the rear axle"


class RecordingError(ValueError):
    """A recording that cannot be read or written: names the directory, and per problem where
    (a meta.json field path such as `captures[0].frames.left_25.K`, or a file such as
    `capture-000/left_25.depth.npy`) and what is wrong."""

    def __init__(self, directory: str, problems: list[tuple[str, str]]) -> None:
        self.directory = directory
        self.problems = problems
        text = "; ".join(f"{where}: {what}" if where else what for where, what in problems)
        super().__init__(f"recording {directory}: {text}")

    def __reduce__(self) -> tuple[type[RecordingError], tuple[str, list[tuple[str, str]]]]:
        return RecordingError, (self.directory, self.problems)  # crosses processes intact


@dataclass(frozen=True)
class Hint:
    """For tests only: where a named object's top was when recording (simulator truth, m in
    `base`). The pipeline and the session never read it; a test aims there as an operator
    would."""

    object: str
    top_base: np.ndarray


@dataclass(frozen=True)
class RecordedCapture:
    """One capture: every camera's frame, and the robot's state when it was taken.

    base_pose: odometry (x, y, yaw) in m and rad. stamp: robot time (s). laser: the pointer's
    aim then (its dots show in the IR images), or None if the recording does not say.
    """

    frames: tuple[DepthFrame, ...]
    joints: JointState
    gripper: GripperState
    base_pose: np.ndarray
    stamp: float
    laser: LaserState | None = None
    hint: Hint | None = None


@dataclass(frozen=True)
class Recording:
    """Captures in sequence, the projector's calibration (if recorded), and where they came
    from (free text)."""

    captures: tuple[RecordedCapture, ...]
    projector: Projector | None = None
    source: str = ""

    @property
    def cameras(self) -> tuple[str, ...]:
        """The camera names, in frame order (the same in every capture)."""
        return tuple(f.camera for f in self.captures[0].frames) if self.captures else ()


def capture_dir(index: int) -> str:
    """The directory of capture `index` (0-based) inside a recording: `capture-000`, ..."""
    return f"capture-{index:03d}"
