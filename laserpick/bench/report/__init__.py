"""A bench run's result (the JSON of `laserpick bench`) as a Markdown report and PNG plots.

`markdown(result)` puts the paper's figures (`papers.REFERENCES`) beside ours, lists our
failures per object, the stage timings and whether each target (`targets.TARGETS`) is met;
`plots(result, out_dir, stem)` draws success by object and the stage times; `write_reports`
writes both beside the JSON file. `measures` holds our numbers from the result, `checks` the
targets held against them, `sections` the Markdown, `charts` the plots and `text` how
numbers and tables are written.

Units: rates are fractions (0..1) in the result and percent in the report; times in s (every
stage is wall-clock time of the pipeline except execute_sim, which is simulated time).
matplotlib is imported inside `plots` only, so importing this package stays cheap.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from laserpick.bench.report.charts import plots
from laserpick.bench.report.checks import Check, check_targets
from laserpick.bench.report.measures import (
    attempt_time,
    failures,
    modes,
    ours,
    reached,
    totals,
)
from laserpick.bench.report.sections import failure_rows, markdown

__all__ = [
    "Check",
    "attempt_time",
    "check_targets",
    "failure_rows",
    "failures",
    "markdown",
    "modes",
    "ours",
    "plots",
    "reached",
    "totals",
    "write_reports",
]


def write_reports(result: dict[str, Any], out_json: Path) -> list[Path]:
    """Writes `<stem>.md` and the plots beside the result's JSON file; returns their paths
    (the Markdown first)."""
    out_json = Path(out_json)
    images = plots(result, out_json.parent, out_json.stem)
    md = out_json.with_suffix(".md")
    md.write_text(markdown(result, images=[p.name for p in images]), encoding="utf-8")
    return [md, *images]
