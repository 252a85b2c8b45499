"""The body: the `Robot` seam (`interface`), the pointer's aim, and its implementations.

`robot.sim` is the MuJoCo simulation; nothing outside robot/ imports it but the CLI, the bench
and the tests.
"""

from laserpick.robot.interface import (
    PROTECTIVE_STOP,
    GripperState,
    JointState,
    LaserPointer,
    LaserState,
    MotionHandle,
    MotionStatus,
    Robot,
    RobotState,
)

__all__ = [
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
