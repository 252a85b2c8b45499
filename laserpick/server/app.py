"""The FastAPI app: the page at `/`, the REST API under `/api/v1`, and the events websocket.

Every command goes to the one `Session` (rule 2) and needs the control lease's token as
`Authorization: Bearer <token>`; reads do not. The e-stop is the exception: anyone who can
reach the API may press it, as anyone near a robot may press its red button.

Status codes: 401 without a valid token; 409 when the command conflicts with the task state
or someone else holds the lease (the body says the current state); 413 for a body over the
size limit; 422 for invalid input, naming the field. Handlers that touch the robot are plain
`def`s, so FastAPI runs them in its thread pool and the event loop never waits on them.
"""

import asyncio
import base64
import contextlib
import hmac
import json
import logging
import tempfile
import time
from collections.abc import AsyncIterator, Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from fastapi import Depends, FastAPI, HTTPException, Query, Request, WebSocket
from fastapi.encoders import jsonable_encoder
from fastapi.exceptions import RequestValidationError
from fastapi.responses import HTMLResponse, JSONResponse, PlainTextResponse, Response
from fastapi.security import HTTPAuthorizationCredentials, HTTPBearer
from fastapi.staticfiles import StaticFiles
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.types import ASGIApp, Message, Receive, Scope, Send
from starlette.websockets import WebSocketDisconnect

from laserpick import __version__
from laserpick.console.view_page import view_page
from laserpick.pipeline.cloud import voxel_downsample
from laserpick.robot.sim.scenes import SceneError, load_scene, parse_scene
from laserpick.robot.sim.truth import SimTruth
from laserpick.server import schemas as S
from laserpick.server.lease import LeaseHeld
from laserpick.server.session import Actor, Conflict, Session
from laserpick.server.wire import CLOUD_FORMAT, encode_cloud, encode_png

log = logging.getLogger(__name__)

API = "/api/v1"
#: The browser page: index.html at `/`, its stylesheet and script under `/static`.
STATIC = Path(__file__).resolve().parents[1] / "static"
#: Messages a slow events client may fall behind by before old state frames are dropped.
CLIENT_QUEUE = 8


# --- limits --------------------------------------------------------------------------------


class BodyLimit:
    """Refuse request bodies over `limit` bytes with 413, whether or not they declare a
    Content-Length (a chunked upload is counted as it arrives)."""

    def __init__(self, app: ASGIApp, limit: int) -> None:
        self.app, self.limit = app, limit

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        length = dict(scope.get("headers", [])).get(b"content-length")
        if length is not None and (not length.isdigit() or int(length) > self.limit):
            await _too_large(self.limit)(scope, receive, send)
            return
        seen = 0

        async def counted() -> Message:
            nonlocal seen
            message = await receive()
            seen += len(message.get("body", b""))
            if seen > self.limit:
                raise _BodyTooLarge(self.limit)
            return message

        try:
            await self.app(scope, counted, send)
        except _BodyTooLarge:
            await _too_large(self.limit)(scope, receive, send)


class _BodyTooLarge(HTTPException):
    """An HTTPException, so that FastAPI's body reader passes it on (rather than answering
    400) to the app's handler, which answers 413."""

    def __init__(self, limit: int) -> None:
        super().__init__(413, f"request body larger than {limit} bytes")


def _too_large(limit: int) -> JSONResponse:
    return JSONResponse({"detail": f"request body larger than {limit} bytes"}, status_code=413)


# --- the events stream ---------------------------------------------------------------------


@dataclass(eq=False)  # hashed by identity: a set of live clients
class _Client:
    queue: asyncio.Queue[str] = field(default_factory=lambda: asyncio.Queue(CLIENT_QUEUE))
    dropped: int = 0
    token: str | None = None  #: set once it heartbeats with the lease's token


