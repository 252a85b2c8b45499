"""The watchdog: halts motion commanded by a lease holder who goes silent (no heartbeat for
`ServerSettings.watchdog_s`, or its websocket dropped), on a thread of its own.

Times are `time.monotonic()` seconds.
"""

from __future__ import annotations

import threading
import time

from laserpick.server.session.core import SessionCore
from laserpick.server.session.states import SYSTEM

#: The watchdog's period (s), and the gap between its ticks that means the process stalled.
WATCHDOG_TICK, WATCHDOG_STALL = 0.02, 0.1
#: Longest the API's event loop may lag (s) before the watchdog judges silence regardless.
IO_STALL_MAX = 2.0


class Watchdog(SessionCore):
    """The dead-man on motion commanded through the API."""

    def _init_watchdog(self) -> None:
        self._io_alive: float | None = None  #: monotonic time of the API loop's last tick

    def _start_watchdog(self) -> None:
        self._closing = threading.Event()
        self._watchdog = threading.Thread(
            target=self._watch, name="laserpick-watchdog", daemon=True
        )
        self._watchdog.start()

    def _stop_watchdog(self) -> None:
        self._watchdog.join(timeout=1.0)

    def _watch(self) -> None:
        """Halt motion commanded by a lease holder who has gone silent (no heartbeat for
        `watchdog_s`, or its websocket dropped)."""
        limit = self.settings.server.watchdog_s
        last = time.monotonic()
        while not self._closing.wait(WATCHDOG_TICK):
            now = time.monotonic()
            stalled, last = now - last > WATCHDOG_STALL, now
            if stalled:
                # This process itself was not running (a loaded machine): heartbeats that
                # arrived meanwhile are still queued, so silence cannot be judged this tick.
                continue
            io_late = now - self._io_alive if self._io_alive is not None else 0.0
            if WATCHDOG_STALL < io_late < IO_STALL_MAX:
                # The thread that reads the sockets is behind (starved of CPU): heartbeats
                # may be waiting unread. A loop stuck for longer halts the motion all the same.
                continue
            with self._lock:
                token = self._motion_token if self.busy else None
                driving = time.monotonic() < self._drive_until and self._drive_token is not None
                drive_token = self._drive_token if driving else None
            for tok, what in ((token, "motion"), (drive_token, "drive")):
                if tok is None or self.lease.silent_for(tok) <= limit:
                    continue
                self.robot.halt()
                with self._lock:
                    if what == "motion":
                        self._cancel_reason = (
                            "The controller went silent, so the motion was halted."
                        )
                        self._cancel.set()
                        self._motion_token = None
                    self._drive_until = 0.0
                    self.message = "The controller went silent: motion halted."
                    self._emit("watchdog", message=self.message)
                    self._record(SYSTEM, "watchdog", "halted", message=self.message)

    def io_alive(self) -> None:
        """Called by the API's event loop on each of its ticks: it is reading the sockets, so
        a missing heartbeat is the client's silence, not the server's."""
        self._io_alive = time.monotonic()
