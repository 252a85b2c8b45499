"""The `laserpick` console script.

    laserpick serve [--host 127.0.0.1] [--port 8000] [--viser-port 8080] [--scene isolation]

`serve` loads a scene (a built-in name or a YAML path), runs the real-time simulation, and
serves the viser 3D console. It prints `laserpick: console at http://HOST:PORT` once the
console is up, and shuts down cleanly on Ctrl-C or SIGTERM.

Security: it binds the loopback interface by default. Binding anything else is refused unless
`LASERPICK_OPERATOR_PASSWORD` is set, because whoever reaches the ports can watch (and, once
the HTTP API lands, command) a robot. The viser port has no authentication of its own, so on a
non-loopback host the console is view-only (no Pause button) and should sit behind the TLS
proxy in deploy/.

Exit codes: 0 clean shutdown, 2 bad usage (unknown scene, refused host).
"""

from __future__ import annotations

import argparse
import ipaddress
import logging
import os
import signal
import socket
import sys
import threading
from collections.abc import Sequence
from types import FrameType

PASSWORD_ENV = "LASERPICK_OPERATOR_PASSWORD"
EXIT_USAGE = 2


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
    """The argument parser: one subcommand per verb (`serve`; `bench` and `adapter` later)."""
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
        help="HTTP API port (reserved: the API is not served yet)",
    )
    serve.add_argument("--viser-port", type=int, default=8080, help="3D console port")
    serve.add_argument(
        "--scene",
        default="isolation",
        help="a built-in scene name (isolation, kitchen, surfaces, jeeves) or a YAML path",
    )
    serve.add_argument("--viewer-rate", type=float, default=40.0, help="3D view updates (Hz)")
    serve.add_argument(
        "--no-shadows",
        dest="shadows",
        action="store_false",
        help="no shadows in the 3D view (for browsers without a GPU)",
    )
    serve.set_defaults(func=cmd_serve)
    return parser


def cmd_serve(args: argparse.Namespace) -> int:
    """Run the simulation and the 3D console until SIGINT or SIGTERM."""
    loopback = is_loopback(args.host)
    if not loopback and not os.environ.get(PASSWORD_ENV):
        _say(
            f"refusing to bind {args.host!r}: it is not a loopback address, and anyone who "
            f"reaches it could watch or command the robot. Set {PASSWORD_ENV} to allow it, "
            "or use --host 127.0.0.1.",
            err=True,
        )
        return EXIT_USAGE
    for name in ("port", "viser_port"):
        value = getattr(args, name)
        if not 0 <= value <= 65535:
            _say(f"--{name.replace('_', '-')} {value} is not a TCP port", err=True)
            return EXIT_USAGE

    # Heavy imports only once the arguments are sane: `laserpick --help` stays fast.
    from laserpick.robot.scenes import load_scene

    try:
        scene = load_scene(args.scene)
    except Exception as exc:
        _say(f"cannot load scene {args.scene!r}: {exc}", err=True)
        return EXIT_USAGE

    import viser

    from laserpick.console.viewer import SceneViewer
    from laserpick.robot.sim import Simulation

    stop = threading.Event()

    def on_signal(signum: int, _frame: FrameType | None) -> None:
        stop.set()

    previous = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
    sim = Simulation(scene, realtime=True)
    server: viser.ViserServer | None = None
    viewer: SceneViewer | None = None
    try:
        sim.start()
        server = viser.ViserServer(
            host=args.host, port=args.viser_port, label="laserpick", verbose=False
        )
        viewer = SceneViewer(
            sim, server, rate_hz=args.viewer_rate, controls=loopback, shadows=args.shadows
        )
        viewer.start()
        port = server.get_port()
        if port != args.viser_port and args.viser_port != 0:
            _say(f"port {args.viser_port} was busy; the console took {port}", err=True)
        if not loopback:
            _say(
                "the 3D console port has no authentication of its own: it is view-only here; "
                "put it behind the TLS proxy (deploy/)",
                err=True,
            )
        _say(f"console at http://{_url_host(args.host)}:{port}")
        while not stop.wait(0.2):
            pass
        _say("shutting down")
    finally:
        if viewer is not None:
            viewer.stop()
        sim.close()
        if server is not None:
            server.stop()
        for s, handler in previous.items():
            signal.signal(s, handler)
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the `laserpick` script; returns the process exit code."""
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    parser = build_parser()
    args = parser.parse_args(argv)
    return int(args.func(args))


if __name__ == "__main__":
    sys.exit(main())
