"""Two bench results compared attempt by attempt (`laserpick bench --compare OLD NEW`).

The bench is deterministic: the same code, seed and packages give the same attempts. After a
change, rerun a protocol with the same seed and compare: every attempt whose object, verdict
(detected, grasped, success), failure kind, marks, grip widths, lever or simulated execution
time differs is listed, field by field. Wall-clock timings and messages are not compared
(a failure's message is shown beside its kind where the kind differs).

An attempt is named by its trial, task, selection mode and, where a task took several
attempts (in-situ and pick-place retries), its try within the task. Floats are compared
exactly unless a tolerance is given (absolute, in the field's unit: m for grip widths and
lever, s for execution time).
"""

from __future__ import annotations

import json
import math
from collections import Counter
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

#: The record fields compared, in the order they are listed; `execute_sim` is read from the
#: record's timings (s of simulated time).
COMPARED = (
    "instance",
    "model",
    "surface",
    "strategy",
    "marks",
    "places",
    "detected",
    "grasped",
    "success",
    "failure",
    "grip",
    "lever",
    "execute_sim",
)
#: The run options that change what a run does (workers and ray only change where it runs).
OUTCOME_OPTIONS = ("selection", "strategy", "scene", "tremor_deg", "objects")

Record = dict[str, Any]


class ResultFileError(ValueError):
    """A result file that cannot be read, or that is not a bench result."""


class ResultMismatch(ValueError):
    """Two results that cannot be compared attempt by attempt (another protocol or seed)."""


@dataclass(frozen=True, order=True)
class AttemptKey:
    """Where an attempt stands in its run: trial, task, selection mode and try (1 for a
    task's first attempt)."""

    trial: int
    task: int
    selection: str
    try_: int = 1

    def __str__(self) -> str:
        text = f"trial {self.trial}, task {self.task}, {self.selection}"
        return text + (f", try {self.try_}" if self.try_ > 1 else "")


@dataclass(frozen=True)
class FieldChange:
    """One compared field of an attempt, as each result has it."""

    name: str
    old: Any
    new: Any


@dataclass(frozen=True)
class AttemptDifference:
    """An attempt that differs: in both results with `changes`, or in one only (the other
    record is None)."""

    key: AttemptKey
    old: Record | None
    new: Record | None
    changes: tuple[FieldChange, ...] = ()


@dataclass(frozen=True)
class Comparison:
    """What `compare_results` found: the differing attempts, in run order, and notes on what
    else differs between the runs (options, package versions, trials that broke off)."""

    protocol: str
    seed: int
    old_attempts: int
    new_attempts: int
    attempts: int  #: in either run
    differences: tuple[AttemptDifference, ...]
    notes: tuple[str, ...] = ()

    @property
    def same(self) -> bool:
        """Whether every attempt matches."""
        return not self.differences


