"""`laserpick bench --compare`: two result files compared attempt by attempt, on small
hand-made results (no simulator)."""

from __future__ import annotations

import copy
import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from laserpick.bench.compare import (
    AttemptKey,
    ResultFileError,
    ResultMismatch,
    compare_files,
    compare_results,
    format_comparison,
    load_result,
)
from laserpick.bench.results import environment


def _record(trial: int, task: int, instance: str, **fields: Any) -> dict[str, Any]:
    rec = {
        "trial": trial,
        "seed": 1 + trial,
        "instance": instance,
        "model": instance,
        "surface": "table",
        "selection": "auto",
        "strategy": "gpd",
        "task": task,
        "marks": 1,
        "places": 0,
        "detected": True,
        "grasped": True,
        "success": True,
        "failure": None,
        "message": "",
        "timings": {"plan": 0.05, "execute_sim": 23.391999999997637, "attempt_total": 23.5},
        "grip": [0.0707, 0.0698],
        "lever": 0.0056,
    }
    return rec | fields


def _result(records: list[dict[str, Any]], protocol: str = "in-situ") -> dict[str, Any]:
    return {
        "protocol": protocol,
        "seed": 1,
        "trials": 2,
        "options": {"selection": "auto", "strategy": "gpd", "scene": None, "tremor_deg": 0.3},
        "records": records,
        "errors": [],
    }


@pytest.fixture
def old() -> dict[str, Any]:
    failed = {"success": False, "grasped": False, "failure": "ik_plan", "message": "no way"}
    return _result(
        [
            _record(0, 1, "mug"),
            _record(0, 2, "soda_can", **failed),  # two tries at one task
            _record(0, 2, "soda_can"),
            _record(1, 1, "tv_remote"),
        ]
    )


def test_identical_results_show_no_difference(old: dict[str, Any]) -> None:
    comparison = compare_results(old, copy.deepcopy(old))
    assert comparison.same and comparison.attempts == 4
    text = format_comparison(comparison, "a.json", "b.json")
    assert text.rstrip().endswith("no difference: all 4 attempts match")


def test_a_changed_verdict_is_listed_with_its_fields(old: dict[str, Any]) -> None:
    new = copy.deepcopy(old)
    new["records"][2].update(success=False, failure="execute", message="slipped")
    comparison = compare_results(old, new)
    (diff,) = comparison.differences
    assert diff.key == AttemptKey(0, 2, "auto", 2)  # the task's second try
    assert [(c.name, c.old, c.new) for c in diff.changes] == [
        ("success", True, False),
        ("failure", None, "execute"),
    ]
    text = format_comparison(comparison, "a.json", "b.json")
    assert "trial 0, task 2, auto, try 2 (soda_can):" in text
    assert "success      yes -> no" in text and "new: slipped" in text
    assert text.rstrip().endswith("1 of 4 attempts differ.")


def test_a_missing_attempt_is_listed(old: dict[str, Any]) -> None:
    new = copy.deepcopy(old)
    del new["records"][3]
    comparison = compare_results(old, new)
    (diff,) = comparison.differences
    assert diff.key == AttemptKey(1, 1, "auto") and diff.new is None
    text = format_comparison(comparison, "a.json", "b.json")
    assert "trial 1, task 1, auto: only in the old run (tv_remote, success)" in text
    assert "1 of 4 attempts differ (1 in one run only)." in text


def test_floats_match_exactly_unless_a_tolerance_is_given(old: dict[str, Any]) -> None:
    new = copy.deepcopy(old)
    new["records"][0]["grip"][1] += 1e-9
    new["records"][1]["timings"]["execute_sim"] += 1e-6
    new["records"][3]["timings"]["plan"] = 9.0  # wall-clock time: not compared
    exact = compare_results(old, new)
    assert [[c.name for c in d.changes] for d in exact.differences] == [["grip"], ["execute_sim"]]
    assert compare_results(old, new, tolerance=1e-5).same
    assert not compare_results(old, new, tolerance=1e-7).same
    with pytest.raises(ValueError, match="tolerance"):
        compare_results(old, new, tolerance=-1.0)


def test_results_of_another_protocol_or_seed_are_refused(old: dict[str, Any]) -> None:
    with pytest.raises(ResultMismatch, match="protocol"):
        compare_results(old, _result(old["records"], protocol="isolation"))
    with pytest.raises(ResultMismatch, match="seed"):
        compare_results(old, {**old, "seed": 2})


def test_other_options_are_noted(old: dict[str, Any]) -> None:
    new = copy.deepcopy(old)
    new["options"]["tremor_deg"] = 0.5
    comparison = compare_results(old, new)
    assert comparison.same and comparison.notes == ("option tremor_deg differs: 0.3 -> 0.5",)


