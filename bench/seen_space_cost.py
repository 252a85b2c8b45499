"""What the seen-space test costs a search (`free_space.seen_free`), asked as it is (the
capture's frames first, then the rest about the points left) against all frames at once.

Replays recorded search problems (`plan_record`; record them by running any bench with
LASERPICK_RECORD_PLANS set) with our RRT-Connect, keeps every call the seen-space test makes
(up to `--calls`), then asks them again each way, in turn, and prints the CPU time of each
and whether their verdicts agree. Only problems with depth frames (a pick's transit, held to
seen space) make such calls.

    LASERPICK_RECORD_PLANS=/tmp/plans/in-situ-7305 .venv/bin/laserpick bench \
        --protocol in-situ --seed 7305 --trials 1 --workers 1 --out /tmp/in-situ-7305.json
    .venv/bin/python bench/seen_space_cost.py /tmp/plans/in-situ-7305 [--calls 5000]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from laserpick.pipeline import free_space
from laserpick.pipeline.collision import seen_space
from laserpick.pipeline.frame_stack import frame_stack
from laserpick.pipeline.plan_record import load_search
from laserpick.pipeline.rrt import rrt_connect


def all_at_once(points: np.ndarray, frames, tolerance: float) -> np.ndarray:
    """`seen_free` as one product over every frame."""
    points = np.asarray(points, np.float64).reshape(-1, 3)
    return frame_stack(frames).seen_past(points, np.full(len(points), tolerance))


def recorded_calls(folder: Path, most: int) -> list[tuple]:
    """The seen-space test's calls (points, frames, tolerance) while our search solves each
    problem of `folder` (seed 0), at most `most`."""
    calls: list[tuple] = []
    asked = seen_space.seen_free

    def keep(points, frames, tolerance):
        if len(calls) < most:
            calls.append((np.array(points), frames, tolerance))
        return asked(points, frames, tolerance)

    seen_space.seen_free = keep
    try:
        for f in sorted(folder.glob("*.npz")):
            q0, q1, checker, kw = load_search(f)
            if checker.frames and kw.get("seen"):
                rrt_connect(q0, q1, checker, np.random.default_rng(0), **kw)
            if len(calls) >= most:
                break
    finally:
        seen_space.seen_free = asked
    return calls


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder", type=Path, help="a folder of recorded .npz search problems")
    ap.add_argument("--calls", type=int, default=5000, help="most calls to keep")
    args = ap.parse_args()
    calls = recorded_calls(args.folder, args.calls)
    if not calls:
        raise SystemExit(f"no search in {args.folder} asked the seen-space test")
    points = np.mean([len(c[0]) for c in calls])
    print(f"{len(calls)} calls, {points:.0f} points and {len(calls[0][1])} frames on average")
    ways = {"as asked (capture's frames first)": free_space.seen_free, "all at once": all_at_once}
    for _ in range(2):  # in turn, twice: both meet the same load
        for name, ask in ways.items():
            t = time.process_time()
            for call in calls:
                ask(*call)
            print(f"{name}: {time.process_time() - t:.2f} s CPU")
    agree = all(np.array_equal(free_space.seen_free(*c), all_at_once(*c)) for c in calls)
    print(f"verdicts agree: {agree}")


if __name__ == "__main__":
    main()
