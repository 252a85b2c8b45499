"""The 3D view's door: which of its browser clients may use its controls, and as whom.

The view obeys the API's door. Each viser client is judged once, from its websocket handshake:

- **the station**: a client that connected straight from this computer (a loopback peer,
  without a proxy's forwarding headers) to a server without an operator password. It is the
  person at the scooter's own screen, and it acts as the operator station (source
  `console`), as the page does without a password.
- **the operator**: a client that brought the control lease's token in the `laserpick_lease`
  cookie, and whose token held the lease when it connected. The operator page sets that
  cookie for the view it embeds, scoped to the view's websocket path (a cookie, not the URL,
  so no access log keeps the token), and reloads the view when its token changes. Every
  control checks the token against the lease again when pressed.
- **a watcher**: everyone else (behind the proxy, from another host, or with a password set,
  without a holding token). It sees the scene and the status, and no controls; a click in
  its scene is refused with the reason.

Anything the handshake does not say counts against the client: a connection that cannot be
read is a watcher's.
"""

from __future__ import annotations

import ipaddress
import threading
from dataclasses import dataclass
from http.cookies import CookieError, SimpleCookie
from typing import Any

import viser

from laserpick.server.lease import ControlLease
from laserpick.server.session import Actor, Conflict, TaskState

__all__ = [
    "LAPSED",
    "LEASE_COOKIE",
    "PROXY_HEADERS",
    "WATCHING",
    "Handshake",
    "ViewDoor",
    "Visitor",
    "handshake_of",
]

#: The cookie that carries the operator page's lease token to the view's websocket.
LEASE_COOKIE = "laserpick_lease"
#: Headers that a proxy adds: their presence means the peer is not the person.
PROXY_HEADERS = ("x-forwarded-for", "x-real-ip", "forwarded")
#: Why a watcher's command is refused.
WATCHING = (
    "this 3D view only watches: its controls act for the operator who holds control. "
    "Take control on the operator page (with the operator password, when the robot has one); "
    "the view it embeds then acts for it."
)
LAPSED = (
    "this 3D view acts for the operator who held control when it opened, and that lease has "
    "lapsed or passed on. Take control on the operator page; it reopens the view with its lease."
)


@dataclass(frozen=True)
class Handshake:
    """What a client's websocket handshake says: the peer's address, and its headers
    (lower-case names; the last value of each)."""

    peer: str
    headers: dict[str, str]

    @property
    def direct_loopback(self) -> bool:
        """From this computer, straight: a loopback peer and no proxy's forwarding header."""
        try:
            address = ipaddress.ip_address(self.peer)
        except ValueError:
            return False
        if isinstance(address, ipaddress.IPv6Address) and address.ipv4_mapped is not None:
            address = address.ipv4_mapped
        return address.is_loopback and not any(h in self.headers for h in PROXY_HEADERS)

    @property
    def lease_token(self) -> str | None:
        """The token in the `laserpick_lease` cookie, if any."""
        cookie = SimpleCookie()
        try:
            cookie.load(self.headers.get("cookie", ""))
        except CookieError:
            return None
        morsel = cookie.get(LEASE_COOKIE)
        return morsel.value if morsel is not None and morsel.value else None


def handshake_of(server: viser.ViserServer, client_id: int) -> Handshake | None:
    """The handshake of `client_id`'s websocket, or None when it cannot be read. viser keeps
    the connection in its websocket server's `_live_connections` (no public accessor); on a
    viser without it every client is a watcher, the safe side."""
    live: Any = getattr(getattr(server, "_websock_server", None), "_live_connections", None)
    connection = live.get(client_id) if isinstance(live, dict) else None
    if connection is None:
        return None
    try:
        peer = str(connection.remote_address[0])
        headers = {k.lower(): v for k, v in connection.request.headers.raw_items()}
    except (AttributeError, IndexError, TypeError):
        return None
    return Handshake(peer, headers)


@dataclass(frozen=True)
class Visitor:
    """A client as the door judged it: `station` (acts as the operator station), or
    `token` (acts with that lease token), or neither (watches)."""

    station: bool
    token: str | None

    @property
    def controls(self) -> bool:
        """Whether it is shown the controls."""
        return self.station or self.token is not None


class ViewDoor:
    """Judges each client on arrival (`arrive`) and gives the `Actor` of each command
    (`actor`). `password_set`: the server has an operator password, so no client is the
    station."""

    def __init__(
        self, server: viser.ViserServer, lease: ControlLease, *, password_set: bool
    ) -> None:
        self.server, self.lease, self.password_set = server, lease, password_set
        self._lock = threading.Lock()
        self._visitors: dict[int, Visitor] = {}

    def arrive(self, client: viser.ClientHandle) -> Visitor:
        """Judge `client` from its handshake and remember the verdict."""
        visitor = self.judge(handshake_of(self.server, client.client_id))
        with self._lock:
            self._visitors[client.client_id] = visitor
        return visitor

    def judge(self, handshake: Handshake | None) -> Visitor:
        """The verdict on a handshake (None: unreadable, a watcher)."""
        if handshake is None:
            return Visitor(False, None)
        if not self.password_set and handshake.direct_loopback:
            return Visitor(True, None)
        token = handshake.lease_token
        if token is not None and self.lease.holds(token):
            return Visitor(False, token)
        return Visitor(False, None)

    def leave(self, client: viser.ClientHandle) -> None:
        with self._lock:
            self._visitors.pop(client.client_id, None)

    def visitor(self, client: viser.ClientHandle | None) -> Visitor:
        """The verdict on `client`; None is an in-process caller (the station); a client
        never judged watches."""
        if client is None:
            return Visitor(True, None)
        with self._lock:
            return self._visitors.get(client.client_id, Visitor(False, None))

    def stations(self) -> int:
        """How many connected clients are the station."""
        with self._lock:
            return sum(v.station for v in self._visitors.values())

    def actor(self, client: viser.ClientHandle | None, state: TaskState) -> Actor | None:
        """The `Actor` of a command from `client`: its lease token's, checked now (a
        heartbeat), or None for the station (the caller acts as the station). Conflict,
        saying why, for a watcher or a token that no longer holds the lease."""
        visitor = self.visitor(client)
        if visitor.station:
            return None
        if visitor.token is None:
            raise Conflict(WATCHING, state)
        source = self.lease.check(visitor.token)
        if source is None:
            raise Conflict(LAPSED, state)
        return Actor(source, visitor.token)  # type: ignore[arg-type]
