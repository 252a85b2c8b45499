"""`laserpick serve`: the operator session on a simulated or recorded robot, the page and the
API (uvicorn), the viser 3D view and the journal, until SIGINT or SIGTERM."""

from __future__ import annotations

import argparse
import asyncio
import os
import signal
import uuid
from pathlib import Path
from typing import TYPE_CHECKING

from laserpick.cli.common import (
    EXIT_USAGE,
    PASSWORD_ENV,
    STOP_SIGNALS,
    default_journal,
    is_loopback,
    rendering_problem,
    say,
    url_host,
)
from laserpick.server.heap import fix_mmap_threshold, limit_malloc_arenas

if TYPE_CHECKING:
    import viser
    from fastapi import FastAPI

    from laserpick.console.operator_console import OperatorConsole
    from laserpick.console.viewer import SceneViewer
    from laserpick.server.journal import Journal
    from laserpick.server.session import Session

__all__ = ["add_serve_parser", "cmd_serve", "open_journal", "run_api"]


def add_serve_parser(sub: argparse._SubParsersAction) -> None:
    """`laserpick serve`: the robot (simulated or recorded), the API, the page, the 3D view."""
    serve = sub.add_parser("serve", help="run the simulation and the browser console")
    serve.add_argument(
        "--host",
        default="127.0.0.1",
        help=f"interface to bind (default 127.0.0.1; others need ${PASSWORD_ENV})",
    )
    serve.add_argument(
        "--port",
        type=int,
        default=8000,
        help="HTTP port of the page and the API (default 8000; 0 picks a free one)",
    )
    serve.add_argument("--viser-port", type=int, default=8080, help="3D view (viser) port")
    serve.add_argument(
        "--viser-url",
        default=None,
        help="URL or path where browsers reach the 3D view, when not at --viser-port on the"
        " page's host (behind deploy/'s proxy: /viser/)",
    )
    serve.add_argument(
        "--journal",
        type=Path,
        default=None,
        help="SQLite journal of the session (default $XDG_DATA_HOME/laserpick/journal.sqlite3)",
    )
    world = serve.add_mutually_exclusive_group()
    world.add_argument(
        "--scene",
        default="isolation",
        help="a built-in scene name (isolation, kitchen, surfaces, jeeves) or a YAML path",
    )
    world.add_argument(
        "--recorded",
        type=Path,
        metavar="DIR",
        help="serve this recording (laserpick record) instead of a simulated scene",
    )
    serve.add_argument("--viewer-rate", type=float, default=40.0, help="3D view updates (Hz)")
    serve.add_argument(
        "--lite-view",
        action="store_true",
        help="draw the 3D view for browsers without a GPU: no shadows or environment "
        "lighting, flat shading (3x faster in software WebGL)",
    )
    serve.set_defaults(func=cmd_serve)


def serve_usage_problem(args: argparse.Namespace, loopback: bool) -> str | None:
    """Why `serve` refuses `args` (a non-loopback host without a password, a bad port), or
    None."""
    if not loopback and not os.environ.get(PASSWORD_ENV):
        return (
            f"refusing to bind {args.host!r}: it is not a loopback address, and anyone who "
            f"reaches it could watch or command the robot. Set {PASSWORD_ENV} to allow it, "
            "or use --host 127.0.0.1."
        )
    for name in ("port", "viser_port"):
        value = getattr(args, name)
        if not 0 <= value <= 65535:
            return f"--{name.replace('_', '-')} {value} is not a TCP port"
    return None


class _ViewServer:
    """The viser server, with the 3D scene view (the simulated world as its layer) and the
    operator console drawn on it."""

    def __init__(self) -> None:
        self.server: viser.ViserServer | None = None
        self.viewer: SceneViewer | None = None
        self.console: OperatorConsole | None = None

    def start(self, args: argparse.Namespace, session: Session, loopback: bool) -> int:
        """Start the server on --viser-port, the view and the console (whose controls act
        only for the clients its door lets in: `console.view_door`); the port it took."""
        import viser

        from laserpick.console.operator_console import OperatorConsole
        from laserpick.console.viewer import SceneViewer
        from laserpick.robot.sim.world_view import SimWorld

        self.server = viser.ViserServer(
            host=args.host, port=args.viser_port, label="laserpick", verbose=False
        )
        viewer = self.viewer = SceneViewer(
            session.robot,
            self.server,
            world=SimWorld(session.robot.sim),  # type: ignore[attr-defined]
            rate_hz=args.viewer_rate,
            lite=args.lite_view,
        )
        viewer.start()
        session.on_scene(lambda robot: viewer.set_robot(robot, SimWorld(robot.sim)))  # type: ignore[attr-defined]
        self.console = OperatorConsole(session, self.server)
        self.console.start()
        port = self.server.get_port()
        if port != args.viser_port and args.viser_port != 0:
            say(f"port {args.viser_port} was busy; the 3D view took {port}", err=True)
        if not loopback:
            say(
                "the 3D view's port has no login of its own: its controls act only for the "
                "operator page's lease, and anyone reaching it sees the scene; put it behind "
                "the TLS proxy (deploy/)",
                err=True,
            )
        return port

    def stop_drawing(self) -> None:
        """Stop the console and the view (before the session closes)."""
        if self.console is not None:
            self.console.stop()
        if self.viewer is not None:
            self.viewer.stop()

    def stop_server(self) -> None:
        if self.server is not None:
            self.server.stop()


