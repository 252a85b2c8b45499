"""The dead-man on motion commanded through the API: silence longer than
`ServerSettings.watchdog_s` halts the arm and the base, always.

Two parts, so that neither a silent operator nor a stalled server leaves the arm moving:

- the robot's controller holds a deadline (`Robot.deadman`) and halts arm and base by itself
  when the wall clock passes it;
- this thread, every `WATCHDOG_TICK`, sets that deadline to `watchdog_s` after the lease
  holder's last sign of life (a heartbeat or a command; a dropped websocket is silence from
  then), and once it has passed ends the job with the reason and journals it.

The deadline is reckoned from when the holder was last heard, never from now, so a watchdog
that runs late can only bring the halt forward: a stall of this thread, or of the event loop
that reads the heartbeats, halts the motion too. After a halt the controller refuses motion
until the stopped job has wound down; nothing moves again until the operator commands it.

Times are `time.monotonic()` seconds.
"""

from __future__ import annotations

import threading
import time

from laserpick.server.session.core import SessionCore
from laserpick.server.session.states import SYSTEM

#: The watchdog's period (s): how often it moves the controller's deadline on.
WATCHDOG_TICK = 0.02
#: Why a job ended when its controller was not heard from for `watchdog_s`.
SILENT_REASON = "The controller went silent, so the motion was halted."
#: Why a job ended when the server itself fell behind in hearing its controller.
STALLED_REASON = (
    "The server fell behind in hearing the controller, so the motion was halted to be safe."
)


class Watchdog(SessionCore):
    """The dead-man on motion commanded through the API."""

    def _init_watchdog(self) -> None:
        self._deadline: float | None = None  #: the deadline the controller holds (s)
        self._tripped = False  #: the controller halted; it stays so until the job winds down

    def _start_watchdog(self) -> None:
        self._closing = threading.Event()
        self._watchdog = threading.Thread(
            target=self._watch, name="laserpick-watchdog", daemon=True
        )
        self._watchdog.start()

    def _stop_watchdog(self) -> None:
        self._watchdog.join(timeout=1.0)

    def _watch(self) -> None:
        while not self._closing.wait(WATCHDOG_TICK):
            self._watch_tick(time.monotonic())

    def _watch_tick(self, now: float) -> None:
        """Move the controller's deadline on to the holder's last sign of life plus
        `watchdog_s`; once it has passed, end the motion; disarm when nothing moves. It reads
        the job and the drive without the session's lock, which a command may hold while it
        waits on the robot: a torn reading is read again a tick later."""
        busy = self.busy
        motion = self._motion_token if busy else None
        drive = self._drive_token if now < self._drive_until else None
        if self._tripped:
            if not busy and drive is None:  # the halted job has wound down
                self._disarm()
            return
        tokens = [t for t in (motion, drive) if t is not None]
        if not tokens:
            if self._deadline is not None:
                self._disarm()
            return
        limit = self.settings.server.watchdog_s
        heard = min(self.lease.heard_at(t) for t in tokens)
        if heard + limit <= now:
            self._halt_motion(SILENT_REASON)
        elif self._deadline is not None and self._deadline <= now:
            self._halt_motion(STALLED_REASON)  # heard again, but only after the deadline
        elif heard + limit != self._deadline:  # heard since the last tick: move it on
            self._deadline = heard + limit
            self.robot.deadman(self._deadline)

    def _disarm(self) -> None:
        self.robot.deadman(None)
        self._deadline, self._tripped = None, False

    def _halt_motion(self, reason: str) -> None:
        """Halt arm and base (the controller has, or does now), end the job with `reason`,
        and keep the controller refusing motion until the job has wound down. The reason is
        set before the halt, so that the job, which sees its motion halted at once, reads it;
        the lock, which a command may hold, is taken only after the halt. A job started since
        clears the cancel (`_start`)."""
        busy = self.busy
        if busy:
            self._cancel_reason = reason
            self._cancel.set()
        self.robot.deadman(time.monotonic())
        self.robot.halt()
        self._tripped = True
        with self._lock:
            if busy:
                self._motion_token = None
            self._drive_until = 0.0
            self.message = f"{reason.split(',')[0]}: motion halted."
            self._emit("watchdog", message=self.message)
            self._record(SYSTEM, "watchdog", "halted", message=reason)
