"""The `laserpick` console script.

    laserpick serve [--host 127.0.0.1] [--port 8000] [--viser-port 8080] [--scene isolation]
                    [--journal FILE] [--recorded DIR]
    laserpick record OUT --scene NAME [--seed S] [--aim-at-object INSTANCE]
    laserpick adapter switch|joystick ...
    laserpick bench --protocol P [--trials N] [--seed S] [--selection auto|manual]
                    [--strategy gpd|overhead|jeeves] [--scene FILE] [--out FILE.json]
                    [--workers N] [--ray ADDRESS] [--tremor DEG] [--objects N]
    laserpick bench --compare OLD.json NEW.json [--tolerance T]

`serve` loads a scene (a built-in name or a YAML path), runs the real-time simulation and the
operator session, serves the page and the API (uvicorn) and the viser 3D view, and records
the session in the journal. It prints `laserpick: console at http://HOST:PORT/` once the API
is up, and shuts down cleanly on Ctrl-C or SIGTERM.

Security: it binds the loopback interface by default. Binding anything else is refused unless
`LASERPICK_OPERATOR_PASSWORD` is set, because whoever reaches the ports can watch or command
a robot; taking control then needs that password. The viser port has no authentication of its
own, so on a non-loopback host the 3D view is view-only (no Pause button) and should sit
behind the TLS proxy in deploy/.

`serve --recorded DIR` serves a recording instead (`robot.recorded.RecordedRobot`): the
pipeline runs on the recorded frames and nothing moves; no simulator is loaded, and the 3D
view is not served. `record` writes such a recording from a scene simulated headless, with the
laser confirmed on an object if asked (the format: docs/recording.md).

`bench` reruns one of the papers' experiments with the scripted operator (docs/bench.md);
`bench --compare` lists the attempts that differ between two of its result files.

Exit codes: 0 clean shutdown (or a finished benchmark, or two results with no difference),
1 a benchmark trial broke off (the others' results are still written) or the compared results
differ, 2 bad usage (unknown scene, refused host, a bad count, an unreadable result file).
"""

from __future__ import annotations

import argparse
import asyncio
import ipaddress
import logging
import os
import signal
import socket
import sys
import uuid
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import viser
    from fastapi import FastAPI

    from laserpick.console.operator_console import OperatorConsole
    from laserpick.console.viewer import SceneViewer
    from laserpick.server.journal import Journal
    from laserpick.server.session import Session

PASSWORD_ENV = "LASERPICK_OPERATOR_PASSWORD"
EXIT_USAGE = 2
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


def _say(msg: str, *, err: bool = False) -> None:
    print(f"laserpick: {msg}", file=sys.stderr if err else sys.stdout, flush=True)


def is_loopback(host: str) -> bool:
    """True if `host` names only the loopback interface (127.0.0.0/8, ::1, localhost)."""
    if host.strip().lower() in ("localhost", "localhost.", "ip6-localhost"):
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        pass
    try:
        infos = socket.getaddrinfo(host, None)
    except OSError:
        return False
    addrs = {info[4][0] for info in infos}
    return bool(addrs) and all(ipaddress.ip_address(a.split("%")[0]).is_loopback for a in addrs)


def _url_host(host: str) -> str:
    if host in ("0.0.0.0", "::", ""):
        return socket.gethostname()
    return f"[{host}]" if ":" in host else host


