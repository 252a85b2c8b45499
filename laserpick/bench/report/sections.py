"""The Markdown report of one bench run, section by section: the run, the targets, the
paper's figures beside ours, the paper's breakdowns, our failures by object, the stage
timings and the command's options."""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from laserpick.bench import FAILURE_KINDS, MOTION_STAGES, STAGES
from laserpick.bench.papers import Breakdown, Reference, TimingColumn, reference
from laserpick.bench.report.checks import Check, check_targets
from laserpick.bench.report.measures import Summary, failures, modes, ours_text, totals
from laserpick.bench.report.text import DASH, fraction, markdown_table, seconds


def _revision(result: dict[str, Any]) -> str:
    """The commit a run ran on, as the header shows it: " (commit C)", marked where its tree
    had uncommitted changes; nothing for a result that did not record it."""
    commit = result.get("commit")
    if commit is None:
        return ""
    dirty = ", with uncommitted changes" if result.get("tree_clean") is False else ""
    return f" (commit {commit}{dirty})"


def _header(result: dict[str, Any], ref: Reference) -> list[str]:
    p = result["protocol"]
    lines = [f"# laserpick bench: {p} (seed {result.get('seed')}, {result.get('trials')} trials)"]
    lines += ["", f"Reruns {ref.experiment}. Published figures: {ref.cite}."]
    lines += [
        "",
        f"{result.get('attempts', 0)} grasp attempts on {result.get('tasks', 0)} tasks; "
        f"wall time {result.get('wall_time_s', 0.0):.0f} s; "
        f"laserpick {result.get('version', '?')}{_revision(result)}; "
        f"created {result.get('created', '?')}.",
    ]
    env = result.get("environment")
    if env:  # runs before the record was kept have none
        packages = ", ".join(f"{k} {v}" for k, v in env["packages"].items() if v)
        lines += ["", f"Python {env['python']}; {packages}; CPU: {env['cpu']}."]
        overrides = env.get("settings")
        if overrides is not None:
            said = ", ".join(f"`{k}={v}`" for k, v in overrides.items()) or "none"
            lines += ["", f"Settings overridden by the environment: {said}."]
    for error in result.get("errors") or []:
        lines += [
            "",
            f"**A trial broke off, and its attempts are missing:** {error.splitlines()[0]}",
        ]
    return lines


def _options(result: dict[str, Any]) -> list[str]:
    opts = {"protocol": result["protocol"], "seed": result.get("seed"),
            "trials": result.get("trials"), **(result.get("options") or {})}  # fmt: skip
    rows = [(k, "none" if v is None else v) for k, v in opts.items()]
    return ["## Command options", "", *markdown_table(("option", "value"), rows)]


def _targets_section(checks: list[Check]) -> list[str]:
    missed = [c.label for c in checks if not c.met]
    verdict = f"**{len(checks) - len(missed)} of {len(checks)} targets met.**" + (
        f" NOT MET: {'; '.join(missed)}." if missed else ""
    )
    rows = [(c.label, c.required, c.got, "met" if c.met else "**NOT MET**") for c in checks]
    return [
        "## Targets",
        "",
        verdict,
        "",
        *markdown_table(("target", "required", "ours", "status"), rows),
    ]


def _paper_section(result: dict[str, Any], ref: Reference) -> list[str]:
    by_mode = dict(modes(result))
    with_mode = any(f.mode for f in ref.figures)
    with_base = any(f.baseline for f in ref.figures)
    header = ["figure", *(["mode"] if with_mode else []), f"paper ({ref.cite.paper})"]
    header += [*(["baseline [5] (as 004 prints it)"] if with_base else []), "ours", "source"]
    rows, marks = [], dict.fromkeys(f.note for f in ref.figures if f.note)
    numbers = {note: i for i, note in enumerate(marks, start=1)}
    notes = [f"[{i}] {note}" for note, i in numbers.items()]
    for f in ref.figures:
        summary = by_mode.get(f.mode or "ours", result)
        label = f.label + (f" [{numbers[f.note]}]" if f.note else "")
        row = [label, *([f.mode or ""] if with_mode else []), str(f.value or "not reported")]
        row += [*([str(f.baseline or DASH)] if with_base else []), ours_text(summary, f.metric)]
        rows.append([*row, str(f.cite)])
    lines = [f"## Against the paper ({ref.cite})", "", *markdown_table(header, rows)]
    if any(f.metric and f.metric.startswith("failure:") for f in ref.figures):
        notes.append(
            "Failure rates: failures / attempts that reached the stage (ours: attempts not "
            "stopped by an earlier kind, in the order " + ", ".join(FAILURE_KINDS) + ")."
        )
    return lines + ([""] + notes if notes else [])


