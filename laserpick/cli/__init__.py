"""The `laserpick` console script.

    laserpick serve [--host 127.0.0.1] [--port 8000] [--viser-port 8080] [--viser-url URL]
                    [--scene isolation | --recorded DIR] [--journal FILE]
                    [--viewer-rate HZ] [--lite-view]
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
a robot; taking control then needs that password. The viser port has no login of its own:
its controls act only for the operator page's control lease (the page hands the view its
token), except for a browser on this computer connected straight to a server without a
password; everyone else sees the scene only. Put it behind the TLS proxy in deploy/.

`serve --recorded DIR` serves a recording instead (`robot.recorded.RecordedRobot`): the
pipeline runs on the recorded frames and nothing moves; no simulator is loaded, and the 3D
view is not served. `record` writes such a recording from a scene simulated headless, with the
laser confirmed on an object if asked (the format: docs/recording.md).

`bench` reruns one of the papers' experiments with the scripted operator (docs/bench.md);
`bench --compare` lists the attempts that differ between two of its result files.

Exit codes: 0 clean shutdown (or a finished benchmark, or two results with no difference),
1 a benchmark trial broke off (the others' results are still written), the compared results
differ, the API could not start (`serve`), no camera sees the object to aim at (`record`) or
a scripted wait timed out (`adapter`); 2 bad usage (unknown scene, refused host, a bad count,
an unreadable result file) or no way for MuJoCo to render here (`serve`, `record` and
`bench` choose its OpenGL backend before loading it: `robot.gl_backend`)."""

from __future__ import annotations

import argparse
import logging
from collections.abc import Sequence

from laserpick.cli.adapter import add_adapter_parser
from laserpick.cli.bench import add_bench_parser
from laserpick.cli.common import EXIT_USAGE
from laserpick.cli.record import add_record_parser
from laserpick.cli.serve import add_serve_parser

__all__ = ["EXIT_USAGE", "build_parser", "main"]


def build_parser() -> argparse.ArgumentParser:
    """The argument parser: one subcommand per verb (`serve`, `adapter`, `bench`)."""
    parser = argparse.ArgumentParser(
        prog="laserpick",
        description="Assistive laser-directed pick and place: a UR5 on a mobility scooter.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    add_serve_parser(sub)
    add_record_parser(sub)
    add_adapter_parser(sub)
    add_bench_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the `laserpick` script; returns the process exit code."""
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    parser = build_parser()
    args = parser.parse_args(argv)
    return int(args.func(args))