def build_parser() -> argparse.ArgumentParser:
    """The argument parser: one subcommand per verb (`serve`, `adapter`, `bench`)."""
    parser = argparse.ArgumentParser(
        prog="laserpick",
        description="Assistive laser-directed pick and place: a UR5 on a mobility scooter.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
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
    _add_record_parser(sub)
    _add_adapter_parser(sub)
    _add_bench_parser(sub)
    return parser


def _add_record_parser(sub: argparse._SubParsersAction) -> None:
    """`laserpick record OUT --scene NAME`: a recording from a scene simulated headless."""
    record = sub.add_parser(
        "record",
        help="capture a simulated scene into a recording (serve it with serve --recorded)",
        description="Load a scene headless, let it settle, optionally confirm the laser on an"
        " object, capture once, and write the recording (format: docs/recording.md).",
    )
    record.add_argument("out", type=Path, metavar="OUT", help="a new (or empty) directory")
    record.add_argument("--scene", required=True, help="a built-in scene name or a scene YAML path")
    record.add_argument("--seed", type=int, help="the scene's random placement seed")
    record.add_argument(
        "--aim-at-object",
        metavar="INSTANCE",
        help="confirm the laser (both beams) on this object before capturing",
    )
    record.set_defaults(func=cmd_record)


def _add_adapter_parser(sub: argparse._SubParsersAction) -> None:
    """`laserpick adapter switch|joystick`: accessibility input adapters, run as separate
    clients of a server's public API (see `laserpick/adapters/` and the README)."""
    adapter = sub.add_parser(
        "adapter", help="run an input adapter (switch, joystick) against a running server"
    )
    kinds = adapter.add_subparsers(dest="adapter", metavar="ADAPTER", required=True)
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument(
        "--url", default="http://127.0.0.1:8000", help="the server (default %(default)s)"
    )
    common.add_argument(
        "--source",
        default="keyboard",
        help="evdev:NAME_OR_PATH | keyboard | script:FILE (default %(default)s)",
    )
    common.add_argument("--name", default=None, help="the name others see holding control")
    common.add_argument(
        "--speak", action="store_true", help="also announce through espeak-ng (if installed)"
    )
    common.add_argument(
        "--step", type=float, default=0.02, help="laser nudge per step (rad, default 0.02)"
    )
    common.add_argument(
        "--speed", type=float, default=0.2, help="driving speed (m/s, default %(default)s)"
    )
    common.add_argument(
        "--turn", type=float, default=0.4, help="turning rate (rad/s, default %(default)s)"
    )
    common.add_argument(
        "--map",
        action="append",
        default=[],
        metavar="CODE=NAME",
        help="evdev: bind a key, button or axis code to a control (repeatable)",
    )
    common.add_argument(
        "--record", type=Path, default=None, help="write the input to FILE, as an event file"
    )
    switch = kinds.add_parser("switch", parents=[common], help="one-switch or two-switch scanning")
    switch.add_argument("--mode", choices=("one-switch", "two-switch"), default="one-switch")
    switch.add_argument(
        "--scan-period", type=float, default=1.0, help="s per highlighted item (one-switch)"
    )
    switch.add_argument(
        "--cycles", type=int, default=3, help="scan passes before stopping (0: never)"
    )
    switch.add_argument("--accept", type=float, default=0.1, help="s a press must be held to count")
    switch.add_argument(
        "--release", type=float, default=0.1, help="s after a release that presses are ignored"
    )
    switch.add_argument(
        "--delay", type=float, default=0.0, help="s before a selection acts (undo window)"
    )
    joystick = kinds.add_parser(
        "joystick", parents=[common], help="a stick as a pan-tilt laser, or sip-and-puff"
    )
    joystick.add_argument("--preset", choices=("stick", "sip-puff"), default="stick")
    joystick.add_argument(
        "--dead-zone", type=float, default=0.15, help="stick travel read as zero (fraction)"
    )
    joystick.add_argument("--rate", type=float, default=0.4, help="beam rad/s at full deflection")
    joystick.add_argument(
        "--hold", type=float, default=0.3, help="sip-puff: s before a held sip or puff moves"
    )
    joystick.add_argument(
        "--double", type=float, default=0.4, help="sip-puff: s between taps that switch mode"
    )
    adapter.set_defaults(func=cmd_adapter)


def _add_bench_parser(sub: argparse._SubParsersAction) -> None:
    """`laserpick bench`: rerun a paper's experiment (docs/bench.md), or compare two of its
    result files."""
    from laserpick.bench import PROTOCOL_NAMES  # not .protocols: that loads the simulator

    bench = sub.add_parser(
        "bench",
        help="rerun a paper's experiment in simulation and report it beside the paper's table",
        description="Run a benchmark protocol with the scripted operator and write the result"
        " JSON, a Markdown report and PNG plots (the schema is in docs/bench.md).",
    )
    bench.add_argument("--protocol", choices=PROTOCOL_NAMES, help="which experiment (required)")
    bench.add_argument("--trials", type=int, help="trials to run (default: the paper's number)")
    bench.add_argument("--seed", type=int, default=1, help="trial k uses seed SEED + k")
    bench.add_argument("--selection", choices=["auto", "manual"], help="grasp selection")
    bench.add_argument("--strategy", choices=["gpd", "overhead", "jeeves"], help="grasp strategy")
    bench.add_argument("--scene", type=Path, help="a scene YAML file to use instead")
    bench.add_argument(
        "--out", type=Path, help="result JSON (default: bench-results/PROTOCOL.json)"
    )
    bench.add_argument(
        "--workers",
        type=int,
        default=os.cpu_count() or 1,
        help="local worker processes (default: one per core)",
    )
    bench.add_argument("--ray", metavar="ADDRESS", help="run the trials on this Ray cluster")
    bench.add_argument(
        "--tremor", type=float, default=0.3, help="aim noise, deg standard deviation (0.3)"
    )
    bench.add_argument("--objects", type=int, help="at most this many objects per trial")
    bench.add_argument(
        "--compare",
        nargs=2,
        type=Path,
        metavar=("OLD.json", "NEW.json"),
        help="run nothing: list the attempts that differ between two result files (exit 1 if"
        " any differ)",
    )
    bench.add_argument(
        "--tolerance",
        type=float,
        default=0.0,
        help="with --compare: how far floats may differ (absolute, m or s; default 0: exactly)",
    )
    bench.set_defaults(func=cmd_bench)


def cmd_adapter(args: argparse.Namespace) -> int:
    """Run an input adapter until its input ends (a script's end, q, Ctrl-C or SIGTERM)."""
    from laserpick.adapters.launch import run  # lazy: `laserpick --help` stays fast

    return run(args)


def cmd_bench_compare(old: Path, new: Path, tolerance: float) -> int:
    """List the attempts that differ between two result files: 0 when none does, 1 when
    some do, 2 when a file cannot be read or the two ran another protocol or seed."""
    from laserpick.bench.compare import compare_files, format_comparison

    try:
        comparison = compare_files(old, new, tolerance)
    except ValueError as exc:  # unreadable, mismatched, or a bad tolerance
        _say(str(exc), err=True)
        return EXIT_USAGE
    print(format_comparison(comparison, str(old), str(new)), end="")
    return 0 if comparison.same else 1


def cmd_bench(args: argparse.Namespace) -> int:
    """Run a protocol with a progress bar; write the JSON, the report and the plots. With
    --compare, compare two result files instead."""
    if args.compare is not None:
        if args.protocol is not None:
            _say("--compare compares two result files; it takes no --protocol", err=True)
            return EXIT_USAGE
        return cmd_bench_compare(*args.compare, args.tolerance)
    if args.protocol is None:
        _say("bench needs --protocol (or --compare OLD.json NEW.json)", err=True)
        return EXIT_USAGE
    return run_bench(args)


def run_bench(args: argparse.Namespace) -> int:
    """Run the protocol of `args` with a progress bar; write the JSON, the report and the
    plots."""
    import json

    from laserpick.bench.protocols import PROTOCOLS, Options
    from laserpick.bench.report import markdown, write_reports
    from laserpick.bench.runner import progress_bar, run
    from laserpick.robot.sim.scenes import SceneError, load_scene

    spec = PROTOCOLS[args.protocol]
    for name, value in (("--trials", args.trials), ("--workers", args.workers)):
        if value is not None and value < 1:
            _say(f"{name} must be at least 1", err=True)
            return EXIT_USAGE
    if args.objects is not None and args.objects < 1:
        _say("--objects must be at least 1", err=True)
        return EXIT_USAGE
    if args.scene is not None:
        try:
            load_scene(args.scene)
        except SceneError as exc:
            _say(str(exc), err=True)
            return EXIT_USAGE
    options = Options(
        selection=args.selection or spec.selection,
        strategy=args.strategy or spec.strategy,
        scene=str(args.scene.resolve()) if args.scene else None,
        tremor_deg=args.tremor,
        objects=args.objects,
    )
    trials = args.trials or spec.trials
    out = args.out or Path("bench-results") / f"{args.protocol}.json"
    _say(f"{args.protocol} ({spec.source}): {trials} trials, seed {args.seed}")
    result = run(
        args.protocol,
        trials=trials,
        seed=args.seed,
        options=options,
        workers=min(args.workers, trials),
        ray_address=args.ray,
        progress=progress_bar(args.protocol),
    )
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(result, indent=1))
    written = [out, *write_reports(result, out)]
    print(markdown(result))
    _say("wrote " + ", ".join(str(p) for p in written))
    if result["errors"]:
        _say(f"{len(result['errors'])} trials broke off (see 'errors' in {out})", err=True)
        return 1
    return 0


