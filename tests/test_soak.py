"""The soak script (`bench/soak.py`) on a real `laserpick serve` for half a minute: it writes
every figure, the server answers no request with a 5xx, the journal holds a row for every
command that makes one, and the second client is always refused. The figures that measure
speed (real-time factor, lag, memory growth) are the long run's to judge, not this. A
half-minute soak with its server's start is about 50 s: it runs with `make test-slow`."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]

pytestmark = [pytest.mark.slow, pytest.mark.timeout(420)]


def test_a_short_soak_reports_every_figure_without_a_5xx_or_a_lost_row(tmp_path: Path) -> None:
    out = tmp_path / "soak.json"
    done = subprocess.run(
        [sys.executable, str(REPO / "bench" / "soak.py"), "--minutes", "0.5", "--out", str(out)],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=400,
    )
    assert done.returncode in (0, 1), done.stdout + done.stderr  # 1: a speed target missed
    f = json.loads(out.read_text())
    for figure in (f["rtf"]["min"], f["rtf"]["mean"], *f["memory_mb"].values()):
        assert math.isfinite(figure), f
    assert f["rtf"]["samples"] >= 5
    assert f["loop_lag_ms"]["minutes"] and math.isfinite(f["loop_lag_ms"]["p99_worst_minute"])
    assert f["server_errors"]["count"] == 0, f["server_errors"]
    journal = f["journal"]
    assert journal["commands_journaled"] > 0 and journal["rows_expected"] > 0
    assert journal["lost"] == 0, journal["lost_by_action"]
    assert journal["rows_recorded"] >= journal["rows_expected"]
    intruder = f["second_client"]
    assert intruder["tries"] > 0 and intruder["refused"] == intruder["tries"], intruder
    assert f["watchers"]["watchers"] == 20 and f["watchers"]["state_frames"] > 0
    assert set(f["targets"]) >= {"no 5xx", "no lost journal row", "memory growth (MB)"}
    assert "soak " in done.stdout and "target" in done.stdout
