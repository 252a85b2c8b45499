"""Our numbers from a result's summaries: the summaries to report (per selection mode), the
failure counts and the attempts that reached each failure kind's stage, and our value of
each of a paper's metrics (`papers.Figure.metric`).

Rates are fractions (0..1); times in s.
"""

from __future__ import annotations

from typing import Any

from laserpick.bench import FAILURE_KINDS
from laserpick.bench.report.text import fraction, percent

Summary = dict[str, Any]


def modes(result: dict[str, Any]) -> list[tuple[str, Summary]]:
    """The summaries to report, by name: auto and manual for "selection", else the run's."""
    if result.get("protocol") == "selection" and result.get("modes"):
        return [
            (name, result["modes"][name]) for name in ("auto", "manual") if name in result["modes"]
        ]
    return [("ours", result)]


def failures(summary: Summary) -> dict[str, int]:
    """The failure counts of a summary, every kind present (0 where none)."""
    got = summary.get("failures") or {}
    return {kind: int(got.get(kind, 0)) for kind in FAILURE_KINDS}


def totals(summary: Summary) -> dict[str, int]:
    """Successes summed over the summary's objects; attempts and tasks as it states them."""
    keys = ("attempts", "detect_success", "grasp_success", "tasks", "task_success")
    objects = (summary.get("objects") or {}).values()
    out = {k: sum(int(o.get(k, 0)) for o in objects) for k in keys}
    for k in ("attempts", "tasks"):
        if summary.get(k) is not None:
            out[k] = int(summary[k])
    return out


def reached(summary: Summary) -> dict[str, int]:
    """Attempts that reached each failure kind's stage (the denominators of 004 Tables 3
    and 5): all attempts for detect_laser, then those the earlier kinds did not stop;
    wrong_object and execute share the executed attempts."""
    fails, left, out = failures(summary), totals(summary)["attempts"], {}
    for kind in FAILURE_KINDS:
        out[kind] = left
        if kind != "wrong_object":
            left -= fails[kind]
    return out


def rate_with_counts(summary: Summary, key: str) -> tuple[float | None, int | None, int | None]:
    """A rate of the result and the counts that give it, when the objects' sums do."""
    rate = summary.get(key)
    t = totals(summary)
    numerators = {
        "grasp_success_rate": ("grasp_success", ("detect_success", "attempts")),
        "detect_success_rate": ("detect_success", ("attempts",)),
        "task_success_rate": ("task_success", ("tasks",)),
    }
    if rate is None:
        return None, None, None
    num, dens = numerators[key]
    for den in dens:
        if t[den] and abs(t[num] / t[den] - rate) < 1e-6:
            return float(rate), t[num], t[den]
    return float(rate), None, None


def _object_rates(summary: Summary) -> list[float]:
    objects = (summary.get("objects") or {}).values()
    return [o.get("grasp_success", 0) / o["attempts"] for o in objects if o.get("attempts")]


def ours(summary: Summary, metric: str) -> tuple[float | None, int | None, int | None]:
    """Our value of a `papers.Figure.metric`: (rate 0..1, k, n); None where not measured."""
    if metric.endswith("_rate"):
        return rate_with_counts(summary, metric)
    kind, _, arg = metric.partition(":")
    t = totals(summary)
    if kind == "failure":
        kinds = arg.split("+")
        k, n = sum(failures(summary)[x] for x in kinds), reached(summary)[kinds[0]]
    elif kind == "per_attempt":
        k, n = failures(summary)[arg], t["attempts"]
    elif kind == "success":
        obj = (summary.get("objects") or {}).get(arg.removeprefix("model="), {})
        k, n = obj.get("grasp_success"), obj.get("attempts")
    elif kind == "grasp_per_detection":
        k, n = t["grasp_success"], t["detect_success"]
    elif kind == "pooled_success":
        k, n = t["grasp_success"], t["attempts"]
    elif kind == "objects_picked":
        objects = [o for o in (summary.get("objects") or {}).values() if o.get("attempts")]
        k, n = sum(1 for o in objects if o.get("grasp_success")), len(objects)
    elif kind == "mean_object_success":
        rates = _object_rates(summary)
        return (sum(rates) / len(rates) if rates else None), None, None
    else:
        raise ValueError(f"unknown metric {metric!r}")
    return (k / n if k is not None and n else None), k, n


def ours_text(summary: Summary, metric: str | None) -> str:
    if metric is None:
        return "not measured"
    rate, k, n = ours(summary, metric)
    return fraction(k, n) if k is not None and n else percent(rate)


def attempt_time(summary: Summary) -> tuple[float | None, float | None, int]:
    """The mean and standard deviation of the attempt time (s), and how many attempts."""
    t = (summary.get("timings_s") or {}).get("attempt_total") or {}
    n = int(t.get("n", 0))
    return (t.get("mean"), t.get("std"), n) if n else (None, None, 0)
