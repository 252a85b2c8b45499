"""An adapter's connection on a fake client: dead-man driving, reconnection without stale
commands, refusals said in one line, nudges split to the server's `max_nudge` read from
`GET /health`, and a clear stop when the server does not state it.
"""

from __future__ import annotations

import io
import time
from collections.abc import Iterator
from typing import Any, ClassVar

import pytest

from laserpick.adapters import Announcer, Connection, MissingLimit, nudge_limit
from laserpick.client import ApiError

#: The fake server's largest nudge (rad), unlike the real default, to show it is read.
FAKE_MAX_NUDGE = 0.15


class FakeClient:
    """Stands in for `laserpick.client.Client`: records posts (path, body, time); `down`
    makes the server unreachable; `refuse` answers a path with an ApiError; `health_answer`
    is what `GET /health` says."""

    servers: ClassVar[list[FakeClient]] = []
    down: ClassVar[bool] = False
    refuse: ClassVar[dict[str, ApiError]] = {}
    health_answer: ClassVar[dict[str, Any]] = {}

    def __init__(self, url: str, **kw: Any) -> None:
        self.url, self.kw = url, kw
        self.token: str | None = None
        self.frames = 0
        self.posts: list[tuple[str, Any, float]] = []
        FakeClient.servers.append(self)

    def _check(self) -> None:
        if FakeClient.down:
            raise ConnectionRefusedError("Connection refused")

    def take_control(self) -> str:
        self._check()
        self.token = "t"
        return self.token

    def release(self) -> None:
        self.token = None

    def post(self, path: str, body: Any = None) -> Any:
        self._check()
        self.frames += 1
        if path in FakeClient.refuse:
            raise FakeClient.refuse[path]
        self.posts.append((path, body, time.monotonic()))
        return {}

    def get(self, path: str, **params: Any) -> Any:
        self._check()
        self.frames += 1
        return FakeClient.health_answer if path == "/health" else {}

    def health(self) -> dict[str, Any]:
        return self.get("/health")

    def state(self) -> dict[str, Any]:
        self._check()
        self.frames += 1
        return {"state": "idle", "busy": False}


@pytest.fixture
def fake_link() -> Iterator[tuple[Connection, io.StringIO]]:
    FakeClient.servers, FakeClient.down, FakeClient.refuse = [], False, {}
    FakeClient.health_answer = {"status": "ok", "max_nudge": FAKE_MAX_NUDGE}
    out = io.StringIO()
    link = Connection(
        "http://fake",
        name="t",
        source="switch",
        announcer=Announcer(out=out),
        client_factory=FakeClient,
        backoff_min=0.05,
        backoff_max=0.1,
        stall_s=100.0,
    )
    link.start()
    end = time.monotonic() + 5
    while not link.connected and time.monotonic() < end:
        time.sleep(0.01)
    yield link, out
    link.close(flush_timeout=2.0)


def drives(client: FakeClient) -> list[tuple[Any, float]]:
    return [(b, t) for p, b, t in client.posts if p == "/drive"]


def test_connection_drives_only_while_asked(fake_link: tuple[Connection, io.StringIO]) -> None:
    link, _ = fake_link
    client = FakeClient.servers[-1]
    end = time.monotonic() + 0.6
    while time.monotonic() < end:  # the input keeps asking
        link.drive(0.2, 0.0)
        last_ask = time.monotonic()
        time.sleep(0.05)
    time.sleep(1.0)  # then it stops asking (a released switch, or a hung input loop)
    go = {"v": 0.2, "w": 0.0, "duration": 0.3}
    sent = drives(client)
    assert [b for b, _ in sent[:-1]] == [go] * (len(sent) - 1) and len(sent) >= 5
    assert sent[-1][0] == {"v": 0.0, "w": 0.0, "duration": 0.1}  # one stop at the end
    # renewed at most hold_s (0.5 s) after the last ask; each lasts 0.3 s: a dead-man
    assert max(t for b, t in sent if b == go) <= last_ask + link.hold_s + 0.05


def test_connection_reconnects_and_drops_stale_commands(
    fake_link: tuple[Connection, io.StringIO],
) -> None:
    link, out = fake_link
    link.drive(0.2, 0.0)
    time.sleep(0.1)
    FakeClient.down = True  # the server dies mid-drive
    time.sleep(0.3)
    assert not link.connected
    assert "lost the server at http://fake" in out.getvalue()
    assert not link.post("confirm", "/laser/confirm")  # said and dropped, not queued
    assert "not connected: confirm not sent" in out.getvalue()
    FakeClient.down = False
    end = time.monotonic() + 3
    while not link.connected and time.monotonic() < end:
        time.sleep(0.01)
    assert link.connected and link.connections == 2
    time.sleep(0.3)
    assert drives(FakeClient.servers[-1]) == []  # nothing resumes by itself
    assert [c for _, c in link.take_notices()] == [True, False, True]


def test_connection_says_refusals_and_splits_big_nudges(
    fake_link: tuple[Connection, io.StringIO],
) -> None:
    link, out = fake_link
    FakeClient.refuse = {
        "/execute": ApiError(409, "not allowed while idle (allowed when: grasps_ready)", "idle"),
        "/mode": ApiError(422, [{"loc": ["body", "mode"], "msg": "Input should be 'a'"}]),
    }
    link.post("go", "/execute")
    link.post("mode", "/mode", {"mode": "x"})
    link.nudge(0.3, 0.0)
    link.nudge(0.2, -0.1)  # merged with the one before while queued, or sent after it
    end = time.monotonic() + 3
    while not link.flushed() and time.monotonic() < end:
        time.sleep(0.01)
    text = out.getvalue()
    assert "refused: go: not allowed while idle (allowed when: grasps_ready) (state idle)" in text
    assert "invalid: mode: mode: Input should be 'a'" in text
    nudges = [b for p, b, _ in FakeClient.servers[-1].posts if p == "/laser/nudge"]
    assert link.max_nudge == FAKE_MAX_NUDGE
    assert all(abs(b["dyaw"]) <= FAKE_MAX_NUDGE + 1e-12 for b in nudges) and len(nudges) >= 4
    assert sum(b["dyaw"] for b in nudges) == pytest.approx(0.5)
    assert sum(b["dpitch"] for b in nudges) == pytest.approx(-0.1)


def test_nudge_limit_is_read_from_health() -> None:
    assert nudge_limit({"status": "ok", "max_nudge": 0.2}) == 0.2
    for answer in ({"status": "ok"}, {"max_nudge": None}, {"max_nudge": 0}, {"max_nudge": True}):
        with pytest.raises(MissingLimit):
            nudge_limit(answer)


def test_a_server_without_max_nudge_stops_the_adapter_with_a_clear_message() -> None:
    FakeClient.servers, FakeClient.down, FakeClient.refuse = [], False, {}
    FakeClient.health_answer = {"status": "ok"}  # a server older than the adapter
    out = io.StringIO()
    link = Connection(
        "http://fake",
        name="t",
        source="switch",
        announcer=Announcer(out=out),
        client_factory=FakeClient,
        backoff_min=0.05,
        backoff_max=0.1,
    )
    link.start()
    end = time.monotonic() + 5
    while link.fatal is None and time.monotonic() < end:
        time.sleep(0.01)
    link.close(flush_timeout=2.0)
    assert link.fatal is not None and "max_nudge" in link.fatal, out.getvalue()
    assert "has no max_nudge" in out.getvalue() and not link.connected
    assert all(c.token is None for c in FakeClient.servers)  # no lease taken or kept
    assert len(FakeClient.servers) == 1  # not retried: retrying cannot help