def failure_rows(summary: Summary) -> list[list[object]]:
    """Per object: attempts, detected, grasped, tasks, tasks done, then a count per failure
    kind; the last row ("all") sums the objects."""
    objects = summary.get("objects") or {}
    keys = ("attempts", "detect_success", "grasp_success", "tasks", "task_success")
    rows: list[list[object]] = []
    for name in sorted(objects):
        o = objects[name]
        fails = failures(o)
        rows.append([name, *(int(o.get(k, 0)) for k in keys), *(fails[k] for k in FAILURE_KINDS)])
    rows.append(["all", *(sum(int(r[i]) for r in rows) for i in range(1, len(keys) + 7))])
    return rows


def _failure_table(summary: Summary) -> list[str]:
    header = ("object", "attempts", "detected", "grasped", "tasks", "done", *FAILURE_KINDS)
    rows = failure_rows(summary)
    lines = markdown_table(header, rows)
    total = rows[-1][6:]
    listed = [failures(summary)[k] for k in FAILURE_KINDS]
    if summary.get("failures") is not None and list(total) != listed:
        lines += ["", f"Note: the run's failure totals ({listed}) differ from the objects' sums."]
    return lines


def _failure_section(result: dict[str, Any]) -> list[str]:
    lines = [
        "## Failures by object",
        "",
        "Per object: attempts, attempts whose grasp was on the object (detected), objects "
        "grasped, tasks and tasks done, and the attempts lost to each failure kind (the kinds "
        "of 004 Tables 3 and 5, plus precondition; 004 Table 1 gives only the overall rates).",
    ]
    titles = {"auto": "### Automatic selection", "manual": "### Manual selection"}
    for name, summary in modes(result):
        lines += ["", *([titles[name], ""] if name in titles else []), *_failure_table(summary)]
    return lines


def _stage_cell(summary: Summary, stage: str) -> str:
    t = (summary.get("timings_s") or {}).get(stage) or {}
    if not t.get("n"):
        return DASH
    return f"{seconds(t.get('mean'), t.get('std'))} ({t['n']})"


def _paper_cell(column: TimingColumn, stage: str) -> str:
    """A published time as printed (s)."""
    t = column.stages.get(stage) or column.extra.get(stage)
    if t is None:
        return DASH
    mean = "?" if t.mean_s is None else f"{t.mean_s:.1f}"
    return f"{mean} s" if t.std_s is None else f"{mean} ± {t.std_s:.1f} s"


def _timing_section(result: dict[str, Any], ref: Reference) -> list[str]:
    named = modes(result)
    columns = ref.timings
    header = ["stage", *(f"{n} (n)" for n, _ in named), *(f"{c.label} ({c.cite})" for c in columns)]
    rows = [[s, *(_stage_cell(m, s) for _, m in named), *(_paper_cell(c, s) for c in columns)]
            for s in STAGES]  # fmt: skip
    motion = [[f"motion: {s}", *(_stage_cell(m, s) for _, m in named), *(DASH for _ in columns)]
              for s in MOTION_STAGES]  # fmt: skip
    at = STAGES.index("execute_sim") + 1
    rows[at:at] = [row for row in motion if any(cell != DASH for cell in row[1 : 1 + len(named)])]
    extra = dict.fromkeys(k for c in columns for k in c.extra)
    rows += [[k, *(DASH for _ in named), *(_paper_cell(c, k) for c in columns)] for k in extra]
    notes = [
        "Ours: mean ± std over the attempts that reached the stage (n); wall-clock time of the "
        "pipeline, except execute_sim (simulated time); attempt_total is their sum, over the"
        " successful attempts. The motion rows split execute_sim at the session's progress"
        " messages: to the pre-grasp, the guarded approach, closing the hand, the re-grip and"
        " lift, the carry until the hand has let go."
    ]
    notes += [f"{c.label}: {c.note}." for c in columns if c.note]
    if not columns:
        notes.append(f"{ref.cite.paper} gives no stage timings for this experiment.")
    return ["## Stage timings", "", *markdown_table(header, rows), "", *notes]


