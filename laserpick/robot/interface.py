"""The `Robot` interface: the one seam between laserpick and hardware.

The simulated robot (`robot.sim`) and the recorded robot (`robot.recorded`) implement it; a
driver for a real UR5 on a real scooter would implement the same methods, and nothing above
robot/ would change. Everything it returns is something real sensors and controllers report:
frames, joint state, gripper state, wheel odometry, the pointer's aim.

Units are SI (m, rad, s, N); poses and points are in `base` unless a name says `world`.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass
from typing import Literal, Protocol

import numpy as np

from laserpick.robot.pointer import LaserState
from laserpick.types import DepthFrame, Projector, Trajectory

__all__ = [
    "DEADMAN_STOP",
    "PROTECTIVE_STOP",
    "GripperState",
    "JointState",
    "LaserPointer",
    "LaserState",
    "MotionHandle",
    "MotionStatus",
    "Robot",
    "RobotState",
]

MotionStatus = Literal["running", "done", "stopped", "failed"]

#: How a motion's message begins when the arm's controller made a protective stop (it met a
#: force over `dims.UR5_PROTECTIVE_STOP_FORCE`), as a UR controller reports one.
PROTECTIVE_STOP = "protective stop: "
#: The message of a motion the controller's dead-man stopped (`Robot.deadman`), and of the
#: motions it refuses until it is disarmed.
DEADMAN_STOP = "dead-man: no sign of life from the operator in time; motion halted"


class MotionHandle:
    """The outcome of one commanded arm motion, shared between the caller and the controller.

    The robot's controller calls `finish` once; later calls are ignored.
    """

    def __init__(self, kind: str) -> None:
        self.kind = kind
        self.status: MotionStatus = "running"
        self.message = ""
        self._done = threading.Event()

    def finish(self, status: MotionStatus, message: str = "") -> None:
        """End the motion with `status` and a sentence saying why (for stopped or failed)."""
        if self._done.is_set():
            return
        self.status, self.message = status, message
        self._done.set()

    def done(self) -> bool:
        return self._done.is_set()

    def wait(self, timeout: float | None = None) -> MotionStatus:
        """Block until the motion ends (or `timeout` seconds of wall time pass)."""
        self._done.wait(timeout)
        return self.status


@dataclass(frozen=True)
class JointState:
    """UR5 joint angles (rad) and velocities (rad/s) at `stamp` (s)."""

    q: np.ndarray
    qd: np.ndarray
    stamp: float


@dataclass(frozen=True)
class GripperState:
    """Opening between the pads (m), summed pad force (N), the last command (closed), and
    the holding verdict. moving: the fingers are still on their way, as the 2F-85 reports
    it (gOBJ 0): closing, until shut or stopped on something at the grip force; opening,
    until fully open. A gripper that reports no such status leaves it False."""

    width: float
    force: float
    closed: bool
    holding: bool
    moving: bool = False


@dataclass(frozen=True)
class RobotState:
    """One consistent reading of everything the robot reports, for status displays.

    stamp: robot time (s). base_pose: odometry (x, y, yaw) in m and rad since start.
    base_velocity: forward speed (m/s) and turn rate (rad/s). estopped: the e-stop is latched.
    moving: an arm motion is in progress. drive_stop: why the base last stopped itself or was
    halted (the dead-man) while driving, or "".
    rtf: robot seconds per wall second (1.0 for hardware and for a simulator keeping up).
    read_at: wall-clock time (s since the epoch) the reading stands for.
    """

    stamp: float
    joints: JointState
    gripper: GripperState
    base_pose: np.ndarray
    base_velocity: np.ndarray
    estopped: bool
    moving: bool
    drive_stop: str
    rtf: float
    read_at: float


class LaserPointer(Protocol):
    """The dual-beam pointer on the scooter (`robot.pointer.DualBeamPointer` keeps the aim)."""

    @property
    def state(self) -> LaserState: ...

    def aim(self, yaw: float, pitch: float) -> LaserState:
        """Light the aiming beam at (yaw, pitch) rad in `base`, clamped to the pointer's limits."""
        ...

    def aim_at(self, point_base: np.ndarray) -> LaserState: ...

    def nudge(self, dyaw: float, dpitch: float) -> LaserState: ...

    def confirm(self) -> LaserState:
        """Light the second beam (does nothing while off)."""
        ...

    def off(self) -> LaserState: ...

    def beams_base(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """(origin m, unit direction) in `base` of each lit beam."""
        ...


class Robot(Protocol):
    """What laserpick needs from a robot, simulated, recorded or real."""

    laser: LaserPointer
    #: True when robot time runs with the wall clock (hardware, the live simulator); False when
    #: the caller advances it (`wait` and `sleep` step a headless simulator, deterministically).
    realtime: bool

    def capture(self) -> list[DepthFrame]:
        """Depth and IR frames from every depth sensor, with intrinsics and extrinsics."""
        ...

    def joint_state(self) -> JointState: ...

    def gripper_state(self) -> GripperState: ...

    def base_pose(self) -> np.ndarray:
        """Odometry: the scooter's (x, y, yaw) on the floor (m, rad) since start."""
        ...

    def state(self) -> RobotState:
        """Everything above in one consistent reading, with the e-stop and pacing."""
        ...

    def projector(self) -> Projector:
        """The scooter's projector as a virtual camera in `base` (its calibration)."""
        ...

    def execute(self, traj: Trajectory) -> MotionHandle:
        """Start tracking a joint trajectory; the handle reports done, stopped or failed."""
        ...

    def wait(self, handle: MotionHandle, timeout: float) -> str:
        """Block until the motion ends or `timeout` s of robot time pass; its status."""
        ...

    def sleep(self, seconds: float) -> None:
        """Let `seconds` of robot time pass (the gripper closing, an object settling)."""
        ...

    def gripper(self, close: bool) -> None:
        """Close to the force limit, or open fully."""
        ...

    def drive(self, v: float, w: float, duration: float = 0.5) -> None:
        """Drive at v (m/s) and w (rad/s) for at most `duration` s (a dead-man command)."""
        ...

    def halt(self) -> None:
        """Stop the arm and the base now, without latching (a cancelled or overdue motion)."""
        ...

    def deadman(self, until: float | None) -> None:
        """The controller's own dead-man: once `time.monotonic()` passes `until` (s), halt the
        arm and the base and refuse motion until this is called with None. Calls with later
        times keep it from tripping; once tripped it stays tripped. The controller checks it
        itself, at its own rate, so a caller that stalls stops the robot."""
        ...

    def stop(self) -> None:
        """E-stop: arm and base halt now and stay halted until `reset_stop`."""
        ...

    def reset_stop(self) -> None: ...

    def close(self) -> None:
        """Release the hardware (threads, sensors, connections)."""
        ...