class EventHub:
    """Fans state frames (at `hz`) and discrete events out to every websocket client. Each
    client has a short queue; when it is full the oldest message is dropped and counted, so
    one slow client never holds up the others or the session."""

    def __init__(self, session: Session, hz: float) -> None:
        self.session, self.period = session, 1.0 / hz
        self.clients: set[_Client] = set()
        self.seq = 0
        self.loop: asyncio.AbstractEventLoop | None = None

    def offer(self, client: _Client, text: str) -> None:
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
            self.session.io_alive()
            if self.clients:
                try:
                    status = self.session.status()
                except Exception:
                    log.exception("status failed")
                else:
                    self.broadcast({"type": "state", "t": time.time(), **status})
            delay = next_at - self.loop.time()
            if delay < 0:
                next_at = self.loop.time()
                delay = 0
            await asyncio.sleep(delay)


# --- the app -------------------------------------------------------------------------------


def create_app(
    session: Session,
    *,
    viser_port: int | None = None,
    viser_url: str | None = None,
    cors_origins: list[str] | None = None,
    page: Callable[[], str] | None = None,
) -> FastAPI:
    """The app around `session`. cors_origins: allowed browser origins (default none).
    page: returns the HTML of `/` (default `static/index.html`, the operator page)."""
    settings = session.settings.server
    hub = EventHub(session, settings.events_hz)
    session.on_event(hub.publish_threadsafe)

    @contextlib.asynccontextmanager
    async def lifespan(_app: FastAPI) -> AsyncIterator[None]:
        task = asyncio.create_task(hub.run())
        try:
            yield
        finally:
            task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await task

    app = FastAPI(
        title="laserpick",
        version=__version__,
        summary="Assistive laser-directed pick and place: the operator session's API.",
        description=(
            "Take the control lease (`POST /api/v1/control`), then send commands with "
            "`Authorization: Bearer <token>`. Heartbeat on the events websocket "
            '(`{"type": "heartbeat", "token": ...}`) or by `POST /api/v1/control` with the '
            "token at least every 0.5 s while the robot moves, or the motion halts. Reads "
            "and the e-stop need no token. Units: m, rad, s; points in the scooter's `base` "
            "frame (x forward, y left, z up) unless `frame` says `world`."
        ),
        lifespan=lifespan,
        # BodyLimit refuses a body over the limit whatever the route
        responses={413: {"model": S.Problem, "description": "The body is over the size limit."}},
    )
    app.state.session, app.state.hub = session, hub
    app.add_middleware(BodyLimit, limit=settings.max_body_bytes)
    if cors_origins:
        from fastapi.middleware.cors import CORSMiddleware

        app.add_middleware(CORSMiddleware, allow_origins=cors_origins, allow_methods=["*"])

    bearer = HTTPBearer(auto_error=False, description="The control lease's token.")

    def actor(
        creds: Annotated[HTTPAuthorizationCredentials | None, Depends(bearer)],
    ) -> Actor:
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

    Commander = Annotated[Actor, Depends(actor)]

    def ok(taken_at: float) -> S.Ok:
        return S.Ok(state=session.state.value, message=session.message, sim_time=taken_at)

    def sim_now() -> float:
        return session.robot.sim.snapshot().time

    def guarded(fn: Callable[[], object]) -> S.Ok:
        taken_at = sim_now()
        try:
            fn()
        except Conflict as exc:
            raise HTTPException(409, {"detail": str(exc), "state": exc.state.value}) from None
        except (ValueError, IndexError) as exc:
            raise _unprocessable("body", str(exc)) from None
        return ok(taken_at)

    unauthorized = {401: {"model": S.Problem, "description": "No token, or not the lease's."}}
    conflict = {
        **unauthorized,
        409: {"model": S.Refusal, "description": "Conflicts with the task state."},
    }
    # The token is optional here. FastAPI lists the bearer scheme as required and appends
    # these requirements to it; the empty one makes the scheme optional in the OpenAPI.
    token_optional: dict[str, Any] = {"security": [{}]}

    @app.exception_handler(StarletteHTTPException)  # FastAPI's own 400 is Starlette's
    async def _http_error(request: Request, exc: StarletteHTTPException) -> JSONResponse:
        if exc.status_code == 400:  # FastAPI could not decode the body (not UTF-8): bad input
            error = {"loc": ("body",), "msg": str(exc.detail), "type": "json_invalid"}
            return await _invalid(request, RequestValidationError([error]))
        body = exc.detail if isinstance(exc.detail, dict) else {"detail": exc.detail}
        return JSONResponse(body, status_code=exc.status_code, headers=exc.headers)

    @app.exception_handler(RequestValidationError)
    async def _invalid(_request: Request, exc: RequestValidationError) -> JSONResponse:
        errors = [
            {"loc": list(e.get("loc", ())), "msg": e.get("msg", ""), "type": e.get("type", "")}
            for e in exc.errors()
        ]
        if session.journal is not None:
            fields = ", ".join(".".join(str(p) for p in e["loc"]) for e in errors)
            session.journal.record(
                source="rest", action="invalid", outcome="refused", message=fields[:500]
            )
        return JSONResponse({"detail": jsonable_encoder(errors)}, status_code=422)

    # --- reads ---------------------------------------------------------------------------

    @app.get("/", response_class=HTMLResponse, include_in_schema=False)
    def index() -> HTMLResponse:
        html = STATIC / "index.html"
        if page is not None:
            text = page()
        else:
            text = html.read_text(encoding="utf-8") if html.is_file() else _MINIMAL_PAGE
        return HTMLResponse(text)

    @app.get("/view", response_class=HTMLResponse, include_in_schema=False)
    def view() -> HTMLResponse:
        """The 3D view's page, which the page at `/` embeds (console/view_page.py)."""
        try:
            return HTMLResponse(view_page())
        except RuntimeError as exc:
            raise HTTPException(503, str(exc)) from exc

    if STATIC.is_dir():
        app.mount("/static", StaticFiles(directory=STATIC), name="static")

    @app.get(f"{API}/health", response_model=S.Health, tags=["read"])
    def health() -> S.Health:
        snap = session.robot.sim.snapshot()
        scene = session.robot.sim.scene
        return S.Health(
            status="ok",
            version=__version__,
            scene=scene.name if scene is not None else "",
            viser_port=viser_port,
            viser_url=viser_url,
            rtf=round(snap.rtf, 3),
        )

    @app.get(f"{API}/state", response_model=S.Status, tags=["read"])
    def state() -> dict[str, Any]:
        return session.status()

    @app.get(
        f"{API}/projector.png",
        response_class=Response,
        tags=["read"],
        responses={200: {"content": {"image/png": {}}, "description": "The projector image."}},
    )
    def projector() -> Response:
        image = session.projection
        if image is None:  # nothing lit: a black image of the projector's size
            image = np.zeros((session.projector.height, session.projector.width), np.uint8)
        return Response(encode_png(image), media_type="image/png")

    @app.get(
        f"{API}/cloud",
        response_class=Response,
        tags=["read"],
        responses={
            200: {
                "content": {"application/octet-stream": {}},
                "description": f"The fused cloud, voxel-thinned: {CLOUD_FORMAT}.",
            }
        },
    )
    def cloud(
        voxel: Annotated[float | None, Query(gt=0.002, le=0.2, allow_inf_nan=False)] = None,
    ) -> Response:
        thinned = voxel_downsample(session.cloud(), voxel or settings.cloud_voxel)
        return Response(encode_cloud(thinned.points), media_type="application/octet-stream")

    @app.get(
        f"{API}/journal",
        tags=["read"],
        responses={200: {"content": {"application/json": {}, "text/csv": {}}}},
    )
    def journal(
        format: Literal["json", "csv"] = "json",
        since_id: Annotated[int, Query(ge=0, le=2**62)] = 0,
        limit: Annotated[int, Query(ge=1, le=100_000)] = 10_000,
    ) -> Response:
        j = session.journal
        if j is None:
            raise HTTPException(404, "this server keeps no journal")
        if format == "csv":
            text = j.export_csv(since_id=since_id, limit=limit)
            return PlainTextResponse(text, media_type="text/csv")
        text = j.export_json(since_id=since_id, limit=limit)
        return Response(text, media_type="application/json")

    @app.get(f"{API}/sim/objects", response_model=list[S.SimObject], tags=["simulation"])
    def sim_objects() -> list[S.SimObject]:
        """Simulator ground truth: where each object is. For scoring and scripted operators
        (benchmarks, tests) only; a real robot has no such endpoint, and the session never
        reads it."""
        referee = SimTruth(session.robot)
        out = []
        for p in session.robot.sim.scene.placements if session.robot.sim.scene else ():
            pts = referee.object_points(p.instance)
            lo, hi = pts.min(axis=0), pts.max(axis=0)
            q = referee.world_quat(p.instance)
            out.append(
                S.SimObject(
                    name=p.instance,
                    model=p.model.name,
                    position_world=_round(referee.world_position(p.instance)),
                    quat_world=_round(q),
                    center_base=_round((lo + hi) / 2),
                    top_base=float(round(hi[2], 4)),
                    in_basket=referee.in_basket(p.instance),
                    # the body's z axis against world z: 1 upright, 0 on its side
                    upright=float(round(1 - 2 * (q[1] ** 2 + q[2] ** 2), 4)),
                )
            )
        return out

    # --- the lease -----------------------------------------------------------------------

    @app.post(
        f"{API}/control",
        response_model=S.ControlGrant,
        tags=["control"],
        responses={
            401: {"model": S.Problem, "description": "Wrong or missing operator password."},
            409: {"model": S.Refusal, "description": "Someone else holds control."},
        },
        openapi_extra=token_optional,
    )
    def take_control(
        body: S.ControlRequest,
        creds: Annotated[HTTPAuthorizationCredentials | None, Depends(bearer)],
    ) -> S.ControlGrant:
        """Take the control lease, or renew it (a heartbeat) by sending your token."""
        password = session.settings.operator_password
        if password is not None and not hmac.compare_digest(
            (body.password or "").encode(), password.get_secret_value().encode()
        ):
            raise HTTPException(401, "wrong or missing operator password")
        try:
            token = session.lease.acquire(
                body.name, body.source, creds.credentials if creds else None
            )
        except LeaseHeld as exc:
            raise HTTPException(409, {"detail": str(exc), "state": session.state.value}) from None
        return S.ControlGrant(
            token=token,
            holder=body.name,
            lease_timeout_s=settings.lease_timeout_s,
            watchdog_s=settings.watchdog_s,
        )

    @app.delete(f"{API}/control", response_model=S.Ok, tags=["control"], responses=unauthorized)
    def release_control(who: Commander) -> S.Ok:
        assert who.token is not None
        session.lease.release(who.token)
        return ok(sim_now())

    # --- commands ------------------------------------------------------------------------

    @app.post(f"{API}/laser/aim", response_model=S.AimResult, tags=["laser"], responses=conflict)
    def aim(body: S.AimRequest, who: Commander) -> S.AimResult:
        """Aim the laser's single beam by angles, at a point, or along a click ray."""
        hit: list[float] | None = None

        def run() -> None:
            nonlocal hit
            if body.yaw is not None and body.pitch is not None:
                session.aim(who, body.yaw, body.pitch)
            elif body.point is not None:
                session.aim_at(who, np.array(body.point), body.frame)
            else:
                assert body.ray is not None
                p = session.aim_ray(
                    who, np.array(body.ray.origin), np.array(body.ray.direction), body.frame
                )
                hit = [round(float(x), 4) for x in p]

        guarded(run)
        return S.AimResult(hit=hit)

    @app.post(f"{API}/laser/nudge", response_model=S.Ok, tags=["laser"], responses=conflict)
    def nudge(body: S.NudgeRequest, who: Commander) -> S.Ok:
        return guarded(lambda: session.nudge(who, body.dyaw, body.dpitch))

    @app.post(f"{API}/laser/confirm", response_model=S.Ok, tags=["laser"], responses=conflict)
    def confirm(who: Commander) -> S.Ok:
        """Light both beams: mark the object (or, holding one, where to place it)."""
        return guarded(lambda: session.confirm(who))

    @app.delete(f"{API}/laser", response_model=S.Ok, tags=["laser"], responses=conflict)
    def laser_off(who: Commander) -> S.Ok:
        return guarded(lambda: session.laser_off(who))

    @app.post(f"{API}/detect", response_model=S.Ok, tags=["grasps"], responses=conflict)
    def detect(who: Commander) -> S.Ok:
        """Find grasps again for the perceived target (with the current strategy)."""
        return guarded(lambda: session.detect(who))

    @app.post(f"{API}/grasps/next", response_model=S.Ok, tags=["grasps"], responses=conflict)
    def grasps_next(who: Commander, body: S.StepRequest | None = None) -> S.Ok:
        level = body.level if body is not None else "cluster"
        return guarded(lambda: session.step_grasp(who, +1, level))

    @app.post(f"{API}/grasps/prev", response_model=S.Ok, tags=["grasps"], responses=conflict)
    def grasps_prev(who: Commander, body: S.StepRequest | None = None) -> S.Ok:
        level = body.level if body is not None else "cluster"
        return guarded(lambda: session.step_grasp(who, -1, level))

    @app.post(f"{API}/grasps/select", response_model=S.Ok, tags=["grasps"], responses=conflict)
    def grasps_select(body: S.SelectRequest, who: Commander) -> S.Ok:
        return guarded(lambda: session.select_grasp(who, body.cluster, body.candidate))

    @app.post(f"{API}/grasps/auto", response_model=S.Ok, tags=["grasps"], responses=conflict)
    def grasps_auto(who: Commander) -> S.Ok:
        """Back to the system's choice: the best grasp of the best cluster."""
        return guarded(lambda: session.auto_grasp(who))

    @app.post(f"{API}/execute", response_model=S.Ok, tags=["task"], responses=conflict)
    def execute(who: Commander) -> S.Ok:
        """Pick with the current grasp (manual) or the best that plans (auto); when holding,
        drop the object in the basket."""
        return guarded(lambda: session.execute(who))

    @app.post(f"{API}/cancel", response_model=S.Ok, tags=["task"], responses=unauthorized)
    def cancel(who: Commander) -> S.Ok:
        return guarded(lambda: session.cancel(who))

    @app.post(f"{API}/mode", response_model=S.Ok, tags=["task"], responses=conflict)
    def mode(body: S.ModeRequest, who: Commander) -> S.Ok:
        return guarded(lambda: session.set_mode(who, body.mode, body.selection, body.strategy))

    @app.post(f"{API}/drive", response_model=S.Ok, tags=["motion"], responses=conflict)
    def drive(body: S.DriveRequest, who: Commander) -> S.Ok:
        """Drive the base (a dead-man: the command lapses after `duration`, at most 0.5 s)."""
        return guarded(lambda: session.drive(who, body.v, body.w, body.duration, body.seq))

    @app.post(f"{API}/stop", response_model=S.Ok, tags=["motion"], openapi_extra=token_optional)
    def stop(creds: Annotated[HTTPAuthorizationCredentials | None, Depends(bearer)]) -> S.Ok:
        """E-stop: halt the arm and the base now, latched until `POST /stop/reset`. Needs no
        token: anyone watching may stop the robot."""
        taken_at = sim_now()
        token = creds.credentials if creds else None
        source = session.lease.check(token) or "rest"
        session.stop(Actor(source, token))  # type: ignore[arg-type]
        return ok(taken_at)

    @app.post(f"{API}/stop/reset", response_model=S.Ok, tags=["motion"], responses=conflict)
    def stop_reset(who: Commander) -> S.Ok:
        return guarded(lambda: session.reset_stop(who))

    @app.post(f"{API}/scene", response_model=S.Ok, tags=["task"], responses=conflict)
    def scene(body: S.SceneRequest, who: Commander) -> S.Ok:
        """Reset to a built-in scene, or to an uploaded scene file with its meshes."""
        try:
            if body.name is not None:
                new = load_scene(body.name, seed=body.seed)
            else:
                assert body.yaml is not None
                new = _uploaded_scene(body.yaml, body.files, body.seed)
        except SceneError as exc:
            raise _unprocessable("body", str(exc)) from None
        return guarded(lambda: session.reset_scene(who, new))

    # --- the events websocket ------------------------------------------------------------

    @app.websocket(f"{API}/events")
    async def events(ws: WebSocket) -> None:
        """State frames at 30 Hz and discrete events, as JSON text. Send
        `{"type": "heartbeat", "token": "..."}` to keep the lease; the controller's socket
        closing halts motion at once."""
        await ws.accept()
        client = _Client()
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
                text = await ws.receive_text()
                hub.offer(client, json.dumps(_on_message(session, client, text)))
        except (WebSocketDisconnect, RuntimeError):
            pass
        finally:
            hub.clients.discard(client)
            sender.cancel()
            if client.token is not None:
                session.lease.connection_lost(client.token)

    return app


