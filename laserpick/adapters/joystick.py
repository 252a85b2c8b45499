"""`laserpick adapter joystick`: a stick that moves the laser like a pan-tilt unit, or a
sip-and-puff switch (paper 002's plans for people with limited upper-limb mobility and with
quadriplegia).

Preset "stick". Axes x (right +) and y (forward +), in [-1, 1]; a dead zone around the centre
(`dead_zone`, a fraction of full travel) reads as zero and the rest is rescaled to [0, 1].
Rate control: the beam turns at `rate` rad/s at full deflection (stick right: beam right,
stick forward: beam up), sent as POST /laser/nudge every `update` s. Buttons:

    confirm     aiming: POST /laser/confirm; grasps ready or holding: POST /execute (go)
    grasp       the next grasp cluster (grasp_prev: the previous one); switches to manual
    drive       dead-man: while held, the stick drives the base instead (forward: v up to
                `speed` m/s, right: w down to -`turn` rad/s); let go and the base stops
    cancel      POST /cancel
    mode        pick and drop <-> pick and place

Preset "sip-puff". Four switch channels: hard_puff, soft_puff, soft_sip, hard_sip. A sip or
puff held longer than `hold` s acts for as long as it lasts; a shorter one is a tap, and two
taps within `double` s switch the adapter's mode (aim -> grasp -> drive -> task -> aim):

    mode    hard puff        hard sip         soft sip           soft puff
    aim     beam up          beam down        beam left          beam right   (taps: a `step`)
    drive   forward          reverse          turn left          turn right   (held only)
    grasp   confirm / go     cancel           previous grasp     next grasp   (taps)
    task    pick and drop    manual grasp     automatic grasp    pick and place (taps)

This is the usual powered-wheelchair mapping (hard puff forward, hard sip reverse, soft sip
left, soft puff right), carried over to the laser in aim mode. A single tap acts once the
`double` window has passed without a second one.

Both presets: after a (re)connection nothing moves until the stick is back in its dead zone,
the drive button is released, and no sip or puff is held.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from laserpick.adapters.announce import Announcer
from laserpick.adapters.commands import MODE_BODIES, confirm_or_go, step_grasp, toggle_mode
from laserpick.adapters.connection import Connection
from laserpick.adapters.sources import InputEvent


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


# --- sip and puff ------------------------------------------------------------------------------

CHANNELS = ("hard_puff", "soft_puff", "soft_sip", "hard_sip")
MODES = ("aim", "grasp", "drive", "task")
#: (dyaw, dpitch) directions in aim mode; (v, w) signs in drive mode.
AIM_DIR = {"hard_puff": (0, 1), "hard_sip": (0, -1), "soft_sip": (1, 0), "soft_puff": (-1, 0)}
DRIVE_DIR = {"hard_puff": (1, 0), "hard_sip": (-1, 0), "soft_sip": (0, 1), "soft_puff": (0, -1)}
MODE_HELP = {
    "aim": "hard puff up, hard sip down, soft sip left, soft puff right",
    "grasp": "hard puff confirm or go, soft puff next, soft sip previous, hard sip cancel",
    "drive": "hold: hard puff forward, hard sip reverse, soft sip left, soft puff right",
    "task": "hard puff pick and drop, soft puff pick and place, soft sip automatic, "
    "hard sip manual",
}
TASK_TAPS = {
    "hard_puff": "mode_drop",
    "soft_puff": "mode_place",
    "soft_sip": "select_auto",
    "hard_sip": "select_manual",
}


@dataclass
class _Down:
    t: float
    consumed: bool = False  #: part of a double, or held over a reconnection: does nothing


class SipPuffAdapter:
    """The "sip-puff" preset; see the module docstring."""

    buttons = frozenset(CHANNELS)
    axes: frozenset[str] = frozenset()
    timed_highlight = False  # nothing is scanned

    def __init__(self, options: JoystickOptions, link: Connection, say: Announcer) -> None:
        self.o, self.link, self.say = options, link, say
        self.mode = "aim"
        self.down: dict[str, _Down] = {}
        self.tap: tuple[str, float] | None = None  #: a tap waiting for a possible second
        self.moving: tuple[str, float] | None = None  #: channel and since when it acts
        self.t = -math.inf
        self.aim = RateAim(link, options.update)

    def start(self, t: float) -> None:
        self.t = t
        self.say.say(f"sip and puff, mode aim: {MODE_HELP['aim']}", "aim")

    def on_input(self, ev: InputEvent) -> None:
        if ev.kind == "axis":
            return
        self.advance(ev.t)
        t = max(ev.t, self.t)
        if ev.kind == "press":
            if ev.name in self.down:
                return
            if self.tap is not None and t - self.tap[1] <= self.o.double:
                self.tap = None
                self.down[ev.name] = _Down(t, consumed=True)
                self._switch_mode()
            else:
                self.down[ev.name] = _Down(t)
            return
        d = self.down.pop(ev.name, None)
        if d is None or d.consumed:
            return
        if self.moving is not None and self.moving[0] == ev.name:
            self._stop_moving(t)
        elif self.mode in ("grasp", "task") or t - d.t < self.o.hold:
            self.tap = (ev.name, t)

    def advance(self, t: float) -> None:
        if t < self.t:
            return
        if self.tap is not None and t >= self.tap[1] + self.o.double:
            channel, at = self.tap
            self.tap = None
            self._integrate(at + self.o.double)
            self._single_tap(channel)
        if self.moving is None and self.mode in ("aim", "drive"):
            for channel, d in self.down.items():
                if not d.consumed and t >= d.t + self.o.hold:
                    self._start_moving(channel, d.t + self.o.hold)
                    break
        self._integrate(t)

    def _integrate(self, t: float) -> None:
        if t <= self.t:
            return
        dt, self.t = t - self.t, t
        if self.moving is None:
            return
        if self.mode == "aim":
            ky, kp = AIM_DIR[self.moving[0]]
            self.aim.add(ky * self.o.rate * dt, kp * self.o.rate * dt)
            self.aim.flush(t)
        else:
            kv, kw = DRIVE_DIR[self.moving[0]]
            self.link.drive(kv * self.o.speed, kw * self.o.turn)

    def deadline(self) -> float | None:
        times = []
        if self.tap is not None:
            times.append(self.tap[1] + self.o.double)
        if self.moving is not None:
            times.append(self.t + self.o.update)
        elif self.mode in ("aim", "drive"):
            times += [d.t + self.o.hold for d in self.down.values() if not d.consumed]
        return min(times) if times else None

    def on_link(self, connected: bool, t: float) -> None:
        self.advance(t)
        if self.moving is not None:
            self._stop_moving(t)
        self.aim.drop()
        self.tap = None
        for d in self.down.values():
            d.consumed = True  # let go before it acts again

    def highlighted(self) -> tuple[str, float] | None:
        return None

    def shutdown(self, t: float) -> None:
        self.advance(t)
        if self.moving is not None:
            self._stop_moving(t)

    # --- inside ----------------------------------------------------------------------------

    def _switch_mode(self) -> None:
        self.mode = MODES[(MODES.index(self.mode) + 1) % len(MODES)]
        self.say.say(f"mode {self.mode}: {MODE_HELP[self.mode]}", self.mode)

    def _start_moving(self, channel: str, since: float) -> None:
        if not self.link.connected:
            return
        self._integrate(since)
        self.moving = (channel, since)
        self.aim.sent_at = since
        lag = self.t - since  # the loop noticed late: the hold acted from `since` all the same
        if self.mode == "aim" and lag > 0:
            ky, kp = AIM_DIR[channel]
            self.aim.add(ky * self.o.rate * lag, kp * self.o.rate * lag)
        self.say.say(f"{self.mode} {channel.replace('_', ' ')}: moving", channel.split("_")[1])
        if self.mode == "drive":
            kv, kw = DRIVE_DIR[channel]
            self.link.drive(kv * self.o.speed, kw * self.o.turn)

    def _stop_moving(self, t: float) -> None:
        self._integrate(t)
        if self.mode == "aim":
            self.aim.flush(t, force=True)
        else:
            self.link.stop_drive()
        self.say.say(f"{self.mode}: stop", "stop")
        self.moving = None

    def _single_tap(self, channel: str) -> None:
        link, name = self.link, channel.replace("_", " ")
        if self.mode == "aim":
            ky, kp = AIM_DIR[channel]
            self.say.say(f"aim {name}: one step", name)
            link.nudge(ky * self.o.step, kp * self.o.step)
        elif self.mode == "grasp":
            self.say.say(f"grasp {name}", name)
            if channel == "hard_puff":
                link.call("confirm", confirm_or_go)
            elif channel == "hard_sip":
                link.post("cancel", "/cancel")
            else:
                forward = channel == "soft_puff"
                link.call(
                    "next grasp" if forward else "previous grasp", step_grasp(+1 if forward else -1)
                )
        elif self.mode == "task":
            label, body = MODE_BODIES[TASK_TAPS[channel]]
            self.say.say(f"task {name}: {label}", label)
            link.post(label, "/mode", body)
        else:
            self.say.say("drive mode: hold a sip or puff to drive", "hold to drive")
