"""The session's dead-man (`server/session/watchdog.py`): the deadline it hands the robot's
controller, and the halt when the lease holder goes silent."""

from __future__ import annotations

import time

import numpy as np

from laserpick.robot.sim.robot import SimRobot
from laserpick.robot.sim.scenes import load_scene
from laserpick.server.session import Actor, Session
from laserpick.server.session.watchdog import SILENT_REASON


def test_the_dead_man_is_handed_over_again_only_when_the_holder_is_heard_again() -> None:
    """While a drive runs and its holder says nothing, the controller keeps the one deadline
    it was handed: the watchdog's tick posts nothing to the sim thread until the holder is
    heard from again."""
    session = Session(SimRobot(load_scene("isolation", seed=1), realtime=True))
    pushed: list[float | None] = []
    arm = session.robot.deadman

    def recording(until: float | None) -> None:
        pushed.append(until)
        arm(until)

    session.robot.deadman = recording  # type: ignore[method-assign]
    try:
        actor = Actor("console", session.lease.acquire("test", "console"))
        session.drive(actor, 0.2, 0.0, 0.5)
        time.sleep(0.3)  # 15 watchdog ticks, short of the 0.5 s of silence that halts
        armed = [u for u in pushed if u is not None]
        assert len(armed) == 1, armed
        session.lease.heartbeat(actor.token)
        time.sleep(0.1)
        assert len([u for u in pushed if u is not None]) == 2, pushed
    finally:
        session.close()


def test_the_dead_man_is_reckoned_from_the_last_sign_of_life_never_from_now() -> None:
    """While a lease holder's drive runs, every deadline the watchdog hands the controller
    is at most `watchdog_s` after the holder was last heard, so a watchdog running late
    never puts the halt off; silence past it halts the base and says why."""
    session = Session(SimRobot(load_scene("isolation", seed=1), realtime=True))
    pushed: list[tuple[float, float | None]] = []
    arm = session.robot.deadman

    def recording(until: float | None) -> None:
        pushed.append((time.monotonic(), until))
        arm(until)

    session.robot.deadman = recording  # type: ignore[method-assign]
    try:
        actor = Actor("console", session.lease.acquire("test", "console"))
        heard = time.monotonic()
        for _ in range(3):  # drive on for 0.9 s, heard only at the start
            session.drive(actor, 0.2, 0.0, 0.3)
            time.sleep(0.3)
        limit = session.settings.server.watchdog_s
        # A deadline ahead of when it was handed over (not a halt's "trip now").
        ahead = [u for t, u in pushed if u is not None and u > t]
        assert ahead, "the watchdog never armed the controller"
        assert max(ahead) <= heard + limit + 0.005
        assert session.message == "The controller went silent: motion halted."
        assert np.max(np.abs(session.robot.state().base_velocity)) < 0.01
    finally:
        session.close()


def test_the_watchdog_says_why_before_it_halts_the_job() -> None:
    """A job whose motion the watchdog halts sees the halt at once and winds down with
    whatever reason it then reads: the reason and the cancel are set before the arm is
    halted, never after (the job would report the bare "halted")."""
    session = Session(SimRobot(load_scene("isolation", seed=1), realtime=True))
    seen: list[tuple[bool, str]] = []
    halt = session.robot.halt

    def recording() -> None:
        seen.append((session._cancel.is_set(), session._cancel_reason))
        halt()

    session.robot.halt = recording  # type: ignore[method-assign]
    try:
        actor = Actor("console", session.lease.acquire("test", "console"))
        session._start(actor, "motion", lambda: session._cancel.wait(5.0), motion=True)
        end = time.monotonic() + 5.0
        while not seen and time.monotonic() < end:
            time.sleep(0.05)
        assert seen == [(True, SILENT_REASON)]
    finally:
        session.close()
