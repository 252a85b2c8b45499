"""The `Robot` interface: the one seam between laserpick and hardware.

The simulated robot implements it; a driver for a real UR5 on a real scooter would implement
the same methods, and nothing above robot/ would change. Everything it returns is something
real sensors and controllers report: frames, joint state, gripper state, wheel odometry.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from laserpick.pipeline.trajectory import Trajectory
from laserpick.pipeline.types import DepthFrame
from laserpick.robot.sim import PROTECTIVE_STOP, MotionHandle

__all__ = ["PROTECTIVE_STOP", "GripperState", "JointState", "MotionHandle", "Robot"]


@dataclass(frozen=True)
class JointState:
    """UR5 joint angles (rad) and velocities (rad/s) at `stamp` (s)."""

    q: np.ndarray
    qd: np.ndarray
    stamp: float


@dataclass(frozen=True)
class GripperState:
    """Opening between the pads (m), summed pad force (N), and the holding verdict."""

    width: float
    force: float
    closed: bool
    holding: bool


class Robot(Protocol):
    """What laserpick needs from a robot, simulated or real."""

    def capture(self) -> list[DepthFrame]:
        """Depth and IR frames from every depth sensor, with intrinsics and extrinsics."""
        ...

    def joint_state(self) -> JointState: ...

    def gripper_state(self) -> GripperState: ...

    def base_pose(self) -> np.ndarray:
        """Odometry: the scooter's (x, y, yaw) on the floor (m, rad) since start."""
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

    def stop(self) -> None:
        """E-stop: arm and base halt now and stay halted until `reset_stop`."""
        ...

    def reset_stop(self) -> None: ...
