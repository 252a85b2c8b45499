"""The events stream's fan-out: state frames at `events_hz` and the session's discrete events,
to every websocket client, each through a short queue of its own."""

from __future__ import annotations

import asyncio
import json
import logging
import time
from dataclasses import dataclass, field
from typing import Any

from laserpick.server.session import Session

__all__ = ["CLIENT_QUEUE", "EventClient", "EventHub"]

log = logging.getLogger(__name__)

#: Messages a slow events client may fall behind by before old state frames are dropped.
CLIENT_QUEUE = 8


@dataclass(eq=False)  # hashed by identity: a set of live clients
class EventClient:
    """One websocket client: its queue of outgoing texts, how many were dropped, and the
    lease token it heartbeats with (None until it does)."""

    queue: asyncio.Queue[str] = field(default_factory=lambda: asyncio.Queue(CLIENT_QUEUE))
    dropped: int = 0
    token: str | None = None  #: set once it heartbeats with the lease's token


class EventHub:
    """Fans state frames (at `hz`) and discrete events out to every websocket client. Each
    client has a short queue; when it is full the oldest message is dropped and counted, so
    one slow client never holds up the others or the session."""

    def __init__(self, session: Session, hz: float) -> None:
        self.session, self.period = session, 1.0 / hz
        self.clients: set[EventClient] = set()
        self.seq = 0
        self.loop: asyncio.AbstractEventLoop | None = None

    def offer(self, client: EventClient, text: str) -> None:
        if client.queue.full():
            client.queue.get_nowait()
            client.dropped += 1
        client.queue.put_nowait(text)

    def broadcast(self, message: dict[str, Any]) -> None:
        self.seq += 1
        message["seq"] = self.seq
        try:
            text = json.dumps(message, separators=(",", ":"), allow_nan=False)
        except (TypeError, ValueError):  # a bug upstream must not end the stream
            log.exception("cannot encode a %s message", message.get("type"))
            return
        for client in list(self.clients):
            self.offer(client, text)

    def publish_threadsafe(self, event: dict[str, Any]) -> None:
        """For the session's listeners: hand an event over from any thread."""
        if self.loop is not None and not self.loop.is_closed():
            self.loop.call_soon_threadsafe(self.broadcast, dict(event))

    async def run(self) -> None:
        """Send a state frame every period, on time (a late tick is skipped, not queued)."""
        self.loop = asyncio.get_running_loop()
        next_at = self.loop.time()
        while True:
            next_at += self.period
            if self.clients:
                try:  # on a thread: the session's lock may be held, and the loop reads sockets
                    status = await asyncio.to_thread(self.session.status)
                except Exception:
                    log.exception("status failed")
                else:
                    self.broadcast({"type": "state", "t": time.time(), **status})
            delay = next_at - self.loop.time()
            if delay < 0:
                next_at = self.loop.time()
                delay = 0
            await asyncio.sleep(delay)
