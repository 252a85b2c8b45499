"""What the partial shortcuts of `pipeline/quicken.py` save, on recorded joint-space search
problems: per problem, the timed duration of our search's path (RRT-Connect and vertex
joins, as `joint_search.joint_path` had it before) and of the path it returns now,
each timed as the arm runs it (at the carry's limits where the problem carries an object,
its corners blended where the problem's own check passes them), and the wall-clock time
each took. Both start from the same seed, so the search finds the same path, and the
difference is the quickening alone.

Record problems as for bench/planners.py (LASERPICK_RECORD_PLANS=DIR on any bench), then:

    .venv/bin/python bench/path_quickening.py /tmp/plans/isolation [/tmp/plans/...]

--carry-tries N quickens the carries with N partial shortcuts instead of
`joint_search.QUICKEN_TRIES`'s; --carries-only leaves the empty hand's searches out.
"""

from __future__ import annotations

import argparse
import functools
import itertools
import time
from pathlib import Path

import numpy as np

from laserpick.pipeline import joint_search
from laserpick.pipeline.motion_limits import timed
from laserpick.pipeline.plan_record import load_search
from laserpick.pipeline.rrt import rrt_connect, shortcut
from laserpick.settings import get_settings


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folders", nargs="+", type=Path, help="folders of recorded .npz problems")
    ap.add_argument("--carry-tries", type=int, help="partial shortcuts a carry gets")
    ap.add_argument("--carries-only", action="store_true", help="only problems that carry")
    args = ap.parse_args()
    if args.carry_tries is not None:
        joint_search.QUICKEN_TRIES[True] = args.carry_tries
    s = get_settings().motion.model_copy(update={"quicken_paths": True})
    files = sorted(itertools.chain.from_iterable(f.glob("*.npz") for f in args.folders))
    rows = []
    print("problem           carry  searched s  quickened s  plan s (searched, quickened)")
    for f in files:
        q0, q1, checker, kw = load_search(f)
        carry = kw.get("payload") is not None
        if args.carries_only and not carry:
            continue
        t = time.perf_counter()
        rng = np.random.default_rng(0)
        found = rrt_connect(
            q0, q1, checker, rng, step=s.rrt_step, max_samples=s.rrt_max_samples, **kw
        )
        if found is None:
            print(f"{f.stem}  {carry!s:5}  no path")
            continue
        searched = shortcut(found, checker, rng, **kw)
        t_searched = time.perf_counter() - t
        t = time.perf_counter()
        quick = joint_search.joint_path(q0, q1, checker, np.random.default_rng(0), s, **kw)
        t_quick = time.perf_counter() - t
        clear = functools.partial(checker.path_clear, **kw)  # as the arm's timing blends
        before = timed(searched, s, carrying=carry, clear=clear).duration
        after = timed(quick, s, carrying=carry, clear=clear).duration
        rows.append((before, after, t_searched, t_quick))
        times = f"{t_searched:6.2f}, {t_quick:.2f}"
        print(f"{f.stem}  {carry!s:5}  {before:10.2f}  {after:11.2f}  {times}")
    r = np.array(rows)
    print(
        f"\n{len(r)} problems solved: timed duration {r[:, 0].mean():.2f} s -> "
        f"{r[:, 1].mean():.2f} s mean (median saving {np.median(r[:, 0] - r[:, 1]):.2f} s, "
        f"none longer: {bool((r[:, 1] <= r[:, 0] + 1e-9).all())}); planning "
        f"{r[:, 2].mean():.2f} s -> {r[:, 3].mean():.2f} s mean"
    )


if __name__ == "__main__":
    main()
