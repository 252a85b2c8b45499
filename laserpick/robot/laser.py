"""The dual laser pointer the seated user holds (paper 004, section 4.3 and 5.2).

Two parallel red beams `dims.LASER_BEAM_SEPARATION` apart. The user aims with one beam lit
("aiming") and lights the second to confirm the selection ("confirmed"). Here the pointer is
a pair of rays from the model site `laser/origin`, which rides on the scooter, so the pointer
is aimed in `base` and moves with the scooter.

Aim: yaw about +z of `base`, measured from +x (positive turns left), and pitch above the
horizontal (positive up), both in radians and clamped to the `dims.LASER_*` limits. The
first beam leaves the origin; the second leaves a point `LASER_BEAM_SEPARATION` to the
beam's left (horizontal, perpendicular to the beam) and runs parallel to it.

What the beams hit: `mujoco.mj_ray` against geom groups 0 (surfaces, opaque objects),
1 (robot) and 3 (specular objects), excluding the scooter body's own shell (the user points
past the tiller and basket, not at them). Group 2 (transparent objects) is ignored on
purpose: a 650 nm beam mostly passes through clear plastic and glass, and the spot a camera
sees is where it lands behind, on the table. The depth sensor does not see group 2 either, so
the spot and the depth it is deprojected with agree. The arm is not excluded: a beam that
hits the arm lands on the arm.

Plain state, no locks: one `LaserPointer` lives on the simulation thread.
"""

from __future__ import annotations

import dataclasses
import math
import threading
from dataclasses import dataclass

import mujoco
import numpy as np

from laserpick.description import dims
from laserpick.robot.model import LASER_SITE, SCOOTER_BODY
from laserpick.robot.objects import GROUP_OPAQUE, GROUP_ROBOT, GROUP_SPECULAR

#: Geom groups a beam can land on (0, 1, 3); group 2, transparent, lets the beam through.
LASER_GEOMGROUP = np.array(
    [int(g in (GROUP_OPAQUE, GROUP_ROBOT, GROUP_SPECULAR)) for g in range(6)], dtype=np.uint8
)


@dataclass(frozen=True)
class LaserState:
    """What the pointer is doing: lit or not, one beam or two, and where it points (rad)."""

    on: bool
    confirmed: bool  #: both beams lit; implies `on`
    yaw: float  #: rad about +z of `base`, from +x, positive left
    pitch: float  #: rad above the horizontal, positive up


@dataclass(frozen=True)
class LaserHit:
    """Where one beam landed: world point (m), its `base` point (m), and the geom it hit.

    The geom id is simulator ground truth: for bench/ and tests, never for the pipeline.
    """

    point_world: np.ndarray
    point_base: np.ndarray
    geom: int
    distance: float  #: m from the beam's origin


def _clamp(x: float, lo: float, hi: float) -> float:
    return min(max(float(x), lo), hi)


def _finite(**values: float) -> None:
    for name, v in values.items():
        if not math.isfinite(float(v)):
            raise ValueError(f"laser {name} must be a finite number, got {v!r}")


class LaserPointer:
    """The simulated dual laser pointer. Starts off, pointing straight ahead and level.

    Safe to aim from one thread while another casts: the state is one immutable `LaserState`,
    swapped whole under a lock, and every reader works from one snapshot of it.
    """

    def __init__(self, model: mujoco.MjModel) -> None:
        self._site = model.site(LASER_SITE).id
        self._body = model.body(SCOOTER_BODY).id
        if model.site_bodyid[self._site] != self._body:
            raise ValueError(f"site {LASER_SITE!r} must be fixed to body {SCOOTER_BODY!r}")
        # The site is a direct child of the scooter body, so its local position is in `base`.
        self._origin_base = np.array(model.site_pos[self._site], dtype=float)
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

    def beams(self, data: mujoco.MjData) -> list[tuple[np.ndarray, np.ndarray]]:
        """(origin m, unit direction) in `world` of each lit beam, at the scooter's pose in data.

        Needs `data.xpos`/`data.xmat` current (after `mj_kinematics` or `mj_forward`).
        """
        R = data.xmat[self._body].reshape(3, 3)
        p = data.xpos[self._body]
        return [(p + R @ o, R @ d) for o, d in self.beams_base()]

    def cast_hits(self, model: mujoco.MjModel, data: mujoco.MjData) -> list[LaserHit | None]:
        """Ray-cast each lit beam; a `LaserHit` per beam, None if nothing within range."""
        R = data.xmat[self._body].reshape(3, 3)
        p = data.xpos[self._body]
        geomid = np.array([-1], dtype=np.int32)
        out: list[LaserHit | None] = []
        for origin, direction in self.beams(data):
            dist = mujoco.mj_ray(
                model,
                data,
                origin,
                direction,
                LASER_GEOMGROUP,
                True,  # static geoms too: tables and shelves are static
                self._body,
                geomid,
            )
            if dist < 0 or dist > dims.LASER_MAX_RANGE:
                out.append(None)
                continue
            hit = origin + dist * direction
            out.append(LaserHit(hit, R.T @ (hit - p), int(geomid[0]), float(dist)))
        return out

    def cast(self, model: mujoco.MjModel, data: mujoco.MjData) -> list[np.ndarray | None]:
        """World hit point (m) of each lit beam, None where nothing lies within
        `dims.LASER_MAX_RANGE`. Needs the kinematics in `data` current."""
        return [None if h is None else h.point_world for h in self.cast_hits(model, data)]
