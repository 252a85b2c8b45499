"""Our targets (`bench.targets`) held against a run: what was required, what we got, and
whether it was met."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from laserpick.bench.papers import reference
from laserpick.bench.report.measures import Summary, attempt_time, modes, ours, rate_with_counts
from laserpick.bench.report.text import fraction, percent, seconds
from laserpick.bench.targets import Target, targets


@dataclass(frozen=True)
class Check:
    """A target held against a run: what was required, what we got, whether it was met."""

    label: str
    required: str
    got: str
    met: bool


def _check_rate(target: Target, summary: Summary) -> Check:
    rate, k, n = rate_with_counts(summary, target.metric)
    met = rate is not None and rate >= target.threshold - 1e-12
    got = fraction(k, n) if k is not None else percent(rate)
    return Check(
        target.label, f">= {percent(target.threshold)}", got if rate is not None else "no data", met
    )


def _check_time(target: Target, summary: Summary, name: str, protocol: str) -> Check:
    mean, std, n = attempt_time(summary)
    label = target.label if name == "ours" else f"{target.label} ({name})"
    paper = [(c.stages["attempt_total"], c.cite) for c in reference(protocol).timings
             if c.stages.get("attempt_total")]  # fmt: skip
    if paper and paper[0][0].mean_s is not None:
        label += f" ({paper[0][1]}: {paper[0][0].mean_s:g} s)"
    got = f"{seconds(mean, std)} (n = {n})" if n else "no data"
    return Check(label, f"< {target.threshold:g} s", got, n > 0 and mean < target.threshold)


def _check_selection(target: Target, result: dict[str, Any]) -> Check:
    by_mode = dict(modes(result))
    if "auto" not in by_mode or "manual" not in by_mode:
        return Check(target.label, f"manual <= {target.threshold:g} × auto", "no modes", False)
    auto, _, _ = ours(by_mode["auto"], "per_attempt:wrong_object")
    manual, _, _ = ours(by_mode["manual"], "per_attempt:wrong_object")
    if auto is None or manual is None:
        return Check(target.label, f"manual <= {target.threshold:g} × auto", "no data", False)
    got = f"manual {percent(manual)}, auto {percent(auto)}"
    return Check(target.label, f"manual <= {target.threshold:g} × auto", got,
                 manual <= target.threshold * auto + 1e-12)  # fmt: skip


def check_targets(result: dict[str, Any]) -> list[Check]:
    """Every target of the run's protocol, checked (per mode where the protocol has modes)."""
    protocol = result["protocol"]
    checks: list[Check] = []
    for target in targets(protocol):
        if target.metric == "attempt_total_s":
            checks += [_check_time(target, s, name, protocol) for name, s in modes(result)]
        elif target.metric == "wrong_object_manual_vs_auto":
            checks.append(_check_selection(target, result))
        else:
            checks.append(_check_rate(target, result))
    return checks
