"""`RecordedRobot`: a `Robot` that plays a recording (`robot.recording`) and cannot move.

It serves the recorded frames and the robot's recorded state, keeps the laser pointer's aim
(`DualBeamPointer`: its dots are the ones drawn in the recorded IR images, wherever it is
aimed now), accepts every command without moving, and latches the e-stop. It runs the
pipeline on saved captures, a simulator's or a real scooter's sensors', with no simulator
at all: nothing here imports it.
"""

from __future__ import annotations

import os
import threading
import time

import numpy as np

from laserpick.description import dims
from laserpick.robot.interface import GripperState, JointState, MotionHandle, RobotState
from laserpick.robot.pointer import DualBeamPointer
from laserpick.robot.recording import RecordedCapture, Recording, read_recording
from laserpick.transforms import make_transform, pinhole_intrinsics, roty, rotz
from laserpick.types import DepthFrame, Projector, Trajectory

__all__ = ["CANNOT_MOVE", "RecordedRobot", "fallback_projector"]

#: What a motion commanded of a recording reports.
CANNOT_MOVE = "this robot plays a recording and cannot move"


def fallback_projector() -> Projector:
    """The scooter's projector as `description.dims` describes it, for a recording that
    holds no projector calibration: its size, field of view, mounting point and aim."""
    K = pinhole_intrinsics(dims.PROJECTOR_WIDTH, dims.PROJECTOR_HEIGHT, dims.PROJECTOR_FOVY)
    # The OpenCV optical frame at zero pitch and yaw: z along +x of base, x along -y, y down.
    level = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    R = rotz(dims.PROJECTOR_YAW) @ roty(dims.PROJECTOR_PITCH_DOWN) @ level
    T = make_transform(R, np.asarray(dims.PROJECTOR_POS, dtype=float))
    return Projector(K, T, dims.PROJECTOR_WIDTH, dims.PROJECTOR_HEIGHT)


class RecordedRobot:
    """A `Robot` serving a `Recording` (or the directory of one), from capture `start`.

    `capture()` returns the current capture's frames; `use_capture` and `next_capture` step
    through the sequence. Joint, gripper and base state are the current capture's. Motions
    finish at once as failed (`CANNOT_MOVE`); gripper, drive and halt do nothing; stop and
    reset_stop latch and clear the e-stop that `state()` reports.
    """

    #: Robot time runs with the wall clock: `sleep` waits, as on hardware.
    realtime = True

    def __init__(self, recording: Recording | str | os.PathLike, *, start: int = 0) -> None:
        self.recording = (
            recording if isinstance(recording, Recording) else read_recording(recording)
        )
        if not self.recording.captures:
            raise ValueError("the recording holds no capture")
        self.laser = DualBeamPointer()
        self._projector = self.recording.projector or fallback_projector()
        self._lock = threading.Lock()
        self._estopped = False
        self._index = 0
        self.use_capture(start)

    # --- the sequence -------------------------------------------------------------------

    @property
    def index(self) -> int:
        """The current capture (0-based)."""
        return self._index

    def use_capture(self, index: int) -> None:
        """Serve capture `index` (0-based) from now on. IndexError outside the recording."""
        n = len(self.recording.captures)
        if not 0 <= index < n:
            raise IndexError(f"capture {index} is not in the recording (it holds {n})")
        self._index = index

    def next_capture(self) -> int:
        """Serve the next capture (the last stays the last); its index."""
        self.use_capture(min(self._index + 1, len(self.recording.captures) - 1))
        return self._index

    @property
    def current(self) -> RecordedCapture:
        """The capture being served."""
        return self.recording.captures[self._index]

    # --- sensing ------------------------------------------------------------------------

    def capture(self) -> list[DepthFrame]:
        """The current capture's frames (copies: a caller may change them freely)."""
        return [
            DepthFrame(
                f.depth.copy(), f.ir.copy(), f.K.copy(), f.T_base_cam.copy(), f.camera, f.stamp
            )
            for f in self.current.frames
        ]

    def joint_state(self) -> JointState:
        j = self.current.joints
        return JointState(j.q.copy(), j.qd.copy(), j.stamp)

    def gripper_state(self) -> GripperState:
        return self.current.gripper

    def base_pose(self) -> np.ndarray:
        return self.current.base_pose.copy()

    def state(self) -> RobotState:
        cap = self.current
        return RobotState(
            stamp=cap.stamp,
            joints=JointState(cap.joints.q.copy(), cap.joints.qd.copy(), cap.joints.stamp),
            gripper=cap.gripper,
            base_pose=cap.base_pose.copy(),
            base_velocity=np.zeros(2),
            estopped=self._estopped,
            moving=False,
            drive_stop="",
            rtf=1.0,
            read_at=time.time(),
        )

    def projector(self) -> Projector:
        """The recorded projector, or `fallback_projector()` when none was recorded."""
        return self._projector

    # --- acting: accepted, nothing moves ------------------------------------------------

    def execute(self, traj: Trajectory) -> MotionHandle:
        """A handle already failed with `CANNOT_MOVE` (or the e-stop's reason)."""
        handle = MotionHandle("trajectory")
        handle.finish(
            "failed", "e-stop is latched; reset it first" if self._estopped else CANNOT_MOVE
        )
        return handle

    def wait(self, handle: MotionHandle, timeout: float) -> str:
        return handle.wait(timeout)

    def sleep(self, seconds: float) -> None:
        time.sleep(max(0.0, seconds))

    def gripper(self, close: bool) -> None:
        """Does nothing: the recorded gripper stays as recorded."""

    def drive(self, v: float, w: float, duration: float = 0.5) -> None:
        """Does nothing: the recorded base stays where it was."""

    def halt(self) -> None:
        """Does nothing: nothing moves."""

    def deadman(self, until: float | None) -> None:
        """Does nothing: nothing moves, so there is nothing to stop."""

    def stop(self) -> None:
        """Latch the e-stop (reported by `state()` until `reset_stop`)."""
        with self._lock:
            self._estopped = True

    def reset_stop(self) -> None:
        with self._lock:
            self._estopped = False

    def close(self) -> None:
        """Nothing to release: the recording is in memory."""
