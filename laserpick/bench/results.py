"""A benchmark run's attempts summed up as the result JSON (the schema is in docs/bench.md).

Rates (0-1):
- detect_success_rate: attempts whose chosen grasp was on the marked object, over attempts;
- grasp_success_rate: attempts in which the marked object was lifted and held (in
  pick-and-drop, and dropped in the basket), over the attempts whose detection succeeded:
  004 section 8.1 counts it so (93.8 % = 90/96, beside a detection success of 96/104);
- task_success_rate: tasks done (the object in the basket, or set down upright on the mark),
  over tasks. A task is one object to fetch or move; in-situ retries share one task.
"""

from __future__ import annotations

import os
import platform
import statistics
import subprocess
from collections.abc import Iterable, Sequence
from datetime import UTC, datetime
from importlib import metadata
from pathlib import Path
from typing import Any

from laserpick.bench import FAILURE_KINDS, MOTION_STAGES, STAGES

#: The packages whose versions a run's outcomes depend on: the simulation's contacts, the
#: cloud's geometry and the solvers'. Within pyproject.toml's ranges another version moves
#: single attempts (an object held under one version is dropped under the next), so
#: constraints.txt pins each of them to the version the figures were measured with.
RESULT_PACKAGES = (
    "mujoco",
    "numpy",
    "scipy",
    "mink",
    "qpsolvers",
    "daqp",
    "pin",
    "ur-analytic-ik",
    "toppra",
    "ompl",
)


#: The checkout's folder that bench runs write into by default: a run's own results do not
#: make its tree unclean.
RESULTS_FOLDER = "bench-results"


def _git(root: Path, *args: str) -> str | None:
    """`git -C root ARGS`'s output, stripped; None when git is missing or fails."""
    try:
        done = subprocess.run(
            ["git", "-C", str(root), *args], capture_output=True, text=True, timeout=30
        )
    except (OSError, subprocess.TimeoutExpired):
        return None
    return done.stdout.strip() if done.returncode == 0 else None


def source_revision(root: Path | None = None) -> dict[str, Any]:
    """The code a run ran: `commit`, the checked-out commit (`git rev-parse HEAD`) of the git
    checkout whose top folder is `root` (default: the one laserpick is imported from), and
    `tree_clean`, whether that checkout had no changes, staged, unstaged or untracked, but
    in RESULTS_FOLDER. Where `root` is not the top of a git checkout (laserpick installed
    from a wheel, or git missing): commit "unknown" and tree_clean None."""
    root = Path(__file__).resolve().parents[2] if root is None else Path(root).resolve()
    top = _git(root, "rev-parse", "--show-toplevel")
    commit = _git(root, "rev-parse", "HEAD")
    if top is None or Path(top).resolve() != root or not commit:
        return {"commit": "unknown", "tree_clean": None}
    changes = _git(root, "status", "--porcelain", "--", ".", f":(exclude){RESULTS_FOLDER}")
    return {"commit": commit, "tree_clean": None if changes is None else changes == ""}


#: Parts of a setting's name that mark it secret: a result names it, not its value.
SECRET_WORDS = ("PASSWORD", "TOKEN", "SECRET", "KEY")


