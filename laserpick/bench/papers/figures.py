"""How a paper's published figures are written down: where each is printed (`Cite`), a
published k of n (`Count`), a figure beside the metric of ours it is compared with
(`Figure`), stage times (`Timing`, `TimingColumn`), tables by object, surface or location
(`Breakdown`, `Row`), and everything one protocol reruns (`Reference`).

Units: rates are fractions (0..1) unless a field says percent; times in s.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType


@dataclass(frozen=True)
class Cite:
    """Where a figure is printed: seed paper id, section and (if any) table."""

    paper: str
    section: str
    table: str | None = None

    def __str__(self) -> str:
        where = f"{self.paper} §{self.section}"
        return f"{where}, {self.table}" if self.table else where


@dataclass(frozen=True)
class Count:
    """A published k of n, with the percentage as printed (None where not printed)."""

    k: int | None = None
    n: int | None = None
    percent: float | None = None

    @property
    def rate(self) -> float | None:
        """The fraction (0..1): the printed percentage, else k/n, else None."""
        if self.percent is not None:
            return self.percent / 100.0
        if self.k is not None and self.n:
            return self.k / self.n
        return None

    def __str__(self) -> str:
        rate = self.rate
        if rate is None:
            return "not reported"
        p = self.percent if self.percent is not None else 100 * rate
        text = f"{p:.2f} %" if self.percent is not None and round(p, 1) != p else f"{p:.1f} %"
        return f"{text} ({self.k}/{self.n})" if self.k is not None and self.n else text


@dataclass(frozen=True)
class Figure:
    """One published figure and the metric of ours it is compared with.

    metric: how `report` computes ours from a result; one of
      "grasp_success_rate", "detect_success_rate", "task_success_rate" (the result's rates);
      "grasp_per_detection" (objects grasped / attempts whose grasp was on the object);
      "failure:<kind>[+<kind>...]" (those failures over the attempts that reached the kind's
      stage, 004's way of counting in Tables 3 and 5);
      "per_attempt:<kind>" (failures of the kind over all attempts, 004 Table 7's way);
      "success:model=<name>" (grasp successes over attempts of that model);
      "mean_object_success" (mean over models of grasp successes / attempts, 002's average);
      "pooled_success" (all grasp successes / all attempts);
      "objects_picked" (models grasped at least once / models tried);
      None: we measure nothing comparable.
    mode: for "selection", the result's mode ("auto" or "manual") the figure is compared with.
    baseline: the "Work of [5]" column of 004's tables, where it has one.
    """

    label: str
    metric: str | None
    value: Count | None
    cite: Cite
    baseline: Count | None = None
    mode: str | None = None
    note: str = ""


@dataclass(frozen=True)
class Timing:
    """A published stage time: mean and standard deviation (s); None where not printed."""

    mean_s: float | None
    std_s: float | None = None


@dataclass(frozen=True)
class TimingColumn:
    """One column of a published timing table, keyed by our stage names (picking.STAGES);
    `extra` holds the rows we do not time (driving, task totals)."""

    label: str
    cite: Cite
    stages: Mapping[str, Timing]
    extra: Mapping[str, Timing] = field(default_factory=dict)
    note: str = ""


@dataclass(frozen=True)
class Row:
    """One row of a published breakdown; `match` picks our records for the row by record field
    ("model", "surface", or "location": a `locN` found in the record's surface or instance)."""

    name: str
    values: tuple[object, ...]
    match: tuple[tuple[str, str], ...] = ()


@dataclass(frozen=True)
class Breakdown:
    """A published table by object, surface or location, printed beside ours.

    ours: what to show for our matching records: "success" (grasp successes / attempts) or
    "failures" (failed attempts / attempts).
    """

    title: str
    cite: Cite
    columns: tuple[str, ...]
    rows: tuple[Row, ...]
    ours: str = "success"
    note: str = ""


@dataclass(frozen=True)
class Reference:
    """What one protocol reruns and everything the paper publishes for it."""

    protocol: str
    experiment: str
    cite: Cite
    figures: tuple[Figure, ...]
    timings: tuple[TimingColumn, ...] = ()
    breakdowns: tuple[Breakdown, ...] = ()
    notes: tuple[str, ...] = ()


def stage_timings(**kw: tuple[float | None, float | None]) -> Mapping[str, Timing]:
    return MappingProxyType({k: Timing(*v) for k, v in kw.items()})
