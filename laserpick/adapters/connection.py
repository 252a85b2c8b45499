"""An adapter's link to the server: the lease, the heartbeat, reconnection, and safe driving.

One thread owns the `laserpick.client.Client` and sends everything, in the order the input
asked for it, so the input loop never waits on the network. It:

- reads the server's limits from `GET /health` at each connection (`max_nudge`, the largest
  laser nudge it takes per command, rad) and stops with a clear message when the server does
  not send them;
- takes the control lease (the Client heartbeats on the events websocket every 0.15 s), and
  says clearly when someone else holds it;
- notices a lost server (a request fails, or the 30 Hz state frames stop and `/health` does
  not answer), drops what was queued (stale commands are never replayed), and reconnects with
  a doubling backoff (`backoff_min` .. `backoff_max` s), renewing its old lease if the server
  still has it;
- drives only while the input keeps asking: `drive(v, w)` must be repeated within `hold_s`
  (the input loop does so while a drive control is held), and each POST /drive lasts
  `drive_duration` s (< 0.5 s, the server's dead-man). So a lost server, a lost network, or a
  hung adapter all stop the base within half a second, and the arm stops by the server's
  watchdog when the heartbeats stop. After a reconnection nothing moves until input asks anew;
- prints the server's refusals (409: the task state does not allow it; 422: invalid input,
  naming the field) as one clear line each.

Times: `clock()` seconds (monotonic). Speeds: m/s and rad/s. Angles: rad.
"""

from __future__ import annotations

import collections
import contextlib
import math
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

import requests
from websockets.exceptions import WebSocketException

from laserpick.adapters.announce import Announcer
from laserpick.client import ApiError, Client, describe

Run = Callable[[Client], "str | None"]


@dataclass
class _Command:
    kind: Literal["call", "nudge", "state"]
    label: str
    run: Run | None = None
    dyaw: float = 0.0
    dpitch: float = 0.0
    ticket: int = 0


class _Lost(Exception):
    """The server is gone (or no longer knows our lease)."""


class MissingLimit(Exception):
    """The server's `GET /health` does not state a limit this adapter needs."""


def nudge_limit(health: dict[str, Any]) -> float:
    """The largest laser nudge (rad) the server takes per command, from its `GET /health`
    answer. Raises MissingLimit when the answer has no positive, finite `max_nudge`."""
    value = health.get("max_nudge")
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise MissingLimit(
            "the server's GET /health has no max_nudge (its largest laser nudge, rad): "
            "it is older than this adapter; update the server"
        )
    if not (math.isfinite(value) and value > 0):
        raise MissingLimit(f"the server's max_nudge is {value!r}, not a positive number of rad")
    return float(value)


def reason(exc: BaseException) -> str:
    """A short human reason for a network failure."""
    text = str(exc)
    if isinstance(exc, (requests.Timeout, TimeoutError)):
        return "no answer in time"
    if "Connection refused" in text or isinstance(exc, ConnectionRefusedError):
        return "connection refused"
    if isinstance(exc, requests.ConnectionError):
        return "the connection failed"
    return f"{type(exc).__name__}: {text[:120]}"


def refusal(label: str, exc: ApiError) -> str:
    """A server refusal as one line: what was refused and why."""
    if exc.status == 409:
        where = f" (state {exc.state})" if exc.state else ""
        return f"refused: {label}: {describe(exc.detail)}{where}"
    if exc.status == 422:
        return f"invalid: {label}: {describe(exc.detail)}"
    return f"error {exc.status}: {label}: {describe(exc.detail)}"


