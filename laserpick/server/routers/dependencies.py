"""What the routers share, as FastAPI dependencies: the session, the app's settings, the
events hub, and the lease check that turns a bearer token into the `Actor` of a command.

`create_app` puts the session, the settings and the hub on `app.state`; these read them from
there, so every router works on whichever app includes it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Annotated

from fastapi import Depends, HTTPException
from fastapi.security import HTTPAuthorizationCredentials, HTTPBearer
from starlette.requests import HTTPConnection

from laserpick.server.events import EventHub
from laserpick.server.session import Actor, Session

__all__ = [
    "API",
    "AppSettings",
    "Commander",
    "Credentials",
    "Hub",
    "SessionDep",
    "SettingsDep",
    "bearer",
    "commander",
    "get_hub",
    "get_session",
    "get_settings",
]

#: Where the API lives.
API = "/api/v1"


def _no_scene(_session: Session) -> str:
    return ""


@dataclass
class AppSettings:
    """How this app was set up. viser_port, viser_url: where the page finds the 3D view.
    page: returns the HTML of `/` (None: `static/index.html`). scene_name: the name of the
    world the session's robot is in, for `/health` ("" for a robot that has none; the
    simulator router names its scene)."""

    viser_port: int | None = None
    viser_url: str | None = None
    page: Callable[[], str] | None = None
    scene_name: Callable[[Session], str] = _no_scene


def get_session(conn: HTTPConnection) -> Session:
    """The app's one `Session`."""
    return conn.app.state.session


def get_settings(conn: HTTPConnection) -> AppSettings:
    """The app's `AppSettings`."""
    return conn.app.state.settings


def get_hub(conn: HTTPConnection) -> EventHub:
    """The app's events hub."""
    return conn.app.state.hub


SessionDep = Annotated[Session, Depends(get_session)]
SettingsDep = Annotated[AppSettings, Depends(get_settings)]
Hub = Annotated[EventHub, Depends(get_hub)]

#: The control lease's token, as `Authorization: Bearer <token>`; None when not sent.
bearer = HTTPBearer(auto_error=False, description="The control lease's token.")
Credentials = Annotated[HTTPAuthorizationCredentials | None, Depends(bearer)]


def commander(session: SessionDep, creds: Credentials) -> Actor:
    """The `Actor` of a command: its token must hold the lease (401 otherwise)."""
    token = creds.credentials if creds is not None else None
    source = session.lease.check(token)
    if source is None:
        why = "no token" if token is None else "this token does not hold the control lease"
        raise HTTPException(
            401,
            f"{why}: take control with POST {API}/control",
            headers={"WWW-Authenticate": "Bearer"},
        )
    return Actor(source, token)  # type: ignore[arg-type]


Commander = Annotated[Actor, Depends(commander)]
