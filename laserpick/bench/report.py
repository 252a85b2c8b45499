"""A bench run's result (the JSON of `laserpick bench`) as a Markdown report and PNG plots.

`markdown(result)` puts the paper's figures (`papers.REFERENCES`) beside ours, lists our
failures per object, the stage timings and whether each target (`papers.TARGETS`) is met;
`plots(result, out_dir, stem)` draws success by object and the stage times; `write_reports`
writes both beside the JSON file.

Units: rates are fractions (0..1) in the result and percent in the report; times in s (every
stage is wall-clock time of the pipeline except execute_sim, which is simulated time).
matplotlib is imported inside `plots` only, so importing this module stays cheap.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from laserpick.bench import FAILURE_KINDS, STAGES
from laserpick.bench.papers import Breakdown, Reference, Target, TimingColumn
from laserpick.bench.papers import reference as paper_reference
from laserpick.bench.papers import targets as paper_targets

#: The protocols whose success by object is per task (an object may take several attempts).
PER_TASK = ("in-situ", "pick-place")
DASH = "–"

Summary = dict[str, Any]


# --- numbers --------------------------------------------------------------------------------


def _pct(rate: float | None) -> str:
    """A fraction (0..1) as a percentage with one decimal, or a dash."""
    if rate is None or not math.isfinite(rate):
        return DASH
    return f"{100 * rate:.1f} %"


def _frac(k: int | None, n: int | None) -> str:
    """k of n as "p % (k/n)", or a dash when n is 0 or unknown."""
    if k is None or not n:
        return DASH
    return f"{_pct(k / n)} ({k}/{n})"


def _num(x: float) -> str:
    """A time (s) to about three significant digits (0.004, 0.52, 3.84, 51.7)."""
    return f"{x:.1f}" if abs(x) >= 10 else f"{x:.2f}" if abs(x) >= 1 else f"{x:.3f}"


def _secs(mean: float | None, std: float | None = None) -> str:
    """A time (s) with its standard deviation when known, or a dash."""
    if mean is None:
        return DASH if std is None else f"? ± {_num(std)} s"
    return f"{_num(mean)} s" if std is None else f"{_num(mean)} ± {_num(std)} s"


def _table(header: Sequence[str], rows: Iterable[Sequence[object]]) -> list[str]:
    """A Markdown table whose columns are padded to line up as plain text too."""
    cells = [[str(c) for c in header]] + [[str(c) for c in row] for row in rows]
    widths = [max(len(r[i]) for r in cells) for i in range(len(header))]

    def line(row: list[str]) -> str:
        return "| " + " | ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)) + " |"

    return [line(cells[0]), "|" + "|".join("-" * (w + 2) for w in widths) + "|"] + [
        line(r) for r in cells[1:]
    ]


# --- the result's summaries -------------------------------------------------------------------


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


def _rate_with_counts(summary: Summary, key: str) -> tuple[float | None, int | None, int | None]:
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
        return _rate_with_counts(summary, metric)
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


def _ours_text(summary: Summary, metric: str | None) -> str:
    if metric is None:
        return "not measured"
    rate, k, n = ours(summary, metric)
    return _frac(k, n) if k is not None and n else _pct(rate)


def attempt_time(summary: Summary) -> tuple[float | None, float | None, int]:
    """The mean and standard deviation of the attempt time (s), and how many attempts."""
    t = (summary.get("timings_s") or {}).get("attempt_total") or {}
    n = int(t.get("n", 0))
    return (t.get("mean"), t.get("std"), n) if n else (None, None, 0)


# --- targets ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class Check:
    """A target held against a run: what was required, what we got, whether it was met."""

    label: str
    required: str
    got: str
    met: bool


def _check_rate(target: Target, summary: Summary) -> Check:
    rate, k, n = _rate_with_counts(summary, target.metric)
    met = rate is not None and rate >= target.threshold - 1e-12
    got = _frac(k, n) if k is not None else _pct(rate)
    return Check(
        target.label, f">= {_pct(target.threshold)}", got if rate is not None else "no data", met
    )


def _check_time(target: Target, summary: Summary, name: str, protocol: str) -> Check:
    mean, std, n = attempt_time(summary)
    label = target.label if name == "ours" else f"{target.label} ({name})"
    paper = [(c.stages["attempt_total"], c.cite) for c in paper_reference(protocol).timings
             if c.stages.get("attempt_total")]  # fmt: skip
    if paper and paper[0][0].mean_s is not None:
        label += f" ({paper[0][1]}: {paper[0][0].mean_s:g} s)"
    got = f"{_secs(mean, std)} (n = {n})" if n else "no data"
    return Check(label, f"< {target.threshold:g} s", got, n > 0 and mean < target.threshold)


def _check_selection(target: Target, result: dict[str, Any]) -> Check:
    by_mode = dict(modes(result))
    if "auto" not in by_mode or "manual" not in by_mode:
        return Check(target.label, f"manual <= {target.threshold:g} × auto", "no modes", False)
    auto, _, _ = ours(by_mode["auto"], "per_attempt:wrong_object")
    manual, _, _ = ours(by_mode["manual"], "per_attempt:wrong_object")
    if auto is None or manual is None:
        return Check(target.label, f"manual <= {target.threshold:g} × auto", "no data", False)
    got = f"manual {_pct(manual)}, auto {_pct(auto)}"
    return Check(target.label, f"manual <= {target.threshold:g} × auto", got,
                 manual <= target.threshold * auto + 1e-12)  # fmt: skip


def check_targets(result: dict[str, Any]) -> list[Check]:
    """Every target of the run's protocol, checked (per mode where the protocol has modes)."""
    protocol = result["protocol"]
    checks: list[Check] = []
    for target in paper_targets(protocol):
        if target.metric == "attempt_total_s":
            checks += [_check_time(target, s, name, protocol) for name, s in modes(result)]
        elif target.metric == "wrong_object_manual_vs_auto":
            checks.append(_check_selection(target, result))
        else:
            checks.append(_check_rate(target, result))
    return checks


