"""A small Python client of the laserpick API, for scripts, adapters, benchmarks and tests.

    with Client("http://127.0.0.1:8000", name="my script") as c:   # takes the control lease
        c.post("/laser/aim", {"point": [1.5, -0.2, 0.5]})
        c.post("/laser/confirm")
        c.wait_for(lambda s: s["state"] == "grasps_ready", timeout=30)
        c.post("/execute")
        c.wait_for(lambda s: s["state"] == "idle" and not s["busy"], timeout=120)

While a `Client` holds the lease it keeps the events websocket open in a background thread
and heartbeats on it every `heartbeat_s` (the server halts motion after 0.5 s of silence);
`latest` is the newest state frame, `events` the discrete events. Paths are relative to
`/api/v1`. Any language can do the same: the API is plain JSON over HTTP and a websocket
(see `/docs`).
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
import threading
import time
from collections.abc import Callable
from concurrent.futures import Future
from typing import Any

import requests
from websockets.asyncio.client import connect
from websockets.exceptions import WebSocketException

API = "/api/v1"
log = logging.getLogger(__name__)


class ApiError(Exception):
    """The server refused a request: `status` (e.g. 409, 422) and its `detail`."""

    def __init__(self, status: int, detail: Any, state: str | None = None) -> None:
        self.status, self.detail, self.state = status, detail, state
        super().__init__(f"HTTP {status}: {describe(detail)}")


def describe(detail: Any) -> str:
    """A refusal's detail as one readable line (422 lists name their fields)."""
    if isinstance(detail, list):
        parts = []
        for e in detail:
            loc = ".".join(str(p) for p in e.get("loc", ()) if p != "body")
            parts.append(f"{loc}: {e.get('msg', '')}" if loc else str(e.get("msg", "")))
        return "; ".join(parts)
    return str(detail)


class Client:
    """A controlling client. name: shown to others; source: the journal's input source."""

    def __init__(
        self,
        url: str,
        *,
        name: str = "script",
        source: str = "rest",
        password: str | None = None,
        heartbeat_s: float = 0.15,
        timeout: float = 30.0,
    ) -> None:
        self.url = url.rstrip("/")
        self.name, self.source, self.password = name, source, password
        self.heartbeat_s, self.timeout = heartbeat_s, timeout
        self.http = requests.Session()
        self.token: str | None = None
        self.latest: dict[str, Any] | None = None
        self.events: list[dict[str, Any]] = []  #: discrete events seen, oldest first
        self.frames = 0  #: state frames received
        self.gaps = 0  #: frames the server dropped for us (gaps in `seq`)
        self._last_seq = 0
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    # --- plumbing ------------------------------------------------------------------------

    def _headers(self) -> dict[str, str]:
        return {"Authorization": f"Bearer {self.token}"} if self.token else {}

    def request(self, method: str, path: str, body: Any = None, **params: Any) -> Any:
        """Send a request; the decoded JSON (or bytes for binary bodies). Raises ApiError."""
        r = self.http.request(
            method,
            f"{self.url}{API}{path}",
            json=body,
            params=params or None,
            headers=self._headers(),
            timeout=self.timeout,
        )
        if r.status_code >= 400:
            try:
                payload = r.json()
            except ValueError:
                payload = {"detail": r.text}
            raise ApiError(r.status_code, payload.get("detail"), payload.get("state"))
        if r.headers.get("content-type", "").startswith("application/json"):
            return r.json()
        return r.content

    def get(self, path: str, **params: Any) -> Any:
        return self.request("GET", path, **params)

    def post(self, path: str, body: Any = None) -> Any:
        return self.request("POST", path, body)

    def delete(self, path: str) -> Any:
        return self.request("DELETE", path)

    def state(self) -> dict[str, Any]:
        return self.get("/state")

    def health(self) -> dict[str, Any]:
        """`GET /health`: the server's version, scene, 3D view address and limits."""
        return self.get("/health")

    # --- the lease and the heartbeat -----------------------------------------------------

    def take_control(self) -> str:
        """Take the lease (409 ApiError if someone holds it) and start heartbeating."""
        body = {"name": self.name, "source": self.source, "password": self.password}
        self.token = self.post("/control", body)["token"]
        self._start_events()
        return self.token

    def release(self) -> None:
        """Stop heartbeating and give the lease back."""
        self._stop_events()
        if self.token is not None:
            with contextlib.suppress(ApiError, requests.RequestException):
                self.delete("/control")
            self.token = None

    def __enter__(self) -> Client:
        self.take_control()
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()

    def _start_events(self) -> None:
        """Open the events websocket on a thread of its own; raise here if it cannot open."""
        self._stop.clear()
        opened: Future[None] = Future()
        self._thread = threading.Thread(
            target=asyncio.run, args=(self._events(opened),), name="laserpick-client", daemon=True
        )
        self._thread.start()
        try:
            opened.result()
        except BaseException:
            self._thread.join(timeout=2.0)
            self._thread = None
            raise

    def _stop_events(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
        self._thread = None

    async def _events(self, opened: Future[None]) -> None:
        """Heartbeat and receive on one event loop. One thread must own the socket: the sync
        client reads on a thread of its own while the caller writes, which one TLS session
        does not allow (through nginx under load, about 1 opening handshake in 75 was lost)."""
        ws_url = "ws" + self.url[len("http") :] + f"{API}/events"
        try:
            ws = await connect(ws_url, open_timeout=self.timeout, close_timeout=1.0, max_size=2**22)
        except BaseException as exc:
            opened.set_exception(exc)
            return
        opened.set_result(None)
        next_beat = 0.0
        try:
            async with ws:
                while not self._stop.is_set():
                    now = time.monotonic()
                    if now >= next_beat:
                        if self.token is not None:
                            await ws.send(json.dumps({"type": "heartbeat", "token": self.token}))
                        next_beat = now + self.heartbeat_s
                    try:  # waking each heartbeat also notices `_stop` within `heartbeat_s`
                        text = await asyncio.wait_for(ws.recv(), next_beat - time.monotonic())
                    except TimeoutError:
                        continue
                    self._on_message(json.loads(text))
        except (WebSocketException, OSError):
            pass  # the server went away; requests will say so
        except Exception:  # without heartbeats the server halts motion: say why
            log.exception("the events thread failed; heartbeats have stopped")

    def _on_message(self, msg: dict[str, Any]) -> None:
        seq = msg.get("seq")
        if isinstance(seq, int):
            if self._last_seq and seq > self._last_seq + 1:
                self.gaps += seq - self._last_seq - 1
            self._last_seq = seq
        if msg.get("type") == "state":
            self.frames += 1
            self.latest = msg
        elif msg.get("type") == "event":
            self.events.append(msg)

    # --- waiting ---------------------------------------------------------------------------

    def wait_for(
        self, predicate: Callable[[dict[str, Any]], bool], timeout: float, poll: float = 0.1
    ) -> dict[str, Any]:
        """Poll GET /state until `predicate(state)` holds; that state. TimeoutError names the
        last state seen. (Polling, not the stream: a REST answer is never older than the
        command before it, whereas a frame in flight may be.)"""
        deadline = time.monotonic() + timeout
        state = self.state()
        while not predicate(state):
            if time.monotonic() >= deadline:
                raise TimeoutError(
                    f"waited {timeout:.0f} s; last state {state['state']!r}: {state['message']}"
                )
            time.sleep(poll)
            state = self.state()
        return state

    def settled(self, timeout: float) -> dict[str, Any]:
        """Wait until no job runs; that state."""
        return self.wait_for(lambda s: not s["busy"], timeout)
