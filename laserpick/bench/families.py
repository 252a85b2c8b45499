"""Lost attempts grouped by family across runs and seeds (`laserpick bench --families`).

A trace of one lost attempt invites a fix for that seed; a family says how often the same
kind of loss comes back. A family is what went wrong, not where it happened to: the failure
kind, the robot's sentence with its numbers, object names and surface numbers taken out, and
the kind of surface the object stood on (`table_73` is a table, `floor_area` the floor).

For each family the report counts the attempts lost, the tasks lost (a task is lost when
none of its attempts succeeded; it is counted under the family of its last attempt) and the
first tries lost that a later try recovered, each of which cost the user another attempt. It
also gives the task success and the first-try success (a task done at its first attempt), with
and without the models left out (`--leave-out glass_cup`: transparent objects are work of
their own).
"""

from __future__ import annotations

import re
from collections import defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from laserpick.bench.compare import load_result

__all__ = ["Family", "Sweep", "family_of", "format_sweep", "load_sweep", "surface_kind"]

Record = dict[str, Any]

#: How many example attempts a family lists.
EXAMPLES = 3


@dataclass(frozen=True, order=True)
class FamilyKey:
    """What went wrong: the failure kind, the sentence's shape and the surface's kind."""

    kind: str
    sentence: str
    surface: str


@dataclass
class Family:
    """The losses of one `FamilyKey`, with a few of them named."""

    key: FamilyKey
    attempts: int = 0
    tasks_lost: int = 0
    recovered: int = 0  #: first tries lost whose task a later try did
    examples: list[str] = field(default_factory=list)


@dataclass
class Sweep:
    """Attempts of several runs, by task: `tasks[(run, trial, selection, task)]` lists the
    task's attempts in the order they were made."""

    runs: list[str]
    tasks: dict[tuple[str, int, str, int], list[Record]]

    def task_rates(self, leave_out: Iterable[str] = ()) -> tuple[int, int, int]:
        """(tasks, tasks done, tasks done at their first attempt), without the tasks of the
        models in `leave_out`."""
        kept = [a for a in self.tasks.values() if a[0]["model"] not in set(leave_out)]
        done = sum(any(r["success"] for r in a) for a in kept)
        first = sum(bool(a[0]["success"]) for a in kept)
        return len(kept), done, first

    def moved_as_asked(self, field: str) -> tuple[int, int]:
        """(tries in which the user moved the scooter as the robot asked, the attempt's
        `field` non-zero: "backed_up", "parked_aside"; those of them done)."""
        tries = [r for a in self.tasks.values() for r in a if r.get(field, 0.0) != 0.0]
        return len(tries), sum(bool(r["success"]) for r in tries)

    def families(self) -> list[Family]:
        """Every family with a loss, the most attempts lost first."""
        found: dict[FamilyKey, Family] = {}
        for (run, trial, _, task), attempts in self.tasks.items():
            done = any(r["success"] for r in attempts)
            for i, r in enumerate(attempts):
                if r["success"]:
                    continue
                key = family_of(r)
                family = found.setdefault(key, Family(key))
                family.attempts += 1
                family.recovered += int(i == 0 and done)
                family.tasks_lost += int(not done and i == len(attempts) - 1)
                example = f"{run} trial {trial} task {task} {r['instance']}"
                if len(family.examples) < EXAMPLES and example not in family.examples:
                    family.examples.append(example)
        return sorted(found.values(), key=lambda f: (-f.attempts, -f.tasks_lost, f.key))


def surface_kind(surface: str) -> str:
    """The kind of surface an attempt's object stood on: the first surface of a move
    ("table_73 -> floor_area" stood on table_73) without its number or `_area`."""
    first = surface.split("->")[0].strip()
    return re.sub(r"(_area)?(_\d+)?$", "", first) or "?"


def _sentence(message: str, names: Sequence[str]) -> str:
    """The shape of a robot's sentence: its first clause up to the reason in brackets, with
    numbers as N, object names as <object> and surface numbers dropped."""
    text = message.strip()
    for name in sorted({n for n in names if n}, key=len, reverse=True):
        text = re.sub(rf"\b{re.escape(name)}\b", "<object>", text)
    text = re.sub(r"\b([a-z]+)_\d+\b", r"\1", text)  # table_73 -> table
    text = re.sub(r"\d+(\.\d+)?", "N", text)
    text = re.split(r";|\. ", text)[0].rstrip(" .;()")
    if text.count("(") > text.count(")"):
        text += ")"
    return re.sub(r"\s+", " ", text)[:120] or "(no message)"


def family_of(record: Record) -> FamilyKey:
    """The family of a lost attempt (`Attempt.as_dict()`)."""
    names = (record.get("instance", ""), record.get("model", ""))
    return FamilyKey(
        kind=str(record.get("failure") or "none"),
        sentence=_sentence(str(record.get("message") or ""), names),
        surface=surface_kind(str(record.get("surface") or "")),
    )


def load_sweep(paths: Sequence[str | Path]) -> Sweep:
    """The attempts of the result files `paths` by task (ResultFileError: one is not a
    bench result)."""
    tasks: dict[tuple[str, int, str, int], list[Record]] = defaultdict(list)
    runs = []
    for path in paths:
        result = load_result(path)
        run = f"{result['protocol']} seed {result.get('seed', '?')}"
        runs.append(run)
        for r in result["records"]:
            tasks[(run, int(r["trial"]), str(r["selection"]), int(r.get("task") or 0))].append(r)
    return Sweep(runs, dict(tasks))


def _rate_line(label: str, counts: tuple[int, int, int]) -> str:
    n, done, first = counts
    pct = (lambda k: f"{100 * k / n:.1f} %") if n else (lambda k: "–")
    return f"| {label} | {n} | {done} ({pct(done)}) | {first} ({pct(first)}) |"


def format_sweep(sweep: Sweep, leave_out: Sequence[str] = ()) -> str:
    """The sweep as Markdown: the task rates (with and without `leave_out`), then the
    families, the most attempts lost first."""
    lines = [
        f"Runs: {', '.join(sweep.runs)}",
        "",
        "| tasks | n | done | done at the first try |",
        "|---|---|---|---|",
        _rate_line("all", sweep.task_rates()),
    ]
    if leave_out:
        lines.append(_rate_line(f"without {', '.join(leave_out)}", sweep.task_rates(leave_out)))
    backed, backed_done = sweep.moved_as_asked("backed_up")
    aside, aside_done = sweep.moved_as_asked("parked_aside")
    lines += [
        "",
        f"Tries in which the user backed up as the robot asked, before the arm moved: {backed}"
        f" ({backed_done} of them done); parked to a side as it asked, for its cameras to see"
        f" the way: {aside} ({aside_done} of them done).",
        "",
        "| failure | what the robot said | on | attempts lost | tasks lost | first tries"
        " a later try recovered | e.g. |",
        "|---|---|---|---|---|---|---|",
    ]
    for f in sweep.families():
        k = f.key
        lines.append(
            f"| {k.kind} | {k.sentence} | {k.surface} | {f.attempts} | {f.tasks_lost}"
            f" | {f.recovered} | {'; '.join(f.examples)} |"
        )
    return "\n".join(lines) + "\n"