# --- report sections -------------------------------------------------------------------------


def _header(result: dict[str, Any], ref: Reference) -> list[str]:
    p = result["protocol"]
    lines = [f"# laserpick bench: {p} (seed {result.get('seed')}, {result.get('trials')} trials)"]
    lines += ["", f"Reruns {ref.experiment}. Published figures: {ref.cite}."]
    lines += [
        "",
        f"{result.get('attempts', 0)} grasp attempts on {result.get('tasks', 0)} tasks; "
        f"wall time {result.get('wall_time_s', 0.0):.0f} s; "
        f"laserpick {result.get('version', '?')}; "
        f"created {result.get('created', '?')}.",
    ]
    env = result.get("environment")
    if env:  # runs before the record was kept have none
        packages = ", ".join(f"{k} {v}" for k, v in env["packages"].items() if v)
        lines += ["", f"Python {env['python']}; {packages}; CPU: {env['cpu']}."]
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
    return ["## Command options", "", *_table(("option", "value"), rows)]


def _targets_section(checks: list[Check]) -> list[str]:
    missed = [c.label for c in checks if not c.met]
    verdict = f"**{len(checks) - len(missed)} of {len(checks)} targets met.**" + (
        f" NOT MET: {'; '.join(missed)}." if missed else ""
    )
    rows = [(c.label, c.required, c.got, "met" if c.met else "**NOT MET**") for c in checks]
    return ["## Targets", "", verdict, "", *_table(("target", "required", "ours", "status"), rows)]


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
        row += [*([str(f.baseline or DASH)] if with_base else []), _ours_text(summary, f.metric)]
        rows.append([*row, str(f.cite)])
    lines = [f"## Against the paper ({ref.cite})", "", *_table(header, rows)]
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
    lines = _table(header, rows)
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
    return f"{_secs(t.get('mean'), t.get('std'))} ({t['n']})"


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
    extra = dict.fromkeys(k for c in columns for k in c.extra)
    rows += [[k, *(DASH for _ in named), *(_paper_cell(c, k) for c in columns)] for k in extra]
    notes = [
        "Ours: mean ± std over the attempts that reached the stage (n); wall-clock time of the "
        "pipeline, except execute_sim (simulated time); attempt_total is their sum, over the"
        " successful attempts."
    ]
    notes += [f"{c.label}: {c.note}." for c in columns if c.note]
    if not columns:
        notes.append(f"{ref.cite.paper} gives no stage timings for this experiment.")
    return ["## Stage timings", "", *_table(header, rows), "", *notes]


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
        return _frac(sum(1 for r in hits if r.get("failure")), len(hits)) + " failed"
    return _frac(sum(1 for r in hits if r.get("grasped")), len(hits))


