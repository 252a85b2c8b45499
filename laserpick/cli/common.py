"""What every `laserpick` subcommand shares: how it speaks, exit codes, loopback checks, the
journal's default place, and the check that MuJoCo can render before it is loaded."""

from __future__ import annotations

import ipaddress
import os
import signal
import socket
import sys
from pathlib import Path

__all__ = [
    "EXIT_USAGE",
    "PASSWORD_ENV",
    "STOP_SIGNALS",
    "default_journal",
    "is_loopback",
    "rendering_problem",
    "say",
    "url_host",
]

PASSWORD_ENV = "LASERPICK_OPERATOR_PASSWORD"


EXIT_USAGE = 2


STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


def say(msg: str, *, err: bool = False) -> None:
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


def url_host(host: str) -> str:
    if host in ("0.0.0.0", "::", ""):
        return socket.gethostname()
    return f"[{host}]" if ":" in host else host


def default_journal() -> Path:
    """Where the journal lives by default: $XDG_DATA_HOME/laserpick/journal.sqlite3."""
    root = os.environ.get("XDG_DATA_HOME") or str(Path.home() / ".local" / "share")
    return Path(root) / "laserpick" / "journal.sqlite3"


def rendering_problem() -> str | None:
    """Why MuJoCo cannot render here (one sentence naming what to install or set), or None
    once its OpenGL backend is chosen. Call before anything imports the simulator."""
    from laserpick.robot.gl_backend import GLBackendError, choose_gl_backend

    try:
        choose_gl_backend()
    except GLBackendError as exc:
        return str(exc)
    return None
