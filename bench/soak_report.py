"""The soak's figures: gathered into one JSON-able summary, judged against the targets, and
printed. Memory in MB, lag in ms, times in seconds."""

from __future__ import annotations

import math
import statistics
from collections import Counter
from typing import Any

#: The targets: memory growth after the warm-up, mean real-time factor, worst minute's p99 lag.
TARGETS = {"memory_growth_mb": 50.0, "rtf_mean": 0.98, "loop_lag_p99_ms": 50.0}


def rtf_figures(rtf: list[float]) -> dict[str, Any]:
    if not rtf:
        return {"samples": 0, "min": math.nan, "mean": math.nan}
    return {"samples": len(rtf), "min": min(rtf), "mean": round(statistics.fmean(rtf), 4)}


def memory_figures(rss: dict[str, float]) -> dict[str, Any]:
    growth = rss.get("end", math.nan) - rss.get("after_warmup", math.nan)
    return {**{k: rss.get(k, math.nan) for k in ("start", "after_warmup", "end")}, "growth": growth}


def lag_figures(minutes: list[dict[str, Any]]) -> dict[str, Any]:
    """The event loop's lag: each minute's p99, the worst and the median of them, and the
    largest lag seen."""
    p99 = [m["p99_ms"] for m in minutes]
    return {
        "p99_worst_minute": max(p99, default=math.nan),
        "p99_median_minute": statistics.median(p99) if p99 else math.nan,
        "max": max((m["max_ms"] for m in minutes), default=math.nan),
        "minutes": minutes,
    }


def server_error_figures(errors: list[dict[str, Any]]) -> dict[str, Any]:
    by_route = Counter(f"{e['route']} {e['status']}" for e in errors)
    return {"count": len(errors), "by_route": dict(by_route), "first": errors[:10]}


def targets(figures: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """Each target: the figure, the bound, and whether it was met (NaN never meets one)."""
    intruder = figures["second_client"]
    checks = {
        "no 5xx": (figures["server_errors"]["count"], "== 0", lambda v: v == 0),
        "no lost journal row": (figures["journal"]["lost"], "== 0", lambda v: v == 0),
        "memory growth (MB)": (
            figures["memory_mb"]["growth"],
            f"< {TARGETS['memory_growth_mb']:g}",
            lambda v: v < TARGETS["memory_growth_mb"],
        ),
        "real-time factor (mean)": (
            figures["rtf"]["mean"],
            f">= {TARGETS['rtf_mean']:g}",
            lambda v: v >= TARGETS["rtf_mean"],
        ),
        "event-loop lag p99 (ms, worst minute)": (
            figures["loop_lag_ms"]["p99_worst_minute"],
            f"< {TARGETS['loop_lag_p99_ms']:g}",
            lambda v: v < TARGETS["loop_lag_p99_ms"],
        ),
        "second client refused (answers not 409)": (
            intruder["tries"] - intruder["refused"],
            "== 0",
            lambda v: v == 0,
        ),
    }
    return {
        name: {"value": value, "target": bound, "met": bool(ok(value))}
        for name, (value, bound, ok) in checks.items()
    }


def print_summary(f: dict[str, Any]) -> None:
    """The final summary, a figure a line, then each target met or NOT MET."""
    j, m, r, lag = f["journal"], f["memory_mb"], f["rtf"], f["loop_lag_ms"]
    print(f"\nsoak of {f['wall_s'] / 60:.1f} min on {f['url']}")
    print(f"episodes          {f['operator']['episodes']}")
    print(f"picks             {f['operator']['outcomes']}; scene resets {f['operator']['scenes']}")
    print(
        f"real-time factor  min {r['min']:.3f}  mean {r['mean']:.3f}  ({r['samples']} samples; "
        f"{r['unmeasured_new_scene']} of a scene too new to have measured one)"
    )
    print(
        f"memory (MB)       start {m['start']:.1f}  after warm-up {m['after_warmup']:.1f}  "
        f"end {m['end']:.1f}  growth {m['growth']:+.1f}"
    )
    print(
        f"loop lag (ms)     p99 worst minute {lag['p99_worst_minute']:.1f}, median minute "
        f"{lag['p99_median_minute']:.1f}; largest {lag['max']:.1f}"
    )
    print(
        f"journal           {j['commands_sent']} commands sent, {j['commands_journaled']} "
        f"journaled: {j['rows_expected']} rows expected, {j['rows_recorded']} recorded, "
        f"{j['lost']} lost {j['lost_by_action'] or ''}, {j['unexpected']} unexpected "
        f"{j['unexpected_by_action'] or ''}"
    )
    print(f"not journaled     {j['not_journaled']}")
    print(f"watchdog halts    {len(j['watchdog_halts'])} {j['watchdog_halts'] or ''}")
    print(f"second client     {f['second_client']}")
    print(f"watchers          {f['watchers']}")
    print(f"5xx               {f['server_errors']['count']} {f['server_errors']['by_route']}")
    exc = f["client_exceptions"]
    print(f"client exceptions {exc['count']} {exc['by_kind']} {exc['episode_errors'] or ''}")
    for name, t in f["targets"].items():
        verdict = "met" if t["met"] else "NOT MET"
        print(f"target  {name}: {t['value']} (target {t['target']}): {verdict}")
