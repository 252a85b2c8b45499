"""The joystick adapter's presets on a fake link and a fake clock: the stick's dead zone,
rate aiming and dead-man driving; sip and puff's taps, holds and mode switching; and neither
acting on input held across a reconnection.
"""

from __future__ import annotations

import io
from typing import Any

import numpy as np
import pytest

from laserpick.adapters import (
    Announcer,
    InputEvent,
    JoystickOptions,
    SipPuffAdapter,
    StickAdapter,
    shaped,
)
from laserpick.settings import ServerSettings

#: The server's default largest nudge (rad): the stick's per-tick nudges stay well within it.
MAX_NUDGE = ServerSettings().max_nudge


class FakeLink:
    """Records what an adapter asks of the connection."""

    def __init__(self) -> None:
        self.connected = True
        self.nudges: list[tuple[float, float]] = []
        self.drives: list[tuple[float, float]] = []
        self.stops = 0
        self.calls: list[str] = []

    def nudge(self, dyaw: float, dpitch: float) -> None:
        if self.connected:
            self.nudges.append((dyaw, dpitch))

    def drive(self, v: float, w: float) -> None:
        if self.connected:
            self.drives.append((v, w))

    def stop_drive(self) -> None:
        self.stops += 1

    def call(self, label: str, run: Any) -> bool:
        self.calls.append(label)
        return True

    def post(self, label: str, path: str, body: Any = None) -> bool:
        self.calls.append(label)
        return True

    def total(self) -> tuple[float, float]:
        return tuple(np.sum(self.nudges, axis=0)) if self.nudges else (0.0, 0.0)


def quiet() -> Announcer:
    return Announcer(out=io.StringIO())


def test_dead_zone_reads_zero_then_rescales() -> None:
    assert shaped(0.1, 0.15) == 0.0 and shaped(-0.15, 0.15) == 0.0
    assert shaped(1.0, 0.15) == 1.0 and shaped(-1.0, 0.15) == -1.0
    assert shaped(0.575, 0.15) == pytest.approx(0.5)


def test_stick_rate_control_turns_rate_times_time() -> None:
    link = FakeLink()
    js = StickAdapter(JoystickOptions(rate=0.4, dead_zone=0.1), link, quiet())  # type: ignore[arg-type]
    js.start(0.0)
    js.on_link(True, 0.0)
    js.on_input(InputEvent(1.0, "axis", "y", -0.6))
    t = 1.0
    while t < 3.5:  # the runner's ticks, with jitter
        t += 0.07 + 0.05 * (t % 0.1)
        js.advance(min(t, 3.5))
    js.on_input(InputEvent(3.5, "axis", "y", 0.0))
    js.advance(10.0)
    dyaw, dpitch = link.total()
    assert dyaw == 0.0
    assert dpitch == pytest.approx(-0.4 * (0.5 / 0.9) * 2.5, abs=1e-9)
    assert all(abs(n[1]) <= MAX_NUDGE for n in link.nudges)


def test_stick_drives_only_with_the_dead_man_and_rearms_after_a_reconnect() -> None:
    link = FakeLink()
    js = StickAdapter(JoystickOptions(speed=0.2, turn=0.4), link, quiet())  # type: ignore[arg-type]
    js.start(0.0)
    js.on_link(True, 0.0)
    js.on_input(InputEvent(1.0, "axis", "y", 1.0))
    js.advance(1.5)
    assert link.drives == [] and link.nudges  # no dead-man: the stick aims
    js.on_input(InputEvent(2.0, "press", "drive"))
    js.advance(2.1)
    assert link.drives[-1] == (pytest.approx(0.2), 0.0)
    link.connected = False
    js.on_link(False, 2.5)  # lost: stop, and disarm
    link.connected = True
    link.drives.clear()
    js.on_link(True, 5.0)  # back, with drive and the stick still held
    js.advance(6.0)
    assert link.drives == [] and not js.armed
    js.on_input(InputEvent(6.5, "axis", "y", 0.0))
    js.on_input(InputEvent(6.6, "release", "drive"))
    assert js.armed
    js.on_input(InputEvent(7.0, "press", "drive"))
    js.on_input(InputEvent(7.1, "axis", "x", 1.0))  # right: turn right
    assert link.drives[-1] == (0.0, pytest.approx(-0.4))
    stops = link.stops
    js.on_input(InputEvent(8.0, "release", "drive"))
    assert link.stops > stops


def sip(adapter: SipPuffAdapter, channel: str, t: float, held: float) -> None:
    adapter.advance(t)
    adapter.on_input(InputEvent(t, "press", channel))
    adapter.advance(t + held)
    adapter.on_input(InputEvent(t + held, "release", channel))


def test_sip_and_puff_taps_holds_and_double_activation() -> None:
    link = FakeLink()
    sp = SipPuffAdapter(JoystickOptions(rate=0.4, step=0.02), link, quiet())  # type: ignore[arg-type]
    sp.start(0.0)
    sip(sp, "soft_sip", 1.0, 0.1)  # a tap: one step left, once the double window passes
    sp.advance(1.45)
    assert link.nudges == []
    sp.advance(1.51)
    assert link.total() == (pytest.approx(0.02), 0.0)
    link.nudges.clear()
    sip(sp, "hard_sip", 3.0, 1.3)  # held: down at 0.4 rad/s from 0.3 s in
    assert link.total() == (0.0, pytest.approx(-0.4 * 1.0))
    sip(sp, "hard_puff", 6.0, 0.1)
    sip(sp, "hard_puff", 6.3, 0.1)  # double: aim -> grasp
    assert sp.mode == "grasp"
    sp.advance(8.0)
    assert link.calls == []  # neither puff of the double acted
    sip(sp, "hard_puff", 9.0, 0.8)  # in grasp mode any length is a tap: confirm
    sp.advance(10.5)
    assert link.calls == ["confirm"]
    sip(sp, "soft_puff", 11.0, 0.1)
    sp.advance(12.0)
    assert link.calls[-1] == "next grasp"
    sip(sp, "hard_puff", 13.0, 0.1)
    sip(sp, "hard_puff", 13.3, 0.1)  # -> drive
    assert sp.mode == "drive"
    sip(sp, "hard_puff", 15.0, 1.0)  # held: forward while it lasts
    assert link.drives and all(d == (pytest.approx(0.2), 0.0) for d in link.drives)
    assert link.stops >= 1


def test_sip_and_puff_held_over_a_reconnection_does_nothing() -> None:
    link = FakeLink()
    sp = SipPuffAdapter(JoystickOptions(rate=0.4), link, quiet())  # type: ignore[arg-type]
    sp.start(0.0)
    sp.advance(1.0)
    sp.on_input(InputEvent(1.0, "press", "hard_puff"))
    sp.advance(2.0)
    moved = link.total()[1]
    assert moved == pytest.approx(0.4 * 0.7)
    link.connected = False
    sp.on_link(False, 2.0)
    link.connected = True
    sp.on_link(True, 3.0)
    sp.advance(6.0)
    sp.on_input(InputEvent(6.0, "release", "hard_puff"))
    sp.advance(8.0)
    assert link.total()[1] == pytest.approx(moved)  # nothing after the loss, nor a tap