class Connection:
    """The link; see the module docstring. `announcer` prints what happens; `notify` (given
    to `start`) wakes the input loop when the link comes or goes (`take_notices`)."""

    def __init__(
        self,
        url: str,
        *,
        name: str,
        source: str,
        announcer: Announcer,
        password: str | None = None,
        clock: Callable[[], float] = time.monotonic,
        client_factory: Callable[..., Client] = Client,
        backoff_min: float = 0.25,
        backoff_max: float = 4.0,
        drive_period: float = 0.15,
        drive_duration: float = 0.3,
        hold_s: float = 0.5,
        stall_s: float = 1.5,
        request_timeout: float = 5.0,
    ) -> None:
        if not 0 < drive_duration <= 0.5:
            raise ValueError("drive_duration must be in (0, 0.5] s: the server's dead-man")
        self.url, self.name, self.source, self.password = url.rstrip("/"), name, source, password
        self.say = announcer
        self.clock = clock
        self._factory = client_factory
        self.backoff_min, self.backoff_max = backoff_min, backoff_max
        self.drive_period, self.drive_duration, self.hold_s = drive_period, drive_duration, hold_s
        self.stall_s, self.request_timeout = stall_s, request_timeout
        self._cond = threading.Condition()
        self._queue: collections.deque[_Command] = collections.deque()
        self._busy = False
        self._connected = False
        self._closing = False
        self._notices: list[tuple[float, bool]] = []
        self._notify: Callable[[], None] = lambda: None
        self._drive: tuple[float, float, float] | None = None  #: v, w, valid until (clock)
        self._drive_sent_at = -math.inf
        self._drive_sent: tuple[float, float] | None = None  #: last (v, w) sent, this link
        self._drive_refused = ""
        self._tickets = 0
        self._states: dict[int, dict[str, Any]] = {}
        self._client: Client | None = None
        self._old_token: str | None = None
        self._frames, self._frame_at, self._probed_at = 0, 0.0, -math.inf
        self._thread: threading.Thread | None = None
        self.fatal: str | None = None  #: set when retrying cannot help (a wrong password)
        self.max_nudge: float | None = None  #: rad per nudge command, from GET /health
        self.drives_sent = 0  #: POST /drive commands with motion, all links together
        self.connections = 0  #: successful connections so far

    # --- for the input loop --------------------------------------------------------------

    def start(self, notify: Callable[[], None] | None = None) -> None:
        if notify is not None:
            self._notify = notify
        self._thread = threading.Thread(target=self._loop, name="adapter-link", daemon=True)
        self._thread.start()

    @property
    def connected(self) -> bool:
        return self._connected

    def take_notices(self) -> list[tuple[float, bool]]:
        """(time, connected) for each change since the last call."""
        with self._cond:
            out, self._notices = self._notices, []
        return out

    def call(self, label: str, run: Run) -> bool:
        """Queue `run(client)` (it may return a line to announce); False (and said) when there
        is no server to send it to."""
        with self._cond:
            if not self._connected:
                queued = False
            else:
                self._queue.append(_Command("call", label, run))
                self._cond.notify_all()
                queued = True
        if not queued:
            self.say.note(f"not connected: {label} not sent")
        return queued

    def post(self, label: str, path: str, body: Any = None) -> bool:
        """Queue a POST (a command without a reply worth announcing)."""

        def run(c: Client) -> None:
            c.post(path, body)

        return self.call(label, run)

    def nudge(self, dyaw: float, dpitch: float) -> None:
        """Turn the laser by (dyaw, dpitch) rad. Consecutive nudges merge while queued, so a
        slow server never makes the beam lag behind the stick. Dropped when disconnected."""
        with self._cond:
            if not self._connected:
                return
            last = self._queue[-1] if self._queue else None
            if last is not None and last.kind == "nudge":
                last.dyaw += dyaw
                last.dpitch += dpitch
            else:
                self._queue.append(_Command("nudge", "laser nudge", dyaw=dyaw, dpitch=dpitch))
            self._cond.notify_all()

    def drive(self, v: float, w: float) -> None:
        """Drive at v (m/s) and w (rad/s) for the next `hold_s` s; call again to keep going."""
        if v == 0 and w == 0:
            self.stop_drive()
            return
        with self._cond:
            if not self._connected:
                return
            if self._drive is None or self._drive[:2] != (v, w):
                self._drive_refused = ""
            self._drive = (v, w, self.clock() + self.hold_s)
            self._cond.notify_all()

    def stop_drive(self) -> None:
        """Stop driving now (one zero command, if a drive went out on this link)."""
        with self._cond:
            self._drive = None
            self._cond.notify_all()

    def request_state(self) -> int:
        """Ask for GET /state after everything queued before it; a ticket for `state_for`."""
        with self._cond:
            self._tickets += 1
            if self._connected:
                self._queue.append(_Command("state", "state", ticket=self._tickets))
                self._cond.notify_all()
            return self._tickets

    def state_for(self, ticket: int) -> dict[str, Any] | None:
        with self._cond:
            return self._states.pop(ticket, None)

    def flushed(self) -> bool:
        with self._cond:
            return not self._queue and not self._busy

    def close(self, flush_timeout: float = 10.0) -> None:
        """Send what is queued (up to `flush_timeout` s), stop driving, give the lease back."""
        end = time.monotonic() + flush_timeout
        while self._connected and not self.flushed() and time.monotonic() < end:
            time.sleep(0.02)
        with self._cond:
            self._drive = None
            self._closing = True
            self._cond.notify_all()
        if self._thread is not None:
            self._thread.join(timeout=flush_timeout)

    # --- the link thread -----------------------------------------------------------------

    def _loop(self) -> None:
        delay = self.backoff_min
        try:
            while not self._closing:
                if self._client is None:
                    failed = self._connect()
                    if failed is None:
                        delay = self.backoff_min
                        continue
                    why, wait = failed
                    wait = max(wait, delay)
                    if not self._closing:
                        self.say.note(f"{why}; retrying in {wait:.2f} s")
                    with self._cond:
                        self._cond.wait_for(lambda: self._closing, timeout=wait)
                    delay = min(delay * 2, self.backoff_max)
                    continue
                try:
                    self._serve_once()
                except _Lost as exc:
                    self._lose(str(exc))
        finally:
            self._shutdown()

    def _serve_once(self) -> None:
        with self._cond:
            self._cond.wait_for(
                lambda: self._queue or self._closing or self._drive_due(), timeout=0.05
            )
            cmd = self._queue.popleft() if self._queue else None
            self._busy = cmd is not None
        try:
            if cmd is not None:
                self._run(cmd)
            self._drive_tick()
            self._check_alive()
        finally:
            with self._cond:
                self._busy = False
            if cmd is not None:
                self._notify()  # the input loop may be waiting for a flush or a state

    def _drive_due(self) -> bool:
        now = self.clock()
        d = self._drive
        if d is None or now >= d[2]:
            return self._drive_sent is not None  # a stop to send
        return self._drive_sent != d[:2] or now - self._drive_sent_at >= self.drive_period

    def _request(self, label: str, fn: Callable[[], Any]) -> Any:
        try:
            return fn()
        except ApiError as exc:
            if exc.status == 401:
                raise _Lost("the server no longer knows our lease") from None
            raise
        except (requests.RequestException, OSError) as exc:
            raise _Lost(reason(exc)) from None

    def _run(self, cmd: _Command) -> None:
        client = self._client
        assert client is not None
        try:
            if cmd.kind == "nudge":
                self._send_nudge(client, cmd.dyaw, cmd.dpitch)
            elif cmd.kind == "state":
                state = self._request(cmd.label, client.state)
                with self._cond:
                    self._states[cmd.ticket] = state
            else:
                assert cmd.run is not None
                run = cmd.run
                line = self._request(cmd.label, lambda: run(client))
                if line:
                    self.say.note(line)
        except ApiError as exc:
            self.say.note(refusal(cmd.label, exc))

    def _send_nudge(self, client: Client, dyaw: float, dpitch: float) -> None:
        """Send a turn as equal nudges, each within the server's `max_nudge`."""
        assert self.max_nudge is not None  # read at connect
        steps = max(1, math.ceil(max(abs(dyaw), abs(dpitch)) / self.max_nudge - 1e-9))
        for _ in range(steps):
            body = {"dyaw": dyaw / steps, "dpitch": dpitch / steps}
            self._request("laser nudge", lambda b=body: client.post("/laser/nudge", b))

    def _drive_tick(self) -> None:
        client = self._client
        assert client is not None
        now = self.clock()
        with self._cond:
            d = self._drive
            if d is not None and now >= d[2]:
                self._drive = d = None  # the input stopped asking: a dead-man
        if d is None:
            if self._drive_sent is None:
                return
            body = {"v": 0.0, "w": 0.0, "duration": 0.1}
            self._drive_sent = None
        else:
            v, w, _ = d
            if self._drive_sent == (v, w) and now - self._drive_sent_at < self.drive_period:
                return
            body = {"v": v, "w": w, "duration": self.drive_duration}
            self._drive_sent, self._drive_sent_at = (v, w), now
        try:
            self._request("drive", lambda: client.post("/drive", body))
            if body["v"] or body["w"]:
                self.drives_sent += 1
        except ApiError as exc:
            line = refusal("drive", exc)
            if line != self._drive_refused:  # once per hold, not at 7 Hz
                self._drive_refused = line
                self.say.note(line)

    def _check_alive(self) -> None:
        client = self._client
        assert client is not None
        now = self.clock()
        if client.frames != self._frames:
            self._frames, self._frame_at = client.frames, now
            return
        silent = now - self._frame_at
        if silent < self.stall_s or now - self._probed_at < 0.5:
            return
        self._probed_at = now
        self._request("health", lambda: client.get("/health"))  # _Lost if no answer
        if silent > 4 * self.stall_s:
            raise _Lost(f"no state frames for {silent:.1f} s")

    def _connect(self) -> tuple[str, float] | None:
        """Try to take control: None on success, else why not and the least wait (s) before
        the next try."""
        client = self._factory(
            self.url,
            name=self.name,
            source=self.source,
            password=self.password,
            timeout=self.request_timeout,
        )
        client.token = self._old_token  # renews our lease if the server still has it
        try:
            max_nudge = nudge_limit(client.health())
            client.take_control()
        except MissingLimit as exc:
            client.release()
            return self._give_up(str(exc))
        except ApiError as exc:
            client.release()
            if exc.status == 401:
                return self._give_up(f"the server refused the password: {describe(exc.detail)}")
            return f"cannot take control: {describe(exc.detail)}", self.backoff_max
        except (requests.RequestException, OSError, WebSocketException) as exc:
            client.release()
            return f"cannot reach {self.url}: {reason(exc)}", 0.0
        self.max_nudge = max_nudge
        self._client = client
        self._old_token = client.token
        self._frames, self._frame_at, self._probed_at = client.frames, self.clock(), -math.inf
        self._drive_sent, self._drive_refused = None, ""
        self.connections += 1
        with self._cond:
            self._connected = True
            self._drive = None
            self._notices.append((self.clock(), True))
        self.say.note(f"connected to {self.url} as {self.name!r}: control taken")
        self._notify()
        return None

    def _give_up(self, why: str) -> tuple[str, float]:
        """Retrying cannot help: say why, and close the link (the runner exits with 2)."""
        self.fatal = why
        self.say.note(why)
        with self._cond:
            self._closing = True
        self._notify()
        return why, 0.0

    def _lose(self, why: str) -> None:
        with self._cond:
            self._connected = False
            dropped = len(self._queue)
            self._queue.clear()
            self._drive = None
            self._notices.append((self.clock(), False))
        self._drive_sent = None
        self.say.note(
            f"lost the server at {self.url}: {why}. Motion stops by itself (the base's "
            "dead-man, the arm's watchdog); reconnecting"
        )
        if dropped:
            self.say.note(f"dropped {dropped} queued command(s): they will not be replayed")
        self._notify()
        client, self._client = self._client, None
        if client is not None:
            client.release()

    def _shutdown(self) -> None:
        client, self._client = self._client, None
        if client is None:
            return
        if self._drive_sent is not None:
            with contextlib.suppress(ApiError, requests.RequestException, OSError):
                client.post("/drive", {"v": 0.0, "w": 0.0, "duration": 0.1})
        client.release()
        with self._cond:
            self._connected = False
