"""The events websocket: state frames at 30 Hz and discrete events out, heartbeats in."""

from __future__ import annotations

import asyncio
import contextlib
import json
import time
from typing import Any

from fastapi import APIRouter, WebSocket
from starlette.websockets import WebSocketDisconnect

from laserpick import __version__
from laserpick.server.events import EventClient
from laserpick.server.routers.dependencies import API, Hub, SessionDep
from laserpick.server.session import Session

__all__ = ["router"]

router = APIRouter(prefix=API)

#: The answer to a message that is not a JSON text frame (binary, or text that does not parse).
_NOT_TEXT = {"type": "error", "detail": "messages must be JSON objects, sent as text"}


@router.websocket("/events")
async def events(ws: WebSocket, session: SessionDep, hub: Hub) -> None:
    """State frames at 30 Hz and discrete events, as JSON text. Send
    `{"type": "heartbeat", "token": "..."}` to keep the lease; the controller's socket
    closing halts motion at once."""
    settings = session.settings.server
    await ws.accept()
    client = EventClient()
    hello = {
        "type": "hello",
        "version": __version__,
        "events_hz": settings.events_hz,
        "watchdog_s": settings.watchdog_s,
    }
    await ws.send_text(json.dumps(hello))
    hub.clients.add(client)
    sender = asyncio.create_task(_pump(ws, client))
    try:
        while True:
            message = await ws.receive()
            if message["type"] == "websocket.disconnect":
                break
            text = message.get("text")
            reply = _on_message(session, client, text) if text is not None else _NOT_TEXT
            hub.offer(client, json.dumps(reply))
    except (WebSocketDisconnect, RuntimeError):
        pass
    finally:
        hub.clients.discard(client)
        sender.cancel()
        if client.token is not None:
            session.lease.connection_lost(client.token)


async def _pump(ws: WebSocket, client: EventClient) -> None:
    with contextlib.suppress(Exception):
        while True:
            text = await client.queue.get()
            await ws.send_text(text)


def _on_message(session: Session, client: EventClient, text: str) -> dict[str, Any]:
    """Handle one client message: a heartbeat is acknowledged, anything else refused."""
    try:
        msg = json.loads(text)
    except (ValueError, RecursionError):  # RecursionError: nested deeper than the parser goes
        return _NOT_TEXT
    if not isinstance(msg, dict) or msg.get("type") != "heartbeat":
        return {"type": "error", "detail": 'unknown message; send {"type": "heartbeat"}'}
    token = msg.get("token", client.token)
    if not isinstance(token, str) or not session.lease.heartbeat(token):
        return {"type": "error", "detail": "heartbeat without a token that holds the lease"}
    client.token = token
    # The client's own `sent` value comes back, so it can time the round trip on its clock.
    return {"type": "heartbeat_ack", "echo": msg.get("sent"), "t": time.time()}
