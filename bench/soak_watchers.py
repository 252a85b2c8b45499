"""The soak's watchers: read-only clients, each an events websocket (reconnecting when it
drops) and a thread polling `GET /api/v1/state`. Every answer goes through a `Ledger`, so a
5xx to a watcher counts like any other.

They run in a process of their own (`WatcherProcess`), as other people's screens would: in
the controller's process, forty threads parsing state frames hold the interpreter long
enough to delay its heartbeats past the dead-man's 0.5 s."""

from __future__ import annotations

import json
import multiprocessing
import threading
import time
from dataclasses import dataclass
from multiprocessing.connection import Connection
from typing import Any

import requests
from soak_ledger import Ledger
from websockets.exceptions import WebSocketException
from websockets.sync.client import connect

from laserpick.client import API, Client


@dataclass
class WatcherStats:
    frames: int = 0  #: state frames received
    gaps: int = 0  #: messages the server dropped for a watcher (gaps in `seq`)
    drops: int = 0  #: websockets that closed or failed and were opened again
    polls: int = 0  #: GET /state answered


class Watchers:
    """`n` watchers on `url`, started by `start` and stopped by `stop`."""

    def __init__(self, url: str, n: int, read_hz: float, ledger: Ledger) -> None:
        self.url, self.n, self.period, self.ledger = url, n, 1.0 / read_hz, ledger
        self.stats = [WatcherStats() for _ in range(n)]
        self._stop = threading.Event()
        self._threads: list[threading.Thread] = []

    def start(self) -> None:
        for i, s in enumerate(self.stats):
            for target in (self._listen, self._poll):
                t = threading.Thread(target=target, args=(i, s), daemon=True)
                t.start()
                self._threads.append(t)

    def stop(self) -> None:
        self._stop.set()
        for t in self._threads:
            t.join(timeout=10)

    def summary(self) -> dict[str, int]:
        return {
            "watchers": self.n,
            "state_frames": sum(s.frames for s in self.stats),
            "dropped_messages": sum(s.gaps for s in self.stats),
            "websocket_reopened": sum(s.drops for s in self.stats),
            "state_polls": sum(s.polls for s in self.stats),
        }

    def _listen(self, i: int, s: WatcherStats) -> None:
        """Read the events websocket, opening it again whenever it closes."""
        ws_url = "ws" + self.url[len("http") :] + f"{API}/events"
        while not self._stop.is_set():
            last = 0
            try:
                with connect(ws_url, max_size=2**22, open_timeout=30) as ws:
                    while not self._stop.is_set():
                        try:
                            msg = json.loads(ws.recv(timeout=1.0))
                        except TimeoutError:
                            continue
                        seq = msg.get("seq")
                        if isinstance(seq, int):
                            s.gaps += max(0, seq - last - 1) if last else 0
                            last = seq
                        s.frames += msg.get("type") == "state"
            except (WebSocketException, OSError, ValueError) as exc:
                if self._stop.is_set():
                    return
                s.drops += 1
                self.ledger.exception("watcher websocket", exc)
                self._stop.wait(1.0)

    def _poll(self, i: int, s: WatcherStats) -> None:
        """GET /state every period, the watchers spread over it."""
        c = Client(self.url, name=f"soak watcher {i}", timeout=30.0)
        next_at = time.monotonic() + self.period * i / self.n
        while not self._stop.wait(max(0.0, next_at - time.monotonic())):
            next_at = max(next_at + self.period, time.monotonic())
            try:
                status, _ = self.ledger.call(c, "GET", "/state")
            except (requests.RequestException, OSError):
                continue  # counted by the ledger
            s.polls += status == 200


def _watch(url: str, n: int, read_hz: float, conn: Connection) -> None:
    """The watcher process: watch until told to stop, then send back what was seen."""
    ledger = Ledger()
    watchers = Watchers(url, n, read_hz, ledger)
    watchers.start()
    conn.recv()  # the stop
    watchers.stop()
    conn.send(
        {
            "summary": watchers.summary(),
            "statuses": ledger.statuses,
            "server_errors": ledger.server_errors,
            "exceptions": ledger.exceptions,
        }
    )


class WatcherProcess:
    """`Watchers` in a process of their own; `stop` merges what they saw into `ledger`."""

    def __init__(self, url: str, n: int, read_hz: float, ledger: Ledger) -> None:
        self.ledger = ledger
        self._conn, child = multiprocessing.get_context("spawn").Pipe()
        self._proc = multiprocessing.get_context("spawn").Process(
            target=_watch, args=(url, n, read_hz, child), daemon=True
        )
        self.seen: dict[str, Any] = {"watchers": n}

    def start(self) -> None:
        self._proc.start()

    def stop(self) -> dict[str, Any]:
        """Stop the watchers; their summary."""
        self._conn.send("stop")
        if self._conn.poll(60):
            got = self._conn.recv()
            self.seen = got["summary"]
            self.ledger.merge(got["statuses"], got["server_errors"], got["exceptions"])
        else:
            self.ledger.exception("watchers", TimeoutError("the watcher process did not answer"))
        self._proc.join(timeout=10)
        if self._proc.is_alive():
            self._proc.kill()
        return self.seen