def _breakdown_section(result: dict[str, Any], b: Breakdown) -> list[str]:
    records = result.get("records") or []
    ours_label = ["ours: failed attempts" if b.ours == "failures" else "ours: grasped"]
    ours_label = ours_label if any(r.match for r in b.rows) else []
    rows = [[r.name, *(DASH if v is None else v for v in r.values),
             *([_breakdown_ours(records, b, r.match)] if ours_label else [])]
            for r in b.rows]  # fmt: skip
    lines = [f"### {b.title} ({b.cite})", "", *_table(["row", *b.columns, *ours_label], rows)]
    return lines + (["", f"{b.note}."] if b.note else [])


def _selection_section(result: dict[str, Any]) -> list[str]:
    named = modes(result)
    metrics = ["grasp_success_rate", "detect_success_rate", "task_success_rate"]
    rows = [["attempts", *(totals(s)["attempts"] for _, s in named)]]
    rows += [[m, *(_ours_text(s, m) for _, s in named)] for m in metrics]
    rows += [[f"{k} / attempts", *(_ours_text(s, f"per_attempt:{k}") for _, s in named)]
             for k in FAILURE_KINDS]  # fmt: skip
    rows += [["attempt_total", *(_stage_cell(s, "attempt_total") for _, s in named)]]
    return ["## Automatic and manual selection side by side", "",
            *_table(["measure", *(n for n, _ in named)], rows)]  # fmt: skip


def markdown(result: dict[str, Any], images: Sequence[str] = ()) -> str:
    """The report of one bench run (Markdown that reads as plain text too).

    images: file names of plots to link (relative to the report), e.g. those of `plots`.
    """
    ref = paper_reference(result["protocol"])
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


# --- plots -----------------------------------------------------------------------------------


def _object_success(protocol: str, entry: Summary) -> tuple[int, int]:
    """(successes, tries) of one object or of all: tasks done / tasks for the protocols with
    several attempts per task, else objects grasped / attempts."""
    if protocol in PER_TASK:
        return int(entry.get("task_success", 0)), int(entry.get("tasks", 0))
    return int(entry.get("grasp_success", 0)), int(entry.get("attempts", 0))


