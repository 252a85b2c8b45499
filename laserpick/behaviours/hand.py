"""The gripper as the behaviours use it: how long it takes, and what its pads feel."""

from __future__ import annotations

from laserpick.description import dims
from laserpick.robot.interface import Robot

__all__ = [
    "GRIPPER_TIME",
    "closed_on_something",
    "pad_force",
    "peak_pad_force",
    "wait_for_gripper",
]

#: Time (s) the gripper gets to close or open: the full 85 mm stroke at 0.15 m/s, plus margin.
GRIPPER_TIME = dims.GRIPPER_STROKE / dims.GRIPPER_SPEED + 0.3
#: How often (s) a wait reads the gripper's status: a 2F-85 reports at 50 Hz and more.
GRIPPER_POLL = 0.02


def wait_for_gripper(robot: Robot) -> float:
    """Give the gripper the time to close or open (its last command): until it reports its
    fingers still (`GripperState.moving`), and at most `GRIPPER_TIME`. Returns the robot
    time (s) waited. Letting go of a 6.6 cm can, the hand stands fully open after 0.14 s.
    The pick's close waits the full time instead (`Picking`)."""
    waited = 0.0
    while True:
        robot.sleep(GRIPPER_POLL)
        waited += GRIPPER_POLL
        if not robot.gripper_state().moving or waited >= GRIPPER_TIME - 1e-9:
            return waited


def pad_force(robot: Robot) -> float:
    """What the pads press on (N): the gripper's own sensing, summed over both pads."""
    return robot.gripper_state().force


def peak_pad_force(robot: Robot, seconds: float, period: float) -> float:
    """The most the pads feel (N) over the next `seconds` of robot time, read every `period`
    (s). One reading flickers: a pad pressed against a rail read 0 N, then 0.95 N a tenth
    of a second later."""
    most = pad_force(robot)
    for _ in range(round(seconds / period)):
        robot.sleep(period)
        most = max(most, pad_force(robot))
    return most


def closed_on_something(robot: Robot) -> bool:
    """Whether the closed gripper's fingers stand apart, on something (not on each other)."""
    state = robot.gripper_state()
    return state.closed and state.width > dims.GRIPPER_EMPTY_GAP