def environment() -> dict[str, Any]:
    """What a run's outcomes depend on besides the code and the seed: Python's version, each
    of RESULT_PACKAGES' installed versions (None when missing), the CPU's model name and
    the settings the environment overrode (`settings_overrides`)."""
    packages: dict[str, str | None] = {}
    for name in RESULT_PACKAGES:
        try:
            packages[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            packages[name] = None
    return {
        "python": platform.python_version(),
        "packages": packages,
        "cpu": _cpu_model(),
        "settings": settings_overrides(),
    }


def settings_overrides() -> dict[str, str]:
    """The `LASERPICK_*` environment variables set for this run, by name, but those that
    hold secrets (a password, a token), which are named with their value left out: a run
    with the partial shortcuts on (`LASERPICK_MOTION__QUICKEN_PATHS=true`) makes other
    attempts than one without."""
    out = {}
    for name, value in sorted(os.environ.items()):
        if name.upper().startswith("LASERPICK_"):
            secret = any(word in name.upper() for word in SECRET_WORDS)
            out[name] = "(set)" if secret else value
    return out


def _cpu_model() -> str:
    """The CPU's model name (Linux's /proc/cpuinfo; else what `platform` knows)."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _rate(k: int, n: int) -> float:
    return k / n if n else 0.0


def _failures(records: Iterable[dict[str, Any]]) -> dict[str, int]:
    counts = dict.fromkeys(FAILURE_KINDS, 0)
    for r in records:
        if r["failure"] is not None:
            counts[r["failure"]] += 1
    return counts


def _tasks(records: Sequence[dict[str, Any]]) -> dict[tuple, bool]:
    """Whether each task (trial, selection, task id) was done by any of its attempts."""
    done: dict[tuple, bool] = {}
    for r in records:
        key = (r["trial"], r["selection"], r["task"])
        done[key] = done.get(key, False) or r["success"]
    return done


def _timings(records: Sequence[dict[str, Any]]) -> dict[str, dict[str, float]]:
    """Mean, std and count per stage, over the attempts that reached it; attempt_total over
    the successful attempts, as 004 gives "the average time to complete a successful
    attempt" (section 8.2)."""
    out = {}
    for stage in (*STAGES, *MOTION_STAGES):
        rows = [r for r in records if r["success"]] if stage == "attempt_total" else records
        xs = [r["timings"][stage] for r in rows if stage in r["timings"]]
        out[stage] = {
            "mean": statistics.fmean(xs) if xs else 0.0,
            "std": statistics.pstdev(xs) if len(xs) > 1 else 0.0,
            "n": len(xs),
        }
    return out


def summarize(records: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """The summary fields of a set of attempt records (`Attempt.as_dict()`s)."""
    tasks = _tasks(records)
    objects: dict[str, dict[str, Any]] = {}
    for model in sorted({r["model"] for r in records}):
        rows = [r for r in records if r["model"] == model]
        model_tasks = _tasks(rows)
        objects[model] = {
            "attempts": len(rows),
            "grasp_success": sum(r["grasped"] for r in rows),
            "detect_success": sum(r["detected"] for r in rows),
            "tasks": len(model_tasks),
            "task_success": sum(model_tasks.values()),
            "failures": _failures(rows),
        }
    n = len(records)
    return {
        "attempts": n,
        "tasks": len(tasks),
        "grasp_success_rate": _rate(
            sum(r["grasped"] for r in records), sum(r["detected"] for r in records)
        ),
        "detect_success_rate": _rate(sum(r["detected"] for r in records), n),
        "task_success_rate": _rate(sum(tasks.values()), len(tasks)),
        "failures": _failures(records),
        "timings_s": _timings(records),
        "objects": objects,
    }


def result(
    protocol: str,
    seed: int,
    trials: int,
    records: Sequence[dict[str, Any]],
    options: dict[str, Any],
    wall_time_s: float,
) -> dict[str, Any]:
    """The result JSON of a run: the summary over all attempts, per-mode summaries for the
    selection protocol, and every attempt's record (sorted by trial, so the same seed gives
    the same document whatever order the workers finished in)."""
    from laserpick import __version__

    records = sorted(records, key=lambda r: (r["trial"], r["task"], r["selection"]))
    out: dict[str, Any] = {"protocol": protocol, "seed": seed, "trials": trials}
    out.update(summarize(records))
    out["options"] = options
    if protocol == "selection":
        out["modes"] = {
            mode: summarize([r for r in records if r["selection"] == mode])
            for mode in ("auto", "manual")
        }
    out["records"] = records
    out["wall_time_s"] = round(wall_time_s, 1)
    out["version"] = __version__
    out.update(source_revision())
    out["environment"] = environment()
    out["created"] = datetime.now(UTC).isoformat(timespec="seconds")
    return out


def outcomes(result: dict[str, Any]) -> list[tuple]:
    """What the same seed must reproduce: each attempt's verdicts, without its timings."""
    keys = ("trial", "instance", "selection", "marks", "detected", "grasped", "success", "failure")
    return [tuple(r[k] for k in keys) for r in result["records"]]