def _new_figure(width_in: float, height_in: float) -> Any:
    """A matplotlib figure on the Agg canvas (no pyplot, no GUI), 100 px per inch."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure as MplFigure

    fig = MplFigure(figsize=(width_in, height_in), dpi=100, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _success_plot(result: dict[str, Any], path: Path) -> Path:
    protocol, named = result["protocol"], modes(result)
    models = sorted({m for _, s in named for m in (s.get("objects") or {})})
    rows = ["all", *models]
    fig = _new_figure(8.0, max(3.2, 1.6 + 0.32 * len(rows) * max(1, len(named) * 0.7)))
    ax = fig.add_subplot()
    height = 0.8 / len(named)
    for i, (name, summary) in enumerate(named):
        counts = [_object_success(protocol, totals(summary))]
        counts += [
            _object_success(protocol, (summary.get("objects") or {}).get(m, {})) for m in models
        ]
        ys = [r + (i - (len(named) - 1) / 2) * height for r in range(len(rows))]
        xs = [100 * k / n if n else 0.0 for k, n in counts]
        bars = ax.barh(ys, xs, height=height * 0.9, label=name, color=f"C{i}")
        ax.bar_label(bars, [f"{k}/{n}" if n else "none" for k, n in counts], padding=3, fontsize=8)
    if protocol in PER_TASK:
        ax.axvline(96, color="0.3", linestyle="--", linewidth=1, label="target 96 %")
    ax.set_yticks(range(len(rows)), rows, fontsize=9)
    ax.set_ylim(len(rows) - 0.5, -0.5)  # "all" on top
    ax.set_xlim(0, 118)
    what = "tasks done per task" if protocol in PER_TASK else "objects grasped per attempt"
    ax.set_xlabel(f"success: {what} (%)")
    ax.set_ylabel("object model")
    ax.set_title(f"{protocol}: success by object (seed {result.get('seed')}, "
                 f"{result.get('trials')} trials)")  # fmt: skip
    ax.axhline(0.5, color="0.6", linewidth=0.8)  # "all" above, the objects below
    if len(named) > 1 or protocol in PER_TASK:
        fig.legend(loc="outside lower center", ncol=3, fontsize=8, frameon=False)
    ax.grid(axis="x", alpha=0.3)
    fig.savefig(path)
    return path


def _stage_means(summary: Summary) -> dict[str, float]:
    t = summary.get("timings_s") or {}
    return {s: float(t[s]["mean"]) for s in STAGES[:-1] if s in t and t[s].get("n")}


def _paper_stacks(ref: Reference) -> list[tuple[str, dict[str, float], float | None]]:
    """The published stage means (s) as stacks: (label, means, attempt total or None)."""
    out = []
    for c in ref.timings:
        means = {s: t.mean_s for s, t in c.stages.items() if s != "attempt_total" and t.mean_s}
        total = c.stages.get("attempt_total")
        where = f"{c.cite.paper} {c.cite.table or '§' + c.cite.section}"
        label = c.label if c.label.startswith(c.cite.paper) else f"{c.label} ({c.cite.paper})"
        label = f"{label.replace(c.cite.paper, where, 1)}"
        missing = [s for s in STAGES[:-1] if s in c.stages and c.stages[s].mean_s is None]
        label += "".join(f"\n({s} not given)" for s in missing)
        out.append((label, means, total.mean_s if total else None))
    return [s for s in out if s[1]]


def _timing_plot(result: dict[str, Any], path: Path) -> Path:
    ref = paper_reference(result["protocol"])
    stacks = [(name, _stage_means(s), attempt_time(s)[0]) for name, s in modes(result)]
    stacks += _paper_stacks(ref)
    fig = _new_figure(8.0, 2.6 + 0.75 * len(stacks))
    ax = fig.add_subplot()
    for j, stage in enumerate(STAGES[:-1]):
        widths = [m.get(stage, 0.0) for _, m, _ in stacks]
        lefts = [sum(m.get(s, 0.0) for s in STAGES[:j]) for _, m, _ in stacks]
        ax.barh(range(len(stacks)), widths, left=lefts, height=0.6, label=stage, color=f"C{j}")
    for y, (_, means, total) in enumerate(stacks):
        end = sum(means.values())
        if total is not None:
            ax.plot([total], [y], marker="|", markersize=22, color="black", linestyle="none")
        text = f"attempt total {total:.1f} s" if total is not None else f"sum {end:.1f} s"
        ax.annotate(text, (max(end, total or 0.0), y), xytext=(6, 0), textcoords="offset points",
                    va="center", fontsize=8)  # fmt: skip
    ax.set_yticks(range(len(stacks)), [name for name, _, _ in stacks], fontsize=9)
    ax.invert_yaxis()
    longest = max([max(sum(m.values()), t or 0.0) for _, m, t in stacks] + [1e-3])
    ax.set_xlim(0, longest * 1.3)
    ax.set_xlabel("mean time per attempt (s); execute_sim is simulated time; | = attempt total")
    ax.set_title(f"{result['protocol']}: time per stage (seed {result.get('seed')})")
    fig.legend(loc="outside lower center", ncol=4, fontsize=8, frameon=False)
    ax.grid(axis="x", alpha=0.3)
    fig.savefig(path)
    return path


def plots(result: dict[str, Any], out_dir: Path, stem: str) -> list[Path]:
    """Draws `<stem>-success.png` (success by object, grouped by selection mode for
    "selection") and `<stem>-timings.png` (mean s per stage, stacked, beside the paper's) in
    `out_dir`, 800 px wide; returns their paths."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    return [
        _success_plot(result, out_dir / f"{stem}-success.png"),
        _timing_plot(result, out_dir / f"{stem}-timings.png"),
    ]


def write_reports(result: dict[str, Any], out_json: Path) -> list[Path]:
    """Writes `<stem>.md` and the plots beside the result's JSON file; returns their paths
    (the Markdown first)."""
    out_json = Path(out_json)
    images = plots(result, out_json.parent, out_json.stem)
    md = out_json.with_suffix(".md")
    md.write_text(markdown(result, images=[p.name for p in images]), encoding="utf-8")
    return [md, *images]
