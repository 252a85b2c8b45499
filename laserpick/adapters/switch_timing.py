"""Switch timing: when a press counts, per switch (`SwitchFilter`), and the scan's timing
settings (`ScanTiming`). Times are s on the adapter's monotonic clock, passed in.

- acceptance time: a press counts once it has been held `accept` s (shorter presses, a tremor
  or a bounce, do nothing);
- release time: presses that start within `release` s of the last release are ignored (a
  contact bouncing as it opens, a second unintended hit).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["ScanTiming", "SwitchFilter"]


@dataclass(frozen=True)
class ScanTiming:
    """period: s per highlighted element (automatic scanning); cycles: passes without an
    activation before falling back (0: never); accept: s a press must be held; release: s
    after a release during which presses are ignored; delay: s between selecting and acting,
    during which an activation undoes the selection."""

    period: float = 1.0
    cycles: int = 3
    accept: float = 0.1
    release: float = 0.1
    delay: float = 0.0

    def __post_init__(self) -> None:
        for name in ("period", "accept", "release", "delay"):
            value = getattr(self, name)
            if not math.isfinite(value) or value < 0:
                raise ValueError(f"{name} must be a finite number of seconds >= 0, not {value}")
        if self.period <= 0:
            raise ValueError("the scan period must be more than 0 s")
        if self.cycles < 0:
            raise ValueError("cycles must be 0 (never stop) or more")


@dataclass
class SwitchFilter:
    """Raw presses and releases of one switch -> activations (see the module docstring)."""

    accept: float
    release: float
    down_at: float | None = None
    active: bool = False  #: the current press has been accepted
    ignored: bool = False  #: the current press started within the release time
    last_release: float = -math.inf

    def press(self, t: float) -> None:
        if self.down_at is not None:
            return  # already down (a repeated report)
        self.down_at, self.active = t, False
        self.ignored = t - self.last_release < self.release

    def up(self, t: float) -> bool:
        """The switch opened at t; True if an accepted press ended."""
        if self.down_at is None:
            return False
        was_active = self.active
        self.down_at, self.active, self.ignored = None, False, False
        self.last_release = t
        return was_active

    def due(self) -> float | None:
        """When the current press will be accepted, if it is still held then."""
        if self.down_at is None or self.active or self.ignored:
            return None
        return self.down_at + self.accept

    def accept_at(self, t: float) -> None:
        self.active = True