def load_result(path: str | Path) -> dict[str, Any]:
    """A bench result JSON file, checked to hold a protocol and a list of attempt records;
    ResultFileError says why not."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise ResultFileError(f"cannot read {path}: {exc}") from None
    except json.JSONDecodeError as exc:
        raise ResultFileError(f"{path} is not JSON: {exc}") from None
    if not isinstance(data, dict) or not isinstance(data.get("protocol"), str):
        raise ResultFileError(f"{path} is not a bench result (no protocol)")
    records = data.get("records")
    if not isinstance(records, list) or not all(
        isinstance(r, dict) and "trial" in r for r in records
    ):
        raise ResultFileError(f"{path} is not a bench result (no list of attempt records)")
    return data


def attempts_by_key(records: Iterable[Record]) -> dict[AttemptKey, Record]:
    """The records by `AttemptKey`, the tries of a task numbered in the order recorded."""
    tries: Counter[tuple[int, int, str]] = Counter()
    out: dict[AttemptKey, Record] = {}
    for r in records:
        task = (int(r["trial"]), int(r.get("task") or 0), str(r.get("selection", "")))
        tries[task] += 1
        out[AttemptKey(*task, tries[task])] = r
    return out


def field_value(record: Record, name: str) -> Any:
    """A compared field of a record (`COMPARED`); execute_sim from its timings."""
    if name == "execute_sim":
        return (record.get("timings") or {}).get(name)
    return record.get(name)


def values_equal(old: Any, new: Any, tolerance: float = 0.0) -> bool:
    """Whether two field values match: exactly, or floats within `tolerance` (absolute)."""
    if isinstance(old, list | tuple) and isinstance(new, list | tuple):
        return len(old) == len(new) and all(
            values_equal(a, b, tolerance) for a, b in zip(old, new, strict=True)
        )
    if isinstance(old, bool) or isinstance(new, bool):
        return old is new
    if isinstance(old, int | float) and isinstance(new, int | float):
        return old == new or abs(old - new) <= tolerance
    return old == new


def _has_field(record: Record, name: str) -> bool:
    if name == "execute_sim":
        return True  # absent from the timings of an attempt that executed nothing
    return name in record


def attempt_changes(old: Record, new: Record, tolerance: float = 0.0) -> tuple[FieldChange, ...]:
    """The compared fields in which two records of the same attempt differ. A field that one
    of them lacks (a result written before the field was recorded) is not compared."""
    changes = []
    for name in COMPARED:
        if not (_has_field(old, name) and _has_field(new, name)):
            continue
        a, b = field_value(old, name), field_value(new, name)
        if not values_equal(a, b, tolerance):
            changes.append(FieldChange(name, a, b))
    return tuple(changes)


def _code_notes(old: Mapping[str, Any], new: Mapping[str, Any]) -> list[str]:
    """Which code each run ran, where that differs or is uncertain: the commits (`commit`;
    "not recorded" in a result written before it was) and trees with uncommitted changes
    (`tree_clean`). Informational: a change of code is what a comparison is for."""
    notes = []
    commits = [r.get("commit", "not recorded") for r in (old, new)]
    if ("commit" in old or "commit" in new) and commits[0] != commits[1]:
        notes.append(f"commit differs: {commits[0]} -> {commits[1]}")
    for which, result in (("old", old), ("new", new)):
        if result.get("tree_clean") is False:
            notes.append(f"the {which} run's tree had uncommitted changes")
    return notes


def _run_notes(old: Mapping[str, Any], new: Mapping[str, Any]) -> list[str]:
    """What differs between the runs besides their attempts."""
    notes = _code_notes(old, new)
    if old.get("trials") != new.get("trials"):
        notes.append(f"trials differ: {old.get('trials')} -> {new.get('trials')}")
    old_opt, new_opt = old.get("options") or {}, new.get("options") or {}
    for key in OUTCOME_OPTIONS:
        if key in old_opt and key in new_opt and old_opt[key] != new_opt[key]:
            notes.append(f"option {key} differs: {old_opt[key]} -> {new_opt[key]}")
    old_pkg = (old.get("environment") or {}).get("packages") or {}
    new_pkg = (new.get("environment") or {}).get("packages") or {}
    for name in sorted(set(old_pkg) & set(new_pkg)):
        if old_pkg[name] != new_pkg[name]:
            notes.append(f"package {name} differs: {old_pkg[name]} -> {new_pkg[name]}")
    old_set = (old.get("environment") or {}).get("settings")
    new_set = (new.get("environment") or {}).get("settings")
    if old_set is not None and new_set is not None:
        for name in sorted(set(old_set) | set(new_set)):
            if old_set.get(name) != new_set.get(name):
                was, now = old_set.get(name, "unset"), new_set.get(name, "unset")
                notes.append(f"setting {name} differs: {was} -> {now}")
    # Floating point differs in its last digits between CPU models: a grip a millimetre off
    # sends a trial elsewhere, so attempts repeat on one machine only.
    cpus = [(r.get("environment") or {}).get("cpu") for r in (old, new)]
    if None not in cpus and cpus[0] != cpus[1]:
        notes.append(f"CPU differs: {cpus[0]} -> {cpus[1]}; attempts repeat on one CPU model only")
    for which, result in (("old", old), ("new", new)):
        for error in result.get("errors") or []:
            notes.append(f"a trial of the {which} run broke off: {error.splitlines()[0]}")
    return notes


def compare_results(
    old: Mapping[str, Any], new: Mapping[str, Any], tolerance: float = 0.0
) -> Comparison:
    """Compare two results attempt by attempt. Raises ResultMismatch when they ran another
    protocol or seed. tolerance: how far (absolute) floats may differ; 0: exactly."""
    if not math.isfinite(tolerance) or tolerance < 0:
        raise ValueError(f"--tolerance must be a finite number >= 0, not {tolerance}")
    for key in ("protocol", "seed"):
        if old.get(key) != new.get(key):
            raise ResultMismatch(
                f"the two results ran different {key}s (old: {old.get(key)}, new: "
                f"{new.get(key)}); compare two runs of one protocol with one seed"
            )
    before, after = attempts_by_key(old["records"]), attempts_by_key(new["records"])
    differences = []
    for key in sorted(before.keys() | after.keys()):
        a, b = before.get(key), after.get(key)
        if a is None or b is None:
            differences.append(AttemptDifference(key, a, b))
        elif changes := attempt_changes(a, b, tolerance):
            differences.append(AttemptDifference(key, a, b, changes))
    return Comparison(
        protocol=str(old["protocol"]),
        seed=int(old.get("seed") or 0),
        old_attempts=len(before),
        new_attempts=len(after),
        attempts=len(before.keys() | after.keys()),
        differences=tuple(differences),
        notes=tuple(_run_notes(old, new)),
    )


def compare_files(old: str | Path, new: str | Path, tolerance: float = 0.0) -> Comparison:
    """`compare_results` on two result files (ResultFileError, ResultMismatch)."""
    return compare_results(load_result(old), load_result(new), tolerance)


# --- the listing ------------------------------------------------------------------------------


def _shown(value: Any) -> str:
    """A field value as the listing prints it: floats in full (the digits that differ
    show), grip widths as a pair, none for a missing value."""
    if value is None:
        return "none"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, list | tuple):
        return "(" + ", ".join(_shown(v) for v in value) + ")"
    return repr(value) if isinstance(value, float) else str(value)


def _outcome(record: Record) -> str:
    """An attempt in a few words: its object and verdict."""
    if record.get("success"):
        verdict = "success"
    else:
        verdict = f"failed ({record.get('failure') or 'no failure kind'})"
        if record.get("message"):
            verdict += f": {record['message']}"
    return f"{record.get('instance')}, {verdict}"


def _change_line(change: FieldChange, old: Record, new: Record) -> str:
    unit = {"grip": " m", "lever": " m", "execute_sim": " s"}.get(change.name, "")
    line = f"    {change.name:<12} {_shown(change.old)}{unit} -> {_shown(change.new)}{unit}"
    if change.name == "failure":  # what the session said, for context
        for which, record in (("old", old), ("new", new)):
            if record.get("message"):
                line += f"\n{'':17}{which}: {record['message']}"
    return line


def _difference_lines(diff: AttemptDifference) -> list[str]:
    if diff.new is None:
        assert diff.old is not None
        return [f"{diff.key}: only in the old run ({_outcome(diff.old)})"]
    if diff.old is None:
        return [f"{diff.key}: only in the new run ({_outcome(diff.new)})"]
    return [
        f"{diff.key} ({diff.old.get('instance')}):",
        *(_change_line(c, diff.old, diff.new) for c in diff.changes),
    ]


def format_comparison(comparison: Comparison, old_label: str, new_label: str) -> str:
    """The comparison as text for a person: the runs, notes on what else differs, each
    differing attempt with its fields (old -> new), and a last line that says "no
    difference" or how many attempts differ."""
    c = comparison
    lines = [
        f"{c.protocol}, seed {c.seed}",
        f"  old: {old_label} ({c.old_attempts} attempts)",
        f"  new: {new_label} ({c.new_attempts} attempts)",
    ]
    lines += [f"  note: {n}" for n in c.notes]
    lines.append("")
    for diff in c.differences:
        lines += _difference_lines(diff)
    if c.same:
        lines.append(f"no difference: all {c.old_attempts} attempts match")
        return "\n".join(lines) + "\n"
    missing = sum(d.old is None or d.new is None for d in c.differences)
    summary = f"{len(c.differences)} of {c.attempts} attempts differ"
    summary += f" ({missing} in one run only)" if missing else ""
    return "\n".join([*lines, "", summary + "."]) + "\n"
