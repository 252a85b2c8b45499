"""The control lease: one controlling client at a time, kept alive by heartbeats.

A client takes the lease and gets a random token; it proves itself on every command with
`Authorization: Bearer <token>` and keeps the lease with heartbeats (the events websocket's
`{"type": "heartbeat"}` messages, or `POST /api/v1/control` again with its token). Without a
heartbeat for `timeout` seconds the lease lapses and anyone may take it. Others may watch.

The lease also tells the session's watchdog whether the controller is still there:
`heard_at` is the time of its last sign of life (`silent_for` the time since), and a dropped
controlling websocket counts as silence from that moment (`connection_lost`), so motion
stops at the watchdog's next tick instead of after the heartbeat window.

Times are `time.monotonic()` seconds. Thread-safe.
"""

from __future__ import annotations

import hmac
import math
import secrets
import threading
import time
from dataclasses import dataclass

#: The input source of the operator station: the page and its embedded 3D view.
CONSOLE = "console"


class LeaseHeld(Exception):
    """Someone else holds the lease."""

    def __init__(self, holder: str, expires_in: float) -> None:
        super().__init__(
            f"control is held by {holder!r}; it lapses {expires_in:.1f} s after its last heartbeat"
        )
        self.holder = holder
        self.expires_in = expires_in


@dataclass(frozen=True)
class LeaseInfo:
    """What anyone may know about the lease (never the token)."""

    held: bool
    holder: str | None  #: the name the controller gave, e.g. "switch adapter"
    source: str | None  #: its input source: console, rest, switch, joystick, bench
    silent_for: float  #: s since its last heartbeat (0 when free)


class ControlLease:
    """The lease. `timeout`: seconds without a heartbeat after which it lapses."""

    def __init__(self, timeout: float, clock=time.monotonic) -> None:
        self.timeout = timeout
        self._clock = clock
        self._lock = threading.Lock()
        self._token: str | None = None
        self._holder: str | None = None
        self._source: str | None = None
        self._last = -math.inf
        self._lost = False

    def _lapsed(self, now: float) -> bool:
        return self._token is None or now - self._last > self.timeout

    def acquire(self, holder: str, source: str, token: str | None = None) -> str:
        """Take the lease, or renew it when `token` is the current one. Raises LeaseHeld."""
        with self._lock:
            now = self._clock()
            if token is not None and self._valid(token, now):
                self._last, self._lost = now, False
                return token
            # The page and the 3D view are one operator station: either may take over
            # from the other (a person moving from one to the other, not a second person).
            same_station = source == CONSOLE and self._source == CONSOLE
            if not self._lapsed(now) and not same_station:
                assert self._holder is not None
                raise LeaseHeld(self._holder, self.timeout - (now - self._last))
            self._token = secrets.token_urlsafe(24)
            self._holder, self._source = holder, source
            self._last, self._lost = now, False
            return self._token

    def release(self, token: str) -> bool:
        """Give the lease up; False if `token` does not hold it."""
        with self._lock:
            if not self._valid(token, self._clock()):
                return False
            self._token = self._holder = self._source = None
            return True

    def _valid(self, token: str, now: float) -> bool:
        return (
            self._token is not None
            and not self._lapsed(now)
            and hmac.compare_digest(token.encode(), self._token.encode())
        )

    def check(self, token: str | None) -> str | None:
        """The holder's source if `token` holds the lease now (and counts as a heartbeat),
        else None."""
        if token is None:
            return None
        with self._lock:
            now = self._clock()
            if not self._valid(token, now):
                return None
            self._last, self._lost = now, False
            return self._source

    def heartbeat(self, token: str) -> bool:
        """Record a sign of life; False if `token` does not hold the lease."""
        return self.check(token) is not None

    def connection_lost(self, token: str) -> None:
        """The controller's websocket closed: it is silent from now on."""
        with self._lock:
            current = self._token
            if current is not None and hmac.compare_digest(token.encode(), current.encode()):
                self._lost = True

    def token_of(self, source: str) -> str | None:
        """In-process use only (the 3D view acting for the page it is embedded in): the
        current token if the holder's input source is `source`, else None."""
        with self._lock:
            if self._lapsed(self._clock()) or self._source != source:
                return None
            return self._token

    def holds(self, token: str) -> bool:
        with self._lock:
            return self._valid(token, self._clock())

    def heard_at(self, token: str) -> float:
        """When (the clock's s) `token`'s holder last showed life; -inf if it no longer holds
        the lease or its connection dropped. The same value until it is heard again, so a
        deadline reckoned from it moves only then."""
        with self._lock:
            if self._lost or not self._valid(token, self._clock()):
                return -math.inf
            return self._last

    def silent_for(self, token: str) -> float:
        """Seconds since `token`'s holder last showed life; infinite if it no longer holds
        the lease or its connection dropped."""
        return self._clock() - self.heard_at(token)

    def info(self) -> LeaseInfo:
        with self._lock:
            now = self._clock()
            if self._lapsed(now):
                return LeaseInfo(False, None, None, 0.0)
            return LeaseInfo(True, self._holder, self._source, now - self._last)
