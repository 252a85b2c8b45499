"""Isolation trials with every task reseeded, for a paired comparison of two versions of the
arm's motion. `laserpick bench --protocol isolation` seeds a trial once: any change in how
the arm moves changes the random draws of every later task in the trial (grasp sampling,
sensor noise), so two versions meet different grasps from the second task on. Here each task
draws as a fresh session seeded with (trial seed, task) would (`ScriptedOperator.begin_task`),
so both versions try the same grasps, and a task that one loses and the other wins is lost
to the motion.

    MUJOCO_GL=egl .venv/bin/python bench/isolation_paired.py --seeds 1 16 --out A.json
    MUJOCO_GL=egl .venv/bin/python bench/isolation_paired.py --compare A.json B.json
"""

from __future__ import annotations

import argparse
import json
import statistics
from pathlib import Path
from typing import Any

from laserpick.bench.protocols.trials import (
    Options,
    instances,
    limit,
    protocol_scene,
    scripted_operator,
    shuffled,
)


def trial(seed: int) -> list[dict[str, Any]]:
    """One isolation trial of `seed`, each task reseeded: one row a task."""
    opt = Options()
    scene = protocol_scene("isolation", seed, opt)
    rows = []
    with scripted_operator(scene, 0, seed, opt) as op:
        for task, name in enumerate(limit(shuffled(op, instances(scene)), opt)):
            op.begin_task(task)
            a = op.pick_and_drop(op.new_attempt(name, opt.selection, opt.strategy))
            rows.append(
                {
                    "seed": seed,
                    "task": task,
                    "instance": name,
                    "success": a.success,
                    "failure": a.failure,
                    "message": a.message,
                    "execute_sim": a.timings.get("execute_sim"),
                    "grip": a.grip,
                }
            )
    return rows


def compare(old: list[dict[str, Any]], new: list[dict[str, Any]]) -> None:
    """Print both versions' successes and mean execute_sim, and the tasks they differ on."""
    for name, rows in (("old", old), ("new", new)):
        done = [r["execute_sim"] for r in rows if r["success"]]
        print(
            f"{name}: {sum(r['success'] for r in rows)}/{len(rows)} in the basket,"
            f" execute_sim {statistics.fmean(done):.2f} s over those"
        )
    by_task = {(r["seed"], r["task"]): r for r in new}
    for r in old:
        other = by_task.get((r["seed"], r["task"]))
        if other is None or other["success"] != r["success"]:
            lost = other and other["failure"]
            where = f"seed {r['seed']} task {r['task']} {r['instance']}"
            print(f"  {where}: old {r['failure']}, new {lost}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs=2, default=[1, 16], help="from, to (excl.)")
    parser.add_argument("--out", type=Path, help="where to write the rows (JSON)")
    parser.add_argument("--compare", type=Path, nargs=2, metavar=("OLD", "NEW"))
    args = parser.parse_args()
    if args.compare:
        old, new = (json.loads(p.read_text()) for p in args.compare)
        compare(old, new)
        return
    rows: list[dict[str, Any]] = []
    for seed in range(*args.seeds):
        rows += trial(seed)
        print(f"seed {seed}: {sum(r['success'] for r in rows)}/{len(rows)} so far", flush=True)
        if args.out:
            args.out.write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
