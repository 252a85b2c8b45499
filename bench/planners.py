"""Our RRT-Connect against OMPL's, side by side on recorded joint-space search problems.

Record problems by running any bench with LASERPICK_RECORD_PLANS set: every search that
`joint_search.joint_path` starts (the straight move blocked, both ends clear) is saved as one .npz
(`laserpick.pipeline.plan_record`). Then each planner solves each problem once per seed,
in turn (so both meet the same machine load), with the motion settings' sample budget:

- ours: `rrt.rrt_connect` (extension step `rrt_step`, largest joint) and `rrt.shortcut`;
  with `--full-steps`, also without its shorter steps out of a pocket (`rrt.POCKET_TRAPS`);
- ompl: `ompl_search.ompl_connect` (OMPL's RRTConnect and PathSimplifier, our checker);
- with `--short-first`, ours as a pick runs it: a short search (`first_plan.QUICK_SAMPLES`)
  and, where it finds no way, the full one, started anew (as a pick does) or grown on from
  the short one's trees (`rrt.ConnectSearch`), both from the same draws.

Prints, per planner, the success rate, the wall-clock planning time (median, mean, p90, s),
the joint-space path length (rad, summed Euclidean norm of the steps; median and mean over
the problems both solved) and its largest-joint sweep (what bounds its time at the joint
speed limit), the configurations the search asked the collision checker
about (mean: its work, which the machine's load does not change), and checks every returned
path again at the checker's resolution (`CollisionChecker.segment_ok`). Last, the CPU time
of all the searches: on a shared machine, the way to compare two versions of the code run
one after the other (the same configurations checked say they searched alike).

    LASERPICK_RECORD_PLANS=/tmp/plans/in-situ .venv/bin/laserpick bench --protocol in-situ \
        --seed 2 --trials 1 --out /tmp/in-situ.json
    .venv/bin/python bench/planners.py /tmp/plans/in-situ [/tmp/plans/...] [--seeds 3]
"""

from __future__ import annotations

import argparse
import itertools
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from laserpick.pipeline.collision import CollisionChecker
from laserpick.pipeline.first_plan import QUICK_SAMPLES
from laserpick.pipeline.ompl_search import OMPL_RANGE, ompl_connect
from laserpick.pipeline.plan_record import load_search
from laserpick.pipeline.rrt import POCKET_TRAPS, ConnectSearch, rrt_connect, shortcut
from laserpick.settings import MotionSettings, get_settings

Planner = Callable[
    [np.ndarray, np.ndarray, CollisionChecker, np.random.Generator, MotionSettings, dict],
    np.ndarray | None,
]


def ours(q0, q1, checker, rng, s, kw, pocket_traps: int | None = POCKET_TRAPS):
    path = rrt_connect(
        q0,
        q1,
        checker,
        rng,
        step=s.rrt_step,
        max_samples=s.rrt_max_samples,
        pocket_traps=pocket_traps,
        **kw,
    )
    return None if path is None else shortcut(path, checker, rng, **kw)


def ours_full_steps(q0, q1, checker, rng, s, kw):
    """Ours without the shorter steps out of a pocket (`rrt.POCKET_TRAPS`)."""
    return ours(q0, q1, checker, rng, s, kw, pocket_traps=None)


def short_then(grow: bool) -> Planner:
    """Ours after a short search of QUICK_SAMPLES that found no way: anew, or grown on."""

    def planner(q0, q1, checker, rng, s, kw):
        search = ConnectSearch(q0, q1, checker, rng, step=s.rrt_step, **kw)
        path = search.grow(QUICK_SAMPLES)
        if path is None:
            full = search if grow else ConnectSearch(q0, q1, checker, rng, step=s.rrt_step, **kw)
            path = full.grow(s.rrt_max_samples)
        return None if path is None else shortcut(path, checker, rng, **kw)

    return planner


def ompl_with(search_range: float) -> Planner:
    def ompl(q0, q1, checker, rng, s, kw):
        return ompl_connect(
            q0,
            q1,
            checker,
            rng,
            max_samples=s.rrt_max_samples,
            search_range=search_range,
            **kw,
        )

    return ompl


def length(path: np.ndarray) -> float:
    """Joint-space length (rad): the summed Euclidean norms of the path's steps."""
    return float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())


def sweep(path: np.ndarray) -> float:
    """The summed largest joint motion of the path's steps (rad): at the joint speed limit,
    the time the path takes is at least this over the limit."""
    return float(np.abs(np.diff(path, axis=0)).max(axis=1).sum())


