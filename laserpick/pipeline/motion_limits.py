"""The motion's limits, set in one place (`MotionSettings`), and a joint path timed within
them (`timing`).

Units: rad, s, m.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from laserpick.pipeline.smoothing import ClearFn
from laserpick.pipeline.timing import Limits, time_parametrize
from laserpick.settings import MotionSettings
from laserpick.types import Trajectory

__all__ = ["motion_limits", "timed"]


def motion_limits(
    s: MotionSettings, *, carrying: bool = False, tcp_speed: float | None = None
) -> Limits:
    """The limits every move the arm runs keeps, from `s`: the joint speed, acceleration and
    jerk, the TCP speed cap near people, lowered to `tcp_speed` (m/s) where given (the
    approach, the lift; never raised), and while `carrying` the hand's turning cap
    (`carry_turn_speed`)."""
    return Limits(
        speed=s.joint_speed,
        accel=s.joint_accel,
        jerk=s.joint_jerk,
        tcp_speed=min(tcp_speed or s.tcp_speed, s.tcp_speed),
        turn_speed=s.carry_turn_speed if carrying else None,
    )


def timed(
    path: np.ndarray,
    s: MotionSettings,
    *,
    tcp_speed: float | None = None,
    carrying: bool = False,
    gripper: tuple[tuple[int, str], ...] = (),
    clear: Sequence[ClearFn | None] | ClearFn | None = None,
) -> Trajectory:
    """Time-parametrize a joint path within the motion limits of `s` (`motion_limits`,
    `timing`): its corners blended, within `blend_tolerance` of the path, or
    `blend_checked` where the legs' collision checks `clear` (one for all legs, or one per
    leg) pass the blend."""
    return time_parametrize(
        path,
        limits=motion_limits(s, carrying=carrying, tcp_speed=tcp_speed),
        tolerance=s.blend_tolerance,
        checked_tolerance=s.blend_checked,
        clear=clear,
        gripper=gripper,
    )
