"""`laserpick bench`: the papers' experiments with the scripted operator, `--compare` and
`--families`."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from laserpick.cli.common import EXIT_USAGE, rendering_problem, say

__all__ = ["add_bench_parser", "cmd_bench"]


def add_bench_parser(sub: argparse._SubParsersAction) -> None:
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
    bench.add_argument(
        "--families",
        nargs="+",
        type=Path,
        metavar="RESULT.json",
        help="run nothing: group the lost attempts of these result files (a sweep of seeds) by"
        " family, with task and first-try success",
    )
    bench.add_argument(
        "--leave-out",
        action="append",
        default=[],
        metavar="MODEL",
        help="with --families: also give the rates without this object model (repeatable)",
    )
    bench.set_defaults(func=cmd_bench)


def cmd_bench_families(paths: list[Path], leave_out: list[str]) -> int:
    """Print the lost attempts of result files grouped by family: 0, or 2 when a file
    cannot be read."""
    from laserpick.bench.compare import ResultFileError
    from laserpick.bench.families import format_sweep, load_sweep

    try:
        sweep = load_sweep(paths)
    except ResultFileError as exc:
        say(str(exc), err=True)
        return EXIT_USAGE
    print(format_sweep(sweep, leave_out), end="")
    return 0


def cmd_bench_compare(old: Path, new: Path, tolerance: float) -> int:
    """List the attempts that differ between two result files: 0 when none does, 1 when
    some do, 2 when a file cannot be read or the two ran another protocol or seed."""
    from laserpick.bench.compare import compare_files, format_comparison

    try:
        comparison = compare_files(old, new, tolerance)
    except ValueError as exc:  # unreadable, mismatched, or a bad tolerance
        say(str(exc), err=True)
        return EXIT_USAGE
    print(format_comparison(comparison, str(old), str(new)), end="")
    return 0 if comparison.same else 1


def cmd_bench(args: argparse.Namespace) -> int:
    """Run a protocol with a progress bar; write the JSON, the report and the plots. With
    --compare, compare two result files instead."""
    if args.families is not None:
        if args.protocol is not None or args.compare is not None:
            say("--families reads result files; it takes no --protocol or --compare", err=True)
            return EXIT_USAGE
        return cmd_bench_families(args.families, args.leave_out)
    if args.compare is not None:
        if args.protocol is not None:
            say("--compare compares two result files; it takes no --protocol", err=True)
            return EXIT_USAGE
        return cmd_bench_compare(*args.compare, args.tolerance)
    if args.protocol is None:
        say("bench needs --protocol (or --compare OLD.json NEW.json, or --families)", err=True)
        return EXIT_USAGE
    return run_bench(args)


def run_bench(args: argparse.Namespace) -> int:
    """Run the protocol of `args` with a progress bar; write the JSON, the report and the
    plots."""
    problem = rendering_problem()
    if problem is not None:  # before the simulator loads, so that the workers inherit the choice
        say(problem, err=True)
        return EXIT_USAGE

    import json

    from laserpick.bench.protocols import PROTOCOLS, Options
    from laserpick.bench.report import markdown, write_reports
    from laserpick.bench.runner import progress_bar, run
    from laserpick.robot.sim.scenes import SceneError, load_scene

    spec = PROTOCOLS[args.protocol]
    for name, value in (("--trials", args.trials), ("--workers", args.workers)):
        if value is not None and value < 1:
            say(f"{name} must be at least 1", err=True)
            return EXIT_USAGE
    if args.objects is not None and args.objects < 1:
        say("--objects must be at least 1", err=True)
        return EXIT_USAGE
    if args.scene is not None:
        try:
            load_scene(args.scene)
        except SceneError as exc:
            say(str(exc), err=True)
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
    say(f"{args.protocol} ({spec.source}): {trials} trials, seed {args.seed}")
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
    say("wrote " + ", ".join(str(p) for p in written))
    if result["errors"]:
        say(f"{len(result['errors'])} trials broke off (see 'errors' in {out})", err=True)
        return 1
    return 0
