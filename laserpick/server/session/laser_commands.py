"""The laser's commands: aim by angles, at a point or along a click's ray, nudge, turn off,
and confirm (mark the object, or where a held object goes), which starts the jobs.

Frames: points in `base` (m) unless `frame` says `world`; angles in radians.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from laserpick.server.session.foresight import Foresight
from laserpick.server.session.states import AIMABLE, HOLDING_STATES, Actor, TaskState


class LaserCommands(Foresight):
    """Aiming and confirming the mark."""

    def _after_aim(self) -> None:
        """Aiming: a new target drops what was found for the old one."""
        if self.state in HOLDING_STATES:
            self._set(TaskState.AWAITING_PLACE, "Mark where to put it, then confirm.")
        elif self.state != TaskState.AIMING:
            self._forget_task()
            self._set(TaskState.AIMING, "Aim at the object, then confirm.")

    def aim(self, actor: Actor, yaw: float, pitch: float) -> None:
        """Point the laser at (yaw, pitch) rad in `base` (clamped to the pointer's limits)."""
        with self._lock:
            self._require(actor, "laser/aim", AIMABLE)
            self.robot.laser.aim(yaw, pitch)
            self._after_aim()
            self._record(actor, "laser/aim", "ok")

    def aim_at(
        self,
        actor: Actor,
        point: np.ndarray,
        frame: Literal["base", "world"],
        *,
        foresee: bool = False,
    ) -> None:
        """Point the laser at a point (m) in `base` or `world`. foresee: aimed at an object
        by a click, work out the mark there at once (`foresight`): a confirm at this very
        point then finds it done."""
        p = self._to_base(np.asarray(point, dtype=float), frame)
        reach = self.settings.server.max_reach
        if np.linalg.norm(p[:2]) > reach:
            raise ValueError(
                f"point is {np.linalg.norm(p[:2]):.1f} m from the scooter; the laser is aimed"
                f" within {reach:.0f} m"
            )
        with self._lock:
            self._require(actor, "laser/aim", AIMABLE)
            self.robot.laser.aim_at(p)
            self._after_aim()
            self._record(actor, "laser/aim", "ok")
            if foresee and self.state == TaskState.AIMING:
                self._foresee(p)

    def aim_ray(
        self,
        actor: Actor,
        origin: np.ndarray,
        direction: np.ndarray,
        frame: Literal["base", "world"],
    ) -> np.ndarray:
        """Point the laser where a ray (a click in the 3D view) first meets the fused cloud,
        foreseeing the mark there (`aim_at`); the hit point in `base` (m). ValueError when
        the ray misses everything."""
        hit = self.ray_point(origin, direction, frame)
        self.aim_at(actor, hit, "base", foresee=True)
        return hit

    def nudge(self, actor: Actor, dyaw: float, dpitch: float) -> None:
        """Turn the laser by small steps (rad), as a joystick or switch does."""
        with self._lock:
            self._require(actor, "laser/nudge", AIMABLE)
            self.robot.laser.nudge(dyaw, dpitch)
            self._after_aim()
            self._record(actor, "laser/nudge", "ok")

    def laser_off(self, actor: Actor) -> None:
        with self._lock:
            self._require(actor, "laser/off", AIMABLE)
            self.robot.laser.off()
            if self.state == TaskState.AIMING:
                self._set(TaskState.IDLE, "Laser off.")
            self._record(actor, "laser/off", "ok")

    def confirm(self, actor: Actor, point: np.ndarray | None = None) -> None:
        """Light both beams: mark the object (then perceive and find grasps), or, holding an
        object in pick-and-place, mark where it goes (then place it).

        point: where a confirming click landed (m, `base`). The mark is then that point, as
        from a touch screen, and not the dots found in a new capture."""
        with self._lock:
            self._require(actor, "laser/confirm", (TaskState.AIMING, TaskState.AWAITING_PLACE))
            if not self.robot.laser.state.on:
                raise self._refuse(actor, "laser/confirm", "the laser is off; aim it first")
            self.robot.laser.confirm()
            self._record(actor, "laser/confirm", "ok")
            if self.state == TaskState.AWAITING_PLACE:
                self._require_motion(actor, "laser/confirm")
                self._start(actor, "placing", self._place_job, motion=True)
            else:
                if self.strategy == "jeeves":
                    self._require_motion(actor, "laser/confirm")
                self._set(TaskState.MARKED, "Marked. Looking at the object.")
                seen = self._foreseen
                if point is not None and seen is not None and seen.of(self._capture, point):
                    # Worked out since the aim, and the job will take this same result:
                    # the projector lights the target now, not after the job's first step.
                    self._projection = seen.lit
                job = self._perceive_job if point is None else lambda: self._perceive_job(point)
                self._start(actor, "perceiving", job, motion=self.strategy == "jeeves")

    def detect(self, actor: Actor) -> None:
        """Find grasps again for the perceived target (e.g. after changing the strategy)."""
        with self._lock:
            self._require(actor, "detect", (TaskState.PERCEIVED, TaskState.GRASPS_READY))
            if self.strategy == "jeeves":
                self._require_motion(actor, "detect")
            self._set(TaskState.PERCEIVED, "Finding grasps.")
            self._start(actor, "detecting", self._grasp_job, motion=self.strategy == "jeeves")
