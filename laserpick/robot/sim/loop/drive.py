"""The scooter's drive in the loop: the commanded (v, w) with its dead-man deadline, the ramp
within the base's acceleration limits, and the stop when driving pushes the still arm into
something."""

from __future__ import annotations

import logging
import math
from collections.abc import Callable

import mujoco
import numpy as np

from laserpick.description import dims
from laserpick.robot.sim.loop.contacts import Contact, contact_report, felt_force
from laserpick.robot.sim.model import ModelInfo

log = logging.getLogger(__name__)

#: What a console says when the scooter stops itself; what the arm met follows.
DRIVE_STOP = "The scooter stopped: driving pushed the arm into something. Drive back to free it"
#: s of driving without being stopped again before that notice is taken down: the stick held
#: against the push stops the scooter every few steps, and the notice must not flicker.
DRIVE_STOP_CLEARS = 0.5


class BaseDrive:
    """The base's drive state, ticked by the sim thread at the control rate.

    `command` is the last (v m/s, w rad/s) asked for, held until `deadline` (sim s); `now` the
    ramped (v, w) the base servos follow. `stop_reason` says why the scooter last stopped
    itself, or was halted, while driving, until it has driven freely for `DRIVE_STOP_CLEARS`;
    "" otherwise.
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, info: ModelInfo) -> None:
        self.model, self.data, self.info = model, data, info
        self.command = np.zeros(2)
        self.deadline = -1.0
        self.now = np.zeros(2)
        self.rest_push = 0.0  # N on the still arm when the current drive began
        self.push_reported = -math.inf  # sim time (s) the last such push was logged
        self.stop_reason = ""
        self.stopped_at = -math.inf  # sim time (s) of that stop

    def drive(self, v: float, w: float, duration: float) -> None:
        """Drive at v (m/s) and w (rad/s) for `duration` s of sim time from now."""
        self.command = np.array([v, w])
        self.deadline = self.data.time + duration

    def tick(self, dt: float, arm_still: bool, arm_contacts: Callable[[], list[Contact]]) -> None:
        """Ramp toward the command (zero past its deadline) over `dt` s and set the base
        servos; while the arm is still (`arm_still`), stop instead where driving pushes it
        (`arm_contacts` gives its contacts) into something."""
        d, info = self.data, self.info
        want = self.command if d.time < self.deadline else np.zeros(2)
        if arm_still and self._pushes_arm(want, arm_contacts):
            return
        if self.stop_reason and want.any() and d.time - self.stopped_at > DRIVE_STOP_CLEARS:
            self.stop_reason = ""
        limits = np.array([dims.BASE_A_MAX, dims.BASE_ALPHA_MAX]) * dt
        self.now = self.now + np.clip(want - self.now, -limits, limits)
        v, w = self.now
        yaw = d.qpos[info.base_qpos[2]]
        d.ctrl[info.base_ctrl] = [v * math.cos(yaw), v * math.sin(yaw), w]

    def _pushes_arm(self, want: np.ndarray, arm_contacts: Callable[[], list[Contact]]) -> bool:
        """Whether the scooter, driving (`want`: the command, m/s and rad/s), pushes the
        still arm or what it holds into something harder than the protective stop's limit,
        or than the push when the base last stood still, if that was more (an arm resting on
        a counter may be driven off it). Then the base stops at once, and the arm keeps its
        setpoint, so a stick held against the push does not bend it back step by step. The
        UR5 feels such a push as it feels a motion pushed back (`contacts.contact_stop`), and
        our system stops the scooter with it: otherwise the arm and what it holds would be
        pressed into a table at hundreds of newtons while the scooter turns away from it."""
        starting = not self.now.any()
        if starting and not want.any():  # standing still: nothing to watch each step
            return False
        contacts = arm_contacts()
        pushed = felt_force(self.model, contacts)
        if starting:  # the push the drive starts from, the base still standing
            self.rest_push = pushed
        if pushed <= max(dims.UR5_PROTECTIVE_STOP_FORCE, self.rest_push):
            return False
        self.stop_reason = f"{DRIVE_STOP} ({contact_report(self.model, contacts, pushed)})."
        if self.data.time - self.push_reported > 1.0:  # once a second, not every step
            log.warning(self.stop_reason)
            self.push_reported = self.data.time
        self.stopped_at = self.data.time
        self.stop()
        return True

    def halted(self, why: str) -> None:
        """Stop the scooter this step for `why` (a controller's halt); a scooter that was
        driving says so in `stop_reason`, which the consoles show: a halt by the dead-man
        while driving otherwise stops it without a word."""
        if self.now.any() or self.data.time < self.deadline:
            self.stop_reason = f"The scooter stopped: {why}."
            self.stopped_at = self.data.time
        self.stop()

    def stop(self) -> None:
        """Stop the scooter this step, and drop the drive command."""
        d, info = self.data, self.info
        d.qvel[info.base_dof] = 0.0
        self.command[:] = 0.0
        self.now[:] = 0.0
        self.deadline = -1.0
        d.ctrl[info.base_ctrl] = 0.0
