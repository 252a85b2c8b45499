"""`laserpick adapter joystick`: a stick that moves the laser like a pan-tilt unit
(`stick.StickAdapter`), or a sip-and-puff switch (`sip_puff.SipPuffAdapter`), after paper
002's plans for people with limited upper-limb mobility and with quadriplegia. This module
holds what both presets share: their options, the stick's dead zone, and rate aiming.

Both presets: after a (re)connection nothing moves until the stick is back in its dead zone,
the drive button is released, and no sip or puff is held.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from laserpick.adapters.connection import Connection

__all__ = ["JoystickOptions", "RateAim", "shaped"]


@dataclass(frozen=True)
class JoystickOptions:
    """dead_zone: fraction of travel read as zero; rate: beam rad/s at full deflection (or
    while a sip or puff is held); speed: m/s and turn: rad/s at full deflection; step: rad
    per sip-and-puff tap; hold: s before a sip or puff moves; double: s between two taps
    that switch mode; update: s between laser nudges while moving."""

    preset: Literal["stick", "sip-puff"] = "stick"
    dead_zone: float = 0.15
    rate: float = 0.4
    speed: float = 0.2
    turn: float = 0.4
    step: float = 0.02
    hold: float = 0.3
    double: float = 0.4
    update: float = 0.1

    def __post_init__(self) -> None:
        if not 0.0 <= self.dead_zone < 1.0:
            raise ValueError("the dead zone must be in [0, 1)")
        for name in ("rate", "speed", "turn", "step", "hold", "double", "update"):
            value = getattr(self, name)
            if not math.isfinite(value) or value <= 0:
                raise ValueError(f"{name} must be a finite number > 0, not {value}")


def shaped(value: float, dead_zone: float) -> float:
    """An axis reading after the dead zone: 0 inside it, rescaled to reach +/-1 at the end."""
    a = abs(value)
    if a <= dead_zone:
        return 0.0
    return math.copysign(min(1.0, (a - dead_zone) / (1.0 - dead_zone)), value)


class RateAim:
    """Integrates a beam rate (rad/s) over time and sends it as nudges every `update` s, so
    the total turn is rate x time whatever the loop's jitter."""

    def __init__(self, link: Connection, update: float) -> None:
        self.link, self.update = link, update
        self.dyaw = self.dpitch = 0.0
        self.sent_at = -math.inf

    def add(self, dyaw: float, dpitch: float) -> None:
        self.dyaw += dyaw
        self.dpitch += dpitch

    def flush(self, t: float, *, force: bool = False) -> None:
        if not force and t - self.sent_at < self.update:
            return
        if self.dyaw or self.dpitch:
            self.link.nudge(self.dyaw, self.dpitch)
        self.dyaw = self.dpitch = 0.0
        self.sent_at = t

    def drop(self) -> None:
        self.dyaw = self.dpitch = 0.0
