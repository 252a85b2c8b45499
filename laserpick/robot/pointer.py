"""The dual laser pointer's aim (paper 004, sections 4.3 and 5.2), without its hardware.

Two parallel beams `dims.LASER_BEAM_SEPARATION` apart leave `origin_base`, which rides on the
scooter. The user aims with one beam lit ("aiming") and lights the second to confirm
("confirmed"). Aim: yaw about +z of `base`, from +x, positive left; pitch above the horizontal,
positive up; both in radians and clamped to the `dims.LASER_*` limits. The second beam leaves a
point `LASER_BEAM_SEPARATION` to the first beam's left (horizontal, perpendicular to the beam)
and runs parallel to it.

A driver for a real pan-tilt pointer, the simulator and a recorded robot all keep their aim
here; what differs is what the beams land on.
"""

from __future__ import annotations

import dataclasses
import math
import threading
from dataclasses import dataclass

import numpy as np

from laserpick.description import dims

__all__ = ["DualBeamPointer", "LaserState"]


@dataclass(frozen=True)
class LaserState:
    """What the pointer is doing: lit or not, one beam or two, and where it points (rad)."""

    on: bool
    confirmed: bool  #: both beams lit; implies `on`
    yaw: float  #: rad about +z of `base`, from +x, positive left
    pitch: float  #: rad above the horizontal, positive up


def _clamp(x: float, lo: float, hi: float) -> float:
    return min(max(float(x), lo), hi)


def _finite(**values: float) -> None:
    for name, v in values.items():
        if not math.isfinite(float(v)):
            raise ValueError(f"laser {name} must be a finite number, got {v!r}")


class DualBeamPointer:
    """The pointer's aim and beams in `base`. Starts off, pointing straight ahead and level.

    Safe to aim from one thread while another casts: the state is one immutable `LaserState`,
    swapped whole under a lock, and every reader works from one snapshot of it.
    """

    def __init__(self, origin_base: np.ndarray | tuple[float, float, float] = dims.LASER_ORIGIN):
        self._origin_base = np.array(origin_base, dtype=float).reshape(3)
        self._st = LaserState(on=False, confirmed=False, yaw=0.0, pitch=0.0)
        self._lock = threading.Lock()

    # --- state ------------------------------------------------------------------------------

    @property
    def state(self) -> LaserState:
        """A snapshot of the pointer's state."""
        return self._st

    @property
    def origin_base(self) -> np.ndarray:
        """Origin of the first beam in `base` (m)."""
        return self._origin_base.copy()

    def aim(self, yaw: float, pitch: float) -> LaserState:
        """Point the aiming beam at (yaw, pitch) in `base` (rad, clamped); lights it.

        Moving the pointer drops any confirmation: the user re-confirms after re-aiming.
        """
        _finite(yaw=yaw, pitch=pitch)
        with self._lock:
            self._st = self._aimed(yaw, pitch)
            return self._st

    @staticmethod
    def _aimed(yaw: float, pitch: float) -> LaserState:
        return LaserState(
            on=True,
            confirmed=False,
            yaw=_clamp(yaw, -dims.LASER_YAW_LIMIT, dims.LASER_YAW_LIMIT),
            pitch=_clamp(pitch, dims.LASER_PITCH_MIN, dims.LASER_PITCH_MAX),
        )

    def aim_at(self, point_base: np.ndarray) -> LaserState:
        """Aim the first beam at a point in `base` (m), as far as the limits allow."""
        v = np.asarray(point_base, dtype=float).reshape(3) - self._origin_base
        _finite(x=v[0], y=v[1], z=v[2])
        yaw = math.atan2(v[1], v[0])
        pitch = math.atan2(v[2], math.hypot(v[0], v[1]))
        return self.aim(yaw, pitch)

    def nudge(self, dyaw: float, dpitch: float) -> LaserState:
        """Turn the pointer by (dyaw, dpitch) rad from where it points; lights the aiming beam."""
        _finite(dyaw=dyaw, dpitch=dpitch)
        with self._lock:
            self._st = self._aimed(self._st.yaw + dyaw, self._st.pitch + dpitch)
            return self._st

    def confirm(self) -> LaserState:
        """Light the second beam. Does nothing while the pointer is off."""
        with self._lock:
            if self._st.on:
                self._st = dataclasses.replace(self._st, confirmed=True)
            return self._st

    def off(self) -> LaserState:
        """Switch both beams off; the aim is kept."""
        with self._lock:
            self._st = dataclasses.replace(self._st, on=False, confirmed=False)
            return self._st

    # --- geometry ---------------------------------------------------------------------------

    def direction_base(self, st: LaserState | None = None) -> np.ndarray:
        """Unit direction of both beams in `base` (for `st`, default the current state)."""
        st = st or self._st
        cp = math.cos(st.pitch)
        return np.array([cp * math.cos(st.yaw), cp * math.sin(st.yaw), math.sin(st.pitch)])

    def beams_base(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """(origin m, unit direction) in `base` of each lit beam: none, one or two."""
        st = self._st  # one snapshot: another thread may re-aim meanwhile
        if not st.on:
            return []
        d = self.direction_base(st)
        out = [(self._origin_base.copy(), d)]
        if st.confirmed:
            # Horizontal and perpendicular to the beam, to its left; this is well defined even
            # for a beam pointing nearly straight down, since it depends on yaw only.
            left = np.array([-math.sin(st.yaw), math.cos(st.yaw), 0.0])
            out.append((self._origin_base + dims.LASER_BEAM_SEPARATION * left, d.copy()))
        return out
