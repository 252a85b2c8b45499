"""The FastAPI app: the page at `/`, the REST API under `/api/v1`, and the events websocket.

Every command goes to the one `Session` (rule 2) and needs the control lease's token as
`Authorization: Bearer <token>`; reads do not. The e-stop is the exception: anyone who can
reach the API may press it, as anyone near a robot may press its red button.

Status codes: 401 without a valid token; 409 when the command conflicts with the task state
or someone else holds the lease (the body says the current state); 413 for a body over the
size limit; 422 for invalid input, naming the field. Handlers that touch the robot are plain
`def`s, so FastAPI runs them in its thread pool and the event loop never waits on them.

The routes live in `routers/`, one module a resource, sharing `routers/dependencies.py`. A
simulated robot's routes (`/sim/objects`, `POST /scene`) are added by
`routers.simulation.include_simulator`, which the CLI calls only for a simulated robot.
"""

from __future__ import annotations

import contextlib
from collections.abc import AsyncIterator, Callable

from fastapi import FastAPI
from fastapi.staticfiles import StaticFiles

from laserpick import __version__
from laserpick.server import schemas as S
from laserpick.server.background import in_background
from laserpick.server.errors import BodyLimit, add_error_handlers
from laserpick.server.events import EventHub
from laserpick.server.gc_pauses import GcPauses
from laserpick.server.loop_lag import LoopLag
from laserpick.server.routers import control, events, grasps, laser, motion, read, task
from laserpick.server.routers import page as pages
from laserpick.server.routers.dependencies import AppSettings
from laserpick.server.session import Session

__all__ = ["create_app"]

_DESCRIPTION = (
    "Take the control lease (`POST /api/v1/control`), then send commands with "
    "`Authorization: Bearer <token>`. Heartbeat on the events websocket "
    '(`{"type": "heartbeat", "token": ...}`) or by `POST /api/v1/control` with the '
    "token at least every 0.5 s while the robot moves, or the motion halts. Reads "
    "and the e-stop need no token. Units: m, rad, s; points in the scooter's `base` "
    "frame (x forward, y left, z up) unless `frame` says `world`."
)


def create_app(
    session: Session,
    *,
    viser_port: int | None = None,
    viser_url: str | None = None,
    cors_origins: list[str] | None = None,
    page: Callable[[], str] | None = None,
) -> FastAPI:
    """The app around `session`. viser_port, viser_url: where the page finds the 3D view.
    cors_origins: allowed browser origins (default none). page: returns the HTML of `/`
    (default `static/index.html`, the operator page)."""
    limits = session.settings.server
    hub, lag, gc_pauses = EventHub(session, limits.events_hz), LoopLag(), GcPauses()
    session.on_event(hub.publish_threadsafe)

    @contextlib.asynccontextmanager
    async def lifespan(_app: FastAPI) -> AsyncIterator[None]:
        gc_pauses.start()
        try:
            async with in_background(hub.run), in_background(lag.run):
                yield
        finally:
            gc_pauses.stop()

    app = FastAPI(
        title="laserpick",
        version=__version__,
        summary="Assistive laser-directed pick and place: the operator session's API.",
        description=_DESCRIPTION,
        lifespan=lifespan,
        # BodyLimit refuses a body over the limit whatever the route
        responses={413: {"model": S.Problem, "description": "The body is over the size limit."}},
    )
    app.state.session, app.state.hub = session, hub
    app.state.loop_lag, app.state.gc_pauses = lag, gc_pauses
    app.state.settings = AppSettings(viser_port=viser_port, viser_url=viser_url, page=page)
    app.add_middleware(BodyLimit, limit=limits.max_body_bytes)
    if cors_origins:
        from fastapi.middleware.cors import CORSMiddleware

        app.add_middleware(CORSMiddleware, allow_origins=cors_origins, allow_methods=["*"])
    add_error_handlers(app)
    for module in (pages, read, control, laser, grasps, task, motion, events):
        app.include_router(module.router)
    if pages.STATIC.is_dir():
        app.mount("/static", StaticFiles(directory=pages.STATIC), name="static")
    return app
