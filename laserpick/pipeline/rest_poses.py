"""The poses the arm rests in, and whether it is at one. Joint angles in rad."""

from __future__ import annotations

import numpy as np

from laserpick.description.dims import UR5_HOME_Q, UR5_STANDBY_Q

__all__ = ["READY_TOLERANCE", "at_pose", "at_rest"]

READY_TOLERANCE = 0.05  #: rad: the arm counts as at the ready (or stowed) pose within this


def at_pose(q: np.ndarray | None, pose: np.ndarray) -> bool:
    """Whether joint angles q (6,) (rad) are at `pose` (6,), within READY_TOLERANCE."""
    return q is not None and bool(np.max(np.abs(q - pose)) < READY_TOLERANCE)


def at_rest(q: np.ndarray | None) -> bool:
    """Whether joint angles q (6,) (rad) are at a pose the arm rests in between tasks: stowed
    (`UR5_HOME_Q`) or standing by between picks (`UR5_STANDBY_Q`)."""
    return at_pose(q, UR5_HOME_Q) or at_pose(q, UR5_STANDBY_Q)