def _record_location(rec: dict[str, Any]) -> str | None:
    for text in (rec.get("surface"), rec.get("instance")):
        m = re.search(r"loc(\d+)", text or "")
        if m:
            return f"loc{m.group(1)}"
    return None


def _matches(rec: dict[str, Any], match: tuple[tuple[str, str], ...]) -> bool:
    def get(key: str) -> str | None:
        return _record_location(rec) if key == "location" else rec.get(key)

    return all(get(k) == v for k, v in match)


def _breakdown_ours(records: list[dict[str, Any]], b: Breakdown, match: tuple) -> str:
    hits = [r for r in records if _matches(r, match)] if match else []
    if not hits:
        return DASH
    if b.ours == "failures":
        return fraction(sum(1 for r in hits if r.get("failure")), len(hits)) + " failed"
    return fraction(sum(1 for r in hits if r.get("grasped")), len(hits))


def _breakdown_section(result: dict[str, Any], b: Breakdown) -> list[str]:
    records = result.get("records") or []
    ours_label = ["ours: failed attempts" if b.ours == "failures" else "ours: grasped"]
    ours_label = ours_label if any(r.match for r in b.rows) else []
    rows = [[r.name, *(DASH if v is None else v for v in r.values),
             *([_breakdown_ours(records, b, r.match)] if ours_label else [])]
            for r in b.rows]  # fmt: skip
    lines = [
        f"### {b.title} ({b.cite})",
        "",
        *markdown_table(["row", *b.columns, *ours_label], rows),
    ]
    return lines + (["", f"{b.note}."] if b.note else [])


def _selection_section(result: dict[str, Any]) -> list[str]:
    named = modes(result)
    metrics = ["grasp_success_rate", "detect_success_rate", "task_success_rate"]
    rows = [["attempts", *(totals(s)["attempts"] for _, s in named)]]
    rows += [[m, *(ours_text(s, m) for _, s in named)] for m in metrics]
    rows += [[f"{k} / attempts", *(ours_text(s, f"per_attempt:{k}") for _, s in named)]
             for k in FAILURE_KINDS]  # fmt: skip
    rows += [["attempt_total", *(_stage_cell(s, "attempt_total") for _, s in named)]]
    return ["## Automatic and manual selection side by side", "",
            *markdown_table(["measure", *(n for n, _ in named)], rows)]  # fmt: skip


def markdown(result: dict[str, Any], images: Sequence[str] = ()) -> str:
    """The report of one bench run (Markdown that reads as plain text too).

    images: file names of plots to link (relative to the report), e.g. those of `plots`.
    """
    ref = reference(result["protocol"])
    lines = [*_header(result, ref), "", *_targets_section(check_targets(result)), ""]
    lines += [*_paper_section(result, ref), ""]
    if result["protocol"] == "selection":
        lines += [*_selection_section(result), ""]
    for b in ref.breakdowns:
        lines += [*_breakdown_section(result, b), ""]
    lines += [*_failure_section(result), "", *_timing_section(result, ref), ""]
    if ref.notes:
        lines += ["## Notes on the paper", "", *(f"- {n}" for n in ref.notes), ""]
    lines += [*_options(result), ""]
    lines += [f"![{Path(name).stem}]({name})" for name in images]
    return "\n".join(lines).rstrip() + "\n"