def counting(checker: CollisionChecker) -> list[int]:
    """Count the configurations `checker` is asked about (a measure of a search's work that,
    unlike its wall-clock time, does not depend on the machine's load); `all_clear` asks
    through `clearance_ok`."""
    checked = [0]
    clearance_ok = checker.clearance_ok

    def counted(Q, **kw):
        checked[0] += len(np.atleast_2d(Q))
        return clearance_ok(Q, **kw)

    checker.clearance_ok = counted  # type: ignore[method-assign]
    return checked


def run(files: list[Path], planners: dict[str, Planner], seeds: int) -> dict[str, list]:
    """Each planner on each problem and seed: rows (problem, seed, found, seconds, length,
    sweep, clear, configurations checked, CPU seconds), planners taking turns on each
    problem."""
    s = get_settings().motion
    rows: dict[str, list] = {name: [] for name in planners}
    for k, f in enumerate(files):
        q0, q1, checker, kw = load_search(f)
        checked = counting(checker)
        for seed, (name, plan) in itertools.product(range(seeds), planners.items()):
            checked[0] = 0
            t, cpu = time.perf_counter(), time.process_time()
            path = plan(q0, q1, checker, np.random.default_rng(seed), s, kw)
            dt, cpu = time.perf_counter() - t, time.process_time() - cpu
            n = checked[0]
            found = path is not None
            clear = found and all(
                checker.segment_ok(a, b, **kw) for a, b in itertools.pairwise(path)
            )
            lengths = (length(path), sweep(path)) if found else (np.nan, np.nan)
            rows[name].append((k, seed, found, dt, *lengths, clear, n, cpu))
        line = ", ".join(f"{n} {rows[n][-1][3]:.2f} s {rows[n][-1][7]} q" for n in planners)
        print(f"{f.name}: {line}", flush=True)
    return rows


def report(rows: dict[str, list]) -> None:
    """The comparison as a Markdown table."""
    both = np.logical_and.reduce([np.array([x[2] for x in r]) for r in rows.values()])
    print(
        "\n| planner | solved | time median (s) | mean (s) | p90 (s) | length median (rad) |"
        " mean (rad) | largest-joint sweep, mean (rad) | configurations checked, mean |"
        " paths clear | CPU total (s) |"
    )
    print("|" + " --- |" * 11)
    for name, r in rows.items():
        found = np.array([x[2] for x in r])
        dt = np.array([x[3] for x in r])
        lengths = np.array([x[4] for x in r])[both]
        sweeps = np.array([x[5] for x in r])[both]
        clear = sum(x[6] for x in r)
        print(
            f"| {name} | {found.sum()}/{len(r)} ({100 * found.mean():.0f}%) "
            f"| {np.median(dt):.3f} | {dt.mean():.3f} | {np.percentile(dt, 90):.3f} "
            f"| {np.median(lengths):.2f} | {lengths.mean():.2f} | {sweeps.mean():.2f} "
            f"| {np.mean([x[7] for x in r]):.0f} | {clear}/{found.sum()} "
            f"| {sum(x[8] for x in r):.1f} |"
        )
    print(f"\nlengths over the {both.sum()} runs that every planner solved")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folders", nargs="+", type=Path, help="folders of recorded .npz problems")
    ap.add_argument("--seeds", type=int, default=3, help="runs of each planner per problem")
    ap.add_argument(
        "--ranges",
        type=float,
        nargs="*",
        default=[OMPL_RANGE],
        help="OMPL RRT-Connect extension steps (rad, Euclidean) to compare",
    )
    ap.add_argument(
        "--full-steps",
        action="store_true",
        help="also ours without the shorter steps out of a pocket (rrt.POCKET_TRAPS)",
    )
    ap.add_argument(
        "--short-first",
        action="store_true",
        help="ours only, after a short search that found no way: the full one anew or grown on",
    )
    args = ap.parse_args()
    files = sorted(itertools.chain.from_iterable(f.glob("*.npz") for f in args.folders))
    planners: dict[str, Planner] = {"ours": ours}
    if args.full_steps:
        planners["ours, full steps"] = ours_full_steps
    for r in args.ranges:
        planners[f"ompl (range {r:.2f})"] = ompl_with(r)
    if args.short_first:
        planners = {"short, then anew": short_then(False), "short, then grown on": short_then(True)}
    print(f"{len(files)} problems, {args.seeds} seeds each")
    report(run(files, planners, args.seeds))


if __name__ == "__main__":
    main()
