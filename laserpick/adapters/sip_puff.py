"""The joystick adapter's "sip-puff" preset. Four switch channels: hard_puff, soft_puff,
soft_sip, hard_sip. A sip or puff held longer than `hold` s acts for as long as it lasts; a
shorter one is a tap, and two taps within `double` s switch the adapter's mode (aim -> grasp
-> drive -> task -> aim):

    mode    hard puff        hard sip         soft sip           soft puff
    aim     beam up          beam down        beam left          beam right   (taps: a `step`)
    drive   forward          reverse          turn left          turn right   (held only)
    grasp   confirm / go     cancel           previous grasp     next grasp   (taps)
    task    pick and drop    manual grasp     automatic grasp    pick and place (taps)

This is the usual powered-wheelchair mapping (hard puff forward, hard sip reverse, soft sip
left, soft puff right), carried over to the laser in aim mode. A single tap acts once the
`double` window has passed without a second one. After a (re)connection nothing moves until
every sip and puff held across it has ended.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from laserpick.adapters.announce import Announcer
from laserpick.adapters.commands import MODE_BODIES, confirm_or_go, step_grasp
from laserpick.adapters.connection import Connection
from laserpick.adapters.joystick import JoystickOptions, RateAim
from laserpick.adapters.sources import InputEvent

__all__ = ["CHANNELS", "MODES", "SipPuffAdapter"]


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
