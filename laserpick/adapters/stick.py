"""The joystick adapter's "stick" preset. Axes x (right +) and y (forward +), in [-1, 1]; a
dead zone around the centre (`dead_zone`, a fraction of full travel) reads as zero and the
rest is rescaled to [0, 1]. Rate control: the beam turns at `rate` rad/s at full deflection
(stick right: beam right, stick forward: beam up), sent as POST /laser/nudge every `update`
s. Buttons:

    confirm     aiming: POST /laser/confirm; grasps ready or holding: POST /execute (go)
    grasp       the next grasp cluster (grasp_prev: the previous one); switches to manual
    drive       dead-man: while held, the stick drives the base instead (forward: v up to
                `speed` m/s, right: w down to -`turn` rad/s); let go and the base stops
    cancel      POST /cancel
    mode        pick and drop <-> pick and place

After a (re)connection nothing moves until the stick is back in its dead zone and the drive
button is released.
"""

from __future__ import annotations

import math

from laserpick.adapters.announce import Announcer
from laserpick.adapters.commands import confirm_or_go, step_grasp, toggle_mode
from laserpick.adapters.connection import Connection
from laserpick.adapters.joystick import JoystickOptions, RateAim, shaped
from laserpick.adapters.sources import InputEvent

__all__ = ["StickAdapter"]


class StickAdapter:
    """The "stick" preset; see the module docstring."""

    buttons = frozenset({"confirm", "grasp", "grasp_prev", "drive", "cancel", "mode"})
    axes = frozenset({"x", "y"})
    timed_highlight = False  # nothing is scanned

    def __init__(self, options: JoystickOptions, link: Connection, say: Announcer) -> None:
        self.o, self.link, self.say = options, link, say
        self.x = self.y = 0.0
        self.drive_held = False
        self.armed = False
        self.driving = False
        self.told_to_centre = False
        self.t = -math.inf
        self.aim = RateAim(link, options.update)

    def _neutral(self) -> bool:
        dz = self.o.dead_zone
        return shaped(self.x, dz) == 0 and shaped(self.y, dz) == 0 and not self.drive_held

    # --- the runner's interface ----------------------------------------------------------

    def start(self, t: float) -> None:
        self.t = t
        self.say.say("joystick: the stick aims the laser; hold drive to drive")

    def on_input(self, ev: InputEvent) -> None:
        self.advance(ev.t)
        if ev.kind == "axis":
            if ev.name == "x":
                self.x = ev.value
            else:
                self.y = ev.value
            self.aim.flush(ev.t, force=True)  # the exact total up to the change
        elif ev.name == "drive":
            self.drive_held = ev.kind == "press"
            self.aim.flush(ev.t, force=True)
        elif ev.kind == "press":
            self._button(ev.name)
        self._rearm()
        self._update_drive()

    def advance(self, t: float) -> None:
        if t <= self.t:
            return
        dt, self.t = t - self.t, t
        dz = self.o.dead_zone
        if self.armed and not self.drive_held and self.link.connected:
            fx, fy = shaped(self.x, dz), shaped(self.y, dz)
            self.aim.add(-fx * self.o.rate * dt, fy * self.o.rate * dt)
            self.aim.flush(t)
        if self.driving:
            self._update_drive()

    def deadline(self) -> float | None:
        dz = self.o.dead_zone
        moving = shaped(self.x, dz) != 0 or shaped(self.y, dz) != 0
        if self.armed and (moving or self.driving):
            return self.t + self.o.update
        return None

    def on_link(self, connected: bool, t: float) -> None:
        self.advance(t)
        self.aim.drop()
        self.armed = False
        self._stop_driving()
        if connected:
            self._rearm()
            if not self.armed:
                self.say.say("centre the stick and release drive to resume", "centre the stick")
                self.told_to_centre = True

    def highlighted(self) -> tuple[str, float] | None:
        return None

    def shutdown(self, t: float) -> None:
        self.advance(t)
        self.aim.flush(t, force=True)
        self._stop_driving()

    # --- inside ----------------------------------------------------------------------------

    def _rearm(self) -> None:
        if not self.armed and self.link.connected and self._neutral():
            self.armed = True
            self.aim.sent_at = self.t
            if self.told_to_centre:
                self.say.say("stick centred: ready", "ready")
                self.told_to_centre = False

    def _button(self, name: str) -> None:
        link = self.link
        if name == "confirm":
            link.call("confirm", confirm_or_go)
        elif name in ("grasp", "grasp_prev"):
            link.call(
                "next grasp" if name == "grasp" else "previous grasp",
                step_grasp(+1 if name == "grasp" else -1),
            )
        elif name == "cancel":
            link.post("cancel", "/cancel")
        elif name == "mode":
            link.call("mode", toggle_mode)

    def _update_drive(self) -> None:
        dz = self.o.dead_zone
        if not (self.armed and self.drive_held):
            self._stop_driving()
            return
        v = shaped(self.y, dz) * self.o.speed + 0.0  # + 0.0: no "-0.00" in messages
        w = -shaped(self.x, dz) * self.o.turn + 0.0
        if v == 0 and w == 0:
            self._stop_driving()
            return
        if not self.driving:
            self.say.say(f"driving: v {v:+.2f} m/s, w {w:+.2f} rad/s", "driving")
            self.driving = True
        self.link.drive(v, w)

    def _stop_driving(self) -> None:
        if self.driving:
            self.say.say("stop driving", "stop")
            self.driving = False
        self.link.stop_drive()