def test_another_cpu_model_is_noted(old: dict[str, Any]) -> None:
    """Attempts repeat on one CPU model: a comparison across two says so."""
    a = copy.deepcopy(old) | {"environment": {"cpu": "AMD EPYC"}}
    b = copy.deepcopy(old) | {"environment": {"cpu": "Intel(R) Xeon(R) Processor"}}
    notes = compare_results(a, b).notes
    assert any(n.startswith("CPU differs: AMD EPYC -> Intel") for n in notes), notes
    assert compare_results(a, copy.deepcopy(a)).notes == ()


def test_other_settings_are_noted(old: dict[str, Any]) -> None:
    """A run with a setting overridden makes other attempts: a comparison says which, and
    a result written before settings were recorded notes none."""
    quick = {"LASERPICK_MOTION__QUICKEN_PATHS": "true"}
    a = copy.deepcopy(old) | {"environment": {"settings": {}}}
    b = copy.deepcopy(old) | {"environment": {"settings": quick}}
    assert compare_results(a, b).notes == (
        "setting LASERPICK_MOTION__QUICKEN_PATHS differs: unset -> true",
    )
    assert compare_results(old, b).notes == ()


def test_a_result_records_the_settings_the_environment_overrode(monkeypatch) -> None:
    """The run's `LASERPICK_*` variables, a secret's name without its value."""
    monkeypatch.setenv("LASERPICK_MOTION__QUICKEN_PATHS", "true")
    monkeypatch.setenv("LASERPICK_OPERATOR_PASSWORD", "hunter2")
    recorded = environment()["settings"]
    assert recorded["LASERPICK_MOTION__QUICKEN_PATHS"] == "true"
    assert recorded["LASERPICK_OPERATOR_PASSWORD"] == "(set)"
    assert "hunter2" not in json.dumps(recorded)


def test_other_commits_are_noted_not_counted_as_differences(old: dict[str, Any]) -> None:
    """A comparison is for a change of code: another commit, an unclean tree or a result
    written before commits were recorded is a note, and the attempts still match."""
    a = old | {"commit": "a" * 40, "tree_clean": True}
    b = copy.deepcopy(old) | {"commit": "b" * 40, "tree_clean": False}
    comparison = compare_results(a, b)
    assert comparison.same
    assert comparison.notes == (
        f"commit differs: {'a' * 40} -> {'b' * 40}",
        "the new run's tree had uncommitted changes",
    )
    assert compare_results(old, a).notes == (f"commit differs: not recorded -> {'a' * 40}",)
    assert compare_results(a, copy.deepcopy(a)).notes == ()
    text = format_comparison(comparison, "a.json", "b.json")
    assert "note: commit differs" in text and "no difference: all 4 attempts match" in text


def test_unreadable_files_are_refused(tmp_path: Path) -> None:
    with pytest.raises(ResultFileError, match="cannot read"):
        load_result(tmp_path / "missing.json")
    broken = tmp_path / "broken.json"
    broken.write_text("{ not json")
    with pytest.raises(ResultFileError, match="not JSON"):
        load_result(broken)
    other = tmp_path / "other.json"
    other.write_text(json.dumps({"protocol": "isolation", "records": "none"}))
    with pytest.raises(ResultFileError, match="not a bench result"):
        compare_files(other, other)


def _cli(*args: str) -> subprocess.CompletedProcess:
    cmd = [sys.executable, "-m", "laserpick.cli", "bench", *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=120)


def test_the_command_exits_0_1_or_2(tmp_path: Path, old: dict[str, Any]) -> None:
    a, b, c = tmp_path / "a.json", tmp_path / "b.json", tmp_path / "c.json"
    a.write_text(json.dumps(old))
    changed = copy.deepcopy(old)
    changed["records"][0]["instance"] = "glass_cup"
    b.write_text(json.dumps(changed))
    c.write_text(json.dumps(_result(old["records"], protocol="isolation")))
    same = _cli("--compare", str(a), str(a))
    assert same.returncode == 0 and "no difference" in same.stdout
    differ = _cli("--compare", str(a), str(b))
    assert differ.returncode == 1, differ.stderr
    assert "instance     mug -> glass_cup" in differ.stdout
    mismatched = _cli("--compare", str(a), str(c))
    assert mismatched.returncode == 2 and "different protocols" in mismatched.stderr
    missing = _cli("--compare", str(a), str(tmp_path / "none.json"))
    assert missing.returncode == 2 and "cannot read" in missing.stderr
