"""The joint trajectory type shared by planning (pipeline/) and execution (robot/)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

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

    def sample(self, t: float) -> np.ndarray:
        """Joint angles at time t (s), linearly interpolated and held at the ends."""
        return np.array([np.interp(t, self.times, self.q[:, j]) for j in range(6)])
