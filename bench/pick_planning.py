"""The planning stage of recorded picks, planned again: its CPU time and what it found.

In the bench a pick's planning time (`timings.plan`) is wall-clock time beside the
simulation and whatever else the machine runs; the figure the planning target speaks of is
the planning itself. Record picks by running any bench with LASERPICK_RECORD_PICKS set:
every `first_plan.plan_first` writes what it was given (`laserpick.pipeline.plan_record`).
This plans each again, in turn, from the recorded draws, and prints for each its CPU time
(s), whether a grasp planned and which (its place in the order), then the mean, median and
p90 over the picks. Run it with two versions of the code to compare them on the same picks:
the same draws give the same searches, so a version that plans alike gives the same places.

    LASERPICK_RECORD_PICKS=/tmp/picks/7301 .venv/bin/laserpick bench --protocol in-situ \
        --seed 7301 --trials 1 --out /tmp/in-situ-7301.json
    .venv/bin/python bench/pick_planning.py /tmp/picks/7301 [/tmp/picks/...] \
        [--pick-planner ours] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from laserpick.pipeline.first_plan import plan_first
from laserpick.pipeline.plan_record import load_pick


def plan_again(path: Path, pick_planner: str | None) -> dict:
    """Plan the pick recorded at `path` again: its CPU time (s), and the grasp's place."""
    pick = load_pick(path)
    s = pick["settings"]
    if pick_planner is not None:
        s = s.model_copy(update={"pick_planner": pick_planner})
    t0 = time.process_time()
    _, grasp, place = plan_first(
        pick["found"], pick["q_now"], pick["rng"], pick["order"], s, pick["admit"]
    )
    return {"cpu": time.process_time() - t0, "planned": grasp is not None, "place": place}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folders", type=Path, nargs="+", help="folders of recorded picks")
    parser.add_argument("--pick-planner", choices=["ompl", "ours"], default=None)
    parser.add_argument("--json", type=Path, default=None, help="write each pick's row here")
    args = parser.parse_args()
    paths = sorted(p for folder in args.folders for p in folder.glob("*.pkl"))
    if not paths:
        parser.error("no recorded picks (*.pkl) in those folders")
    rows = {}
    for k, path in enumerate(paths, 1):
        row = rows[str(path)] = plan_again(path, args.pick_planner)
        said = f"grasp {row['place']}" if row["planned"] else f"none of {row['place']}"
        print(f"[{k}/{len(paths)}] {path.parent.name}/{path.name}: {row['cpu']:.2f} s, {said}")
    cpu = np.array([r["cpu"] for r in rows.values()])
    planned = sum(r["planned"] for r in rows.values())
    print(
        f"\n{len(cpu)} picks, {planned} planned; CPU time a pick: mean {cpu.mean():.3f} s,"
        f" median {np.median(cpu):.3f} s, p90 {np.percentile(cpu, 90):.3f} s,"
        f" max {cpu.max():.2f} s, total {cpu.sum():.1f} s"
    )
    if args.json is not None:
        args.json.write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
