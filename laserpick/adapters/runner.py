"""The adapter's input loop: timed events from a source into a controller (the switch or
joystick adapter), link changes in, and scripted waits honoured.

The controller is told the time (s, `clock()`) of every event and is advanced to "now"
before it sleeps until its next deadline (the next scan step, acceptance, nudge); so all its
timing comes from event times and deadlines, never from how long the loop took.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any, Protocol, TextIO

from laserpick.adapters.announce import Announcer
from laserpick.adapters.connection import Connection
from laserpick.adapters.sources import InputEvent, Quit, Source, Wait

#: s between state polls while a script waits for the server
STATE_POLL = 0.1
#: s the loop sleeps at most with nothing scheduled (a live source wakes it sooner)
IDLE_SLEEP = 0.5
#: s to send what is queued when the script ends
FLUSH_TIMEOUT = 30.0


class Controller(Protocol):
    """An adapter's logic, driven by times in seconds on the runner's clock."""

    buttons: frozenset[str]
    axes: frozenset[str]
    #: whether the highlight moves by itself (automatic scanning), so that a scripted wait
    #: for it means "until it is next highlighted"
    timed_highlight: bool

    def start(self, t: float) -> None: ...
    def on_input(self, ev: InputEvent) -> None: ...
    def advance(self, t: float) -> None: ...
    def deadline(self) -> float | None: ...
    def on_link(self, connected: bool, t: float) -> None: ...
    def highlighted(self) -> tuple[str, float] | None: ...
    def shutdown(self, t: float) -> None: ...


class Runner:
    """Runs until the source ends (a script's end or `quit`, the keyboard's q) or Ctrl-C.
    record: a file to write the input to, in the event-file format (a session to replay)."""

    def __init__(
        self,
        source: Source,
        controller: Controller,
        link: Connection,
        say: Announcer,
        *,
        clock: Callable[[], float] = time.monotonic,
        record: TextIO | None = None,
    ) -> None:
        self.source, self.controller, self.link, self.say = source, controller, link, say
        self.clock = clock
        self.record = record
        self._wake = threading.Condition()
        self._woken = False
        self._waiting: Wait | None = None
        self._ticket: int | None = None
        self._polled_at = -float("inf")
        self._last_state: dict[str, Any] | None = None
        self._t0 = 0.0

    def wake(self) -> None:
        with self._wake:
            self._woken = True
            self._wake.notify_all()

    def _sleep_until(self, deadline: float) -> None:
        with self._wake:
            if not self._woken:
                self._wake.wait(timeout=max(0.0, deadline - self.clock()))
            self._woken = False

    def run(self) -> int:
        """The exit code: 0 when the input ended, 1 when a scripted wait failed, 2 when the
        link cannot work (a refused password, a server that does not state its limits)."""
        t0 = self._t0 = self.clock()
        self.controller.start(t0)
        self.link.start(self.wake)
        self.source.start(self.wake, t0)
        try:
            return self._loop()
        finally:
            self.controller.shutdown(self.clock())
            self.source.close()
            self.link.close()

    def _loop(self) -> int:
        c = self.controller
        while True:
            now = self.clock()
            if self.link.fatal:
                return 2
            for t, connected in self.link.take_notices():
                c.on_link(connected, t)
                (self.source.unpause if connected else self.source.pause)(t)
            if self._waiting is None:
                for ev in self.source.poll(now):
                    c.advance(ev.t)
                    if isinstance(ev, Quit):
                        return self._finish()
                    if isinstance(ev, Wait):
                        self._waiting, self._ticket, self._last_state = ev, None, None
                        self.say.note(f"script: wait {ev.what} {','.join(ev.targets)}")
                        break
                    self._record(ev)
                    c.on_input(ev)
            c.advance(now)
            if self._waiting is not None:
                code = self._check_wait(now)
                if code is not None:
                    return code
                if self._waiting is None:
                    continue  # resumed: what follows may be due already
            if self._waiting is None and self.source.finished:
                return self._finish()
            times = [now + (STATE_POLL if self._waiting else IDLE_SLEEP)]
            times += [x for x in (c.deadline(), self.source.next_due()) if x is not None]
            self._sleep_until(min(times))

    def _check_wait(self, now: float) -> int | None:
        """Resume the script when its wait is satisfied; an exit code if it timed out."""
        w = self._waiting
        assert w is not None
        if w.what == "highlight":
            shown = self.controller.highlighted()
            fresh = shown is not None and (shown[1] >= w.t or not self.controller.timed_highlight)
            if shown is not None and fresh and shown[0] == w.targets[0]:
                self._resume(max(shown[1], w.t), "")
                return None
        else:
            state = self.link.state_for(self._ticket) if self._ticket is not None else None
            if state is not None:
                self._last_state, self._ticket = state, None
                if state["state"] in w.targets and not state["busy"]:
                    self._resume(now, f": {state['message']}")
                    return None
            stale = self._ticket is not None and now - self._polled_at > 5.0  # lost with a link
            if (self._ticket is None and now - self._polled_at >= STATE_POLL) or stale:
                self._ticket, self._polled_at = self.link.request_state(), now
        if now - w.t > w.timeout:
            last = self._last_state
            seen = f"; last state {last['state']!r}: {last['message']}" if last else ""
            self.say.note(
                f"script: gave up waiting for {w.what} {','.join(w.targets)} after "
                f"{w.timeout:g} s{seen}"
            )
            return 1
        return None

    def _resume(self, t: float, detail: str) -> None:
        w = self._waiting
        assert w is not None
        self.say.note(f"script: {w.what} {','.join(w.targets)} reached{detail}")
        self._waiting = None
        self.source.resume(t)

    def _record(self, ev: InputEvent) -> None:
        if self.record is None:
            return
        t = ev.t - self._t0
        if ev.kind == "axis":
            self.record.write(f"{t:.3f} axis {ev.name} {ev.value:.3f}\n")
        else:
            self.record.write(f"{t:.3f} {ev.kind} {ev.name}\n")
        self.record.flush()

    def _finish(self) -> int:
        """The input ended: send what is queued, then stop."""
        end = self.clock() + FLUSH_TIMEOUT
        while self.link.connected and not self.link.flushed() and self.clock() < end:
            self.controller.advance(self.clock())
            self._sleep_until(self.clock() + 0.05)
        self.say.note("input ended")
        return 0


def open_record(path: Path | None) -> TextIO | None:
    """The file `--record` writes to (truncated), with a header comment."""
    if path is None:
        return None
    f = path.open("w", encoding="utf-8")
    f.write("# laserpick adapter input, replay with --source script:FILE\n")
    return f