def default_journal() -> Path:
    """Where the journal lives by default: $XDG_DATA_HOME/laserpick/journal.sqlite3."""
    root = os.environ.get("XDG_DATA_HOME") or str(Path.home() / ".local" / "share")
    return Path(root) / "laserpick" / "journal.sqlite3"


def _serve_usage_problem(args: argparse.Namespace, loopback: bool) -> str | None:
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
    """The viser server, with the 3D scene view and the operator console drawn on it."""

    def __init__(self) -> None:
        self.server: viser.ViserServer | None = None
        self.viewer: SceneViewer | None = None
        self.console: OperatorConsole | None = None

    def start(self, args: argparse.Namespace, session: Session, loopback: bool) -> int:
        """Start the server on --viser-port, the view and the console (with controls only on
        loopback); the port it took."""
        import viser

        from laserpick.console.operator_console import OperatorConsole
        from laserpick.console.viewer import SceneViewer

        self.server = viser.ViserServer(
            host=args.host, port=args.viser_port, label="laserpick", verbose=False
        )
        from laserpick.robot.sim.world_view import SimWorld

        viewer = self.viewer = SceneViewer(
            session.robot,
            self.server,
            world=SimWorld(session.robot.sim),  # type: ignore[attr-defined]
            rate_hz=args.viewer_rate,
            controls=False,
            lite=args.lite_view,
        )
        viewer.start()
        session.on_scene(lambda robot: viewer.set_robot(robot, SimWorld(robot.sim)))  # type: ignore[attr-defined]
        self.console = OperatorConsole(session, self.server, controls=loopback)
        self.console.start()
        port = self.server.get_port()
        if port != args.viser_port and args.viser_port != 0:
            _say(f"port {args.viser_port} was busy; the 3D view took {port}", err=True)
        if not loopback:
            _say(
                "the 3D view's port has no authentication of its own: it is view-only here; "
                "put it behind the TLS proxy (deploy/)",
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
    problem = _serve_usage_problem(args, loopback)
    if problem is not None:
        _say(problem, err=True)
        return EXIT_USAGE

    if args.recorded is not None:
        return serve_recording(args)

    # Heavy imports only once the arguments are sane: `laserpick --help` stays fast.
    from laserpick.robot.sim.scenes import load_scene

    try:
        scene = load_scene(args.scene)
    except Exception as exc:
        _say(f"cannot load scene {args.scene!r}: {exc}", err=True)
        return EXIT_USAGE
    journal = open_journal(args.journal)
    if journal is None:
        return EXIT_USAGE

    from laserpick.robot.sim.robot import SimRobot
    from laserpick.server.session import Session

    session = Session(SimRobot(scene, realtime=True), journal=journal)
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
        _say(f"cannot open the journal: {exc}", err=True)
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
            _say(f"console at http://{_url_host(host)}:{bound}/")
            if viser_port is not None:
                _say(f"3D view at http://{_url_host(host)}:{viser_port}/")
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
    _say("shutting down")
    return 0 if api.started else 1


def serve_recording(args: argparse.Namespace) -> int:
    """`serve --recorded DIR`: the session on a `RecordedRobot`, the page and the API; no
    simulator, no 3D view."""
    from laserpick.robot.recorded import RecordedRobot
    from laserpick.robot.recording import RecordingError, read_recording

    try:
        recording = read_recording(args.recorded)
    except RecordingError as exc:
        _say(str(exc), err=True)
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
        _say(f"serving {args.recorded} ({count}): it cannot move; no 3D view", err=True)
        return run_api(create_app(session), args.host, args.port, None)
    finally:
        session.close()
        journal.close()


def cmd_record(args: argparse.Namespace) -> int:
    """Simulate a scene headless, let it settle, confirm the laser on an object if asked,
    capture once, and write the recording to `args.out`."""
    from laserpick.robot.sim.scenes import load_scene

    out: Path = args.out
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        _say(f"{out} already exists and is not an empty directory; choose another", err=True)
        return EXIT_USAGE
    try:
        scene = load_scene(args.scene, seed=args.seed)
    except Exception as exc:
        _say(f"cannot load scene {args.scene!r}: {exc}", err=True)
        return EXIT_USAGE
    instances = [p.instance for p in scene.placements]
    target = args.aim_at_object
    if target is not None and target not in instances:
        _say(
            f"scene {scene.name!r} has no object {target!r}; it has: {', '.join(instances)}",
            err=True,
        )
        return EXIT_USAGE

    from laserpick.pipeline.cloud import fuse
    from laserpick.robot.recording import Hint, Recording, capture_from, write_recording
    from laserpick.robot.sim.truth import capture

    _say(f"simulating scene {scene.name!r} headless and letting it settle", err=True)
    captured = capture(scene)
    try:
        hint = None
        if target is not None:
            top = captured.visible_top(fuse(captured.frames), target)
            if top is None:
                _say(f"no camera sees {target!r}: the laser cannot be aimed at it", err=True)
                return 1
            captured.robot.laser.aim_at(top)
            captured.robot.laser.confirm()
            hint = Hint(target, top)
            where = ", ".join(f"{v:.3f}" for v in top)
            _say(f"laser confirmed on {target!r}, its top at ({where}) m in base", err=True)
        _say("capturing", err=True)
        seed = "the scene's seed" if args.seed is None else f"seed {args.seed}"
        recording = Recording(
            (capture_from(captured.robot, hint),),
            captured.robot.projector(),
            source=f"laserpick record: scene {scene.name!r}, {seed}",
        )
        write_recording(out, recording)
    finally:
        captured.close()
    _say(f"wrote {out}: 1 capture from {len(recording.cameras)} cameras", err=True)
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the `laserpick` script; returns the process exit code."""
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    parser = build_parser()
    args = parser.parse_args(argv)
    return int(args.func(args))


if __name__ == "__main__":
    sys.exit(main())