def _api_app(session: Session, viser_port: int, viser_url: str | None) -> FastAPI:
    """The API around `session`, with the simulator's routes when its robot is simulated."""
    from laserpick.robot.sim.robot import SimRobot
    from laserpick.server.app import create_app

    app = create_app(session, viser_port=viser_port, viser_url=viser_url)
    if isinstance(session.robot, SimRobot):
        from laserpick.robot.sim.service import SimulatorService
        from laserpick.server.routers.simulation import include_simulator

        include_simulator(app, SimulatorService(session.settings))
    return app


def cmd_serve(args: argparse.Namespace) -> int:
    """Run the simulation, the API and the 3D console until SIGINT or SIGTERM."""
    loopback = is_loopback(args.host)
    problem = serve_usage_problem(args, loopback)
    if problem is not None:
        say(problem, err=True)
        return EXIT_USAGE

    # Before any thread and any large array: see `server.heap`.
    limit_malloc_arenas()
    fix_mmap_threshold()
    if args.recorded is not None:
        return serve_recording(args)
    problem = rendering_problem()
    if problem is not None:
        say(problem, err=True)
        return EXIT_USAGE

    # Heavy imports only once the arguments are sane: `laserpick --help` stays fast.
    from laserpick.robot.sim.scenes import load_scene

    try:
        scene = load_scene(args.scene)
    except Exception as exc:
        say(f"cannot load scene {args.scene!r}: {exc}", err=True)
        return EXIT_USAGE
    journal = open_journal(args.journal)
    if journal is None:
        return EXIT_USAGE

    from laserpick.behaviours import warm_drop_postures
    from laserpick.robot.sim.robot import SimRobot
    from laserpick.server.session import Session

    session = Session(SimRobot(scene, realtime=True), journal=journal)
    warm_drop_postures(session.settings.behaviour)  # while the page loads, not at the first pick
    views = _ViewServer()
    try:
        viser_port = views.start(args, session, loopback)
        app = _api_app(session, viser_port, args.viser_url)
        return run_api(app, args.host, args.port, viser_port)
    finally:
        views.stop_drawing()
        session.close()
        views.stop_server()
        journal.close()


def open_journal(path: Path | None) -> Journal | None:
    """The session's journal at `path` (default `default_journal()`), or None, said why."""
    from laserpick.server.journal import Journal, JournalError

    try:
        return Journal(path or default_journal(), session=uuid.uuid4().hex)
    except (JournalError, OSError) as exc:
        say(f"cannot open the journal: {exc}", err=True)
        return None


def run_api(app: FastAPI, host: str, port: int, viser_port: int | None) -> int:
    """Serve `app` with uvicorn until SIGINT or SIGTERM; 0 once shut down, 1 if it never
    started. Prints the console's URL (and the 3D view's) once the API is up."""
    import uvicorn

    config = uvicorn.Config(
        app,
        host=host,
        port=port,
        log_level="warning",
        ws="websockets-sansio",
    )
    api = uvicorn.Server(config)

    async def serve() -> None:
        task = asyncio.create_task(api.serve())
        while not api.started and not task.done():
            await asyncio.sleep(0.05)
        if api.started:
            bound = api.servers[0].sockets[0].getsockname()[1]
            say(f"console at http://{url_host(host)}:{bound}/")
            if viser_port is not None:
                say(f"3D view at http://{url_host(host)}:{viser_port}/")
        await task

    # uvicorn turns SIGINT and SIGTERM into a graceful shutdown, then raises the signal
    # again with the handlers it found; with these no-op handlers in place, that second
    # signal ends nothing, and the caller's cleanup (halt, journal) still runs.
    previous = {sig: signal.signal(sig, lambda *_: None) for sig in STOP_SIGNALS}
    try:
        asyncio.run(serve())
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    say("shutting down")
    return 0 if api.started else 1


def serve_recording(args: argparse.Namespace) -> int:
    """`serve --recorded DIR`: the session on a `RecordedRobot`, the page and the API; no
    simulator, no 3D view."""
    from laserpick.robot.recorded import RecordedRobot
    from laserpick.robot.recording import RecordingError, read_recording

    try:
        recording = read_recording(args.recorded)
    except RecordingError as exc:
        say(str(exc), err=True)
        return EXIT_USAGE
    journal = open_journal(args.journal)
    if journal is None:
        return EXIT_USAGE

    from laserpick.server.app import create_app
    from laserpick.server.session import Session

    session = Session(RecordedRobot(recording), journal=journal)
    try:
        n = len(recording.captures)
        count = f"{n} capture" + ("s" if n != 1 else "")
        say(f"serving {args.recorded} ({count}): it cannot move; no 3D view", err=True)
        return run_api(create_app(session), args.host, args.port, None)
    finally:
        session.close()
        journal.close()
