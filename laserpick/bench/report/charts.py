"""The PNG plots of one bench run: success by object (grouped by selection mode for
"selection") and the mean time per stage, stacked, beside the paper's.

matplotlib is imported inside the functions only, so importing the report stays cheap.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from laserpick.bench import STAGES
from laserpick.bench.papers import Reference, reference
from laserpick.bench.report.measures import Summary, attempt_time, modes, totals

#: The protocols whose success by object is per task (an object may take several attempts).
PER_TASK = ("in-situ", "pick-place")


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
    ref = reference(result["protocol"])
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