async def _pump(ws: WebSocket, client: _Client) -> None:
    with contextlib.suppress(Exception):
        while True:
            text = await client.queue.get()
            await ws.send_text(text)


def _on_message(session: Session, client: _Client, text: str) -> dict[str, Any]:
    """Handle one client message: a heartbeat is acknowledged, anything else refused."""
    try:
        msg = json.loads(text)
    except ValueError:
        return {"type": "error", "detail": "messages must be JSON objects"}
    if not isinstance(msg, dict) or msg.get("type") != "heartbeat":
        return {"type": "error", "detail": 'unknown message; send {"type": "heartbeat"}'}
    token = msg.get("token", client.token)
    if not isinstance(token, str) or not session.lease.heartbeat(token):
        return {"type": "error", "detail": "heartbeat without a token that holds the lease"}
    client.token = token
    # The client's own `sent` value comes back, so it can time the round trip on its clock.
    return {"type": "heartbeat_ack", "echo": msg.get("sent"), "t": time.time()}


def _round(v: np.ndarray) -> list[float]:
    return [round(float(x), 4) for x in v]


def _unprocessable(where: str, message: str) -> HTTPException:
    return HTTPException(422, {"detail": [{"loc": [where], "msg": message, "type": "value_error"}]})


def _uploaded_scene(text: str, files: dict[str, str], seed: int | None):
    """Parse an uploaded scene whose meshes came along as base64, in a private directory
    (file names were checked to be plain names, so nothing lands outside it)."""
    with tempfile.TemporaryDirectory(prefix="laserpick-scene-") as tmp:
        base = Path(tmp)
        for name, data in files.items():
            try:
                raw = base64.b64decode(data, validate=True)
            except ValueError:
                raise SceneError("<upload>", [(f"files.{name}", "not valid base64")]) from None
            (base / name).write_bytes(raw)
        return parse_scene(text, source=base / "uploaded.yaml", base_dir=base, seed=seed)


_MINIMAL_PAGE = """<!doctype html><html lang="en"><meta charset="utf-8">
<title>laserpick</title><h1>laserpick</h1>
<p>The API is documented at <a href="/docs">/docs</a>.</p></html>"""
