"""`laserpick adapter switch|joystick`: an input adapter, a client of the API (docs/adapters.md)."""

from __future__ import annotations

import argparse
from pathlib import Path

__all__ = ["add_adapter_parser", "cmd_adapter"]


def add_adapter_parser(sub: argparse._SubParsersAction) -> None:
    """`laserpick adapter switch|joystick`: accessibility input adapters, run as separate
    clients of a server's public API (see `laserpick/adapters/` and docs/adapters.md)."""
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


def cmd_adapter(args: argparse.Namespace) -> int:
    """Run an input adapter until its input ends (a script's end, q, Ctrl-C or SIGTERM)."""
    from laserpick.adapters.launch import run  # lazy: `laserpick --help` stays fast

    return run(args)
