"""`laserpick bench --families`: lost attempts of a sweep of seeds grouped by family, on small
hand-made results (no simulator)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

from laserpick.bench.families import family_of, format_sweep, load_sweep, surface_kind

NO_POSTURE = "The arm cannot take any of {n} grasps (every arm posture for this grasp collides)."
UNSEEN = "None of the 2 grasps could be planned (no way). Park about 20 cm farther to your right."
GLASS = "I see no object at the mark, only the surface: a clear glass does not show."


def _record(trial: int, task: int, instance: str, message: str = "", **fields: Any) -> dict:
    lost = bool(message)
    rec = {
        "trial": trial,
        "instance": instance,
        "model": instance.rsplit("_", 1)[0] if instance[-1].isdigit() else instance,
        "surface": "bookshelf_2 -> table_73",
        "selection": "auto",
        "task": task,
        "success": not lost,
        "failure": "ik_plan" if lost else None,
        "message": message,
    }
    return rec | fields


def _write(path: Path, seed: int, records: list[dict]) -> Path:
    path.write_text(json.dumps({"protocol": "pick-place", "seed": seed, "records": records}))
    return path


def test_losses_that_differ_only_in_numbers_and_names_are_one_family(tmp_path: Path) -> None:
    a = _write(
        tmp_path / "a.json",
        100,
        [
            _record(0, 1, "spice_jar", NO_POSTURE.format(n=3)),  # first try lost...
            _record(0, 1, "spice_jar"),  # ...recovered by the second
            _record(0, 2, "glass_cup", GLASS, failure="precondition", surface="counter"),
            _record(0, 3, "mug", backed_up=0.1),  # done after backing up as asked
        ],
    )
    b = _write(
        tmp_path / "b.json",
        200,
        [
            _record(0, 1, "pill_bottle", NO_POSTURE.format(n=12)),  # lost for good
            _record(0, 2, "mug"),
            _record(0, 3, "juice_bottle", UNSEEN, parked_aside=-0.2),  # lost after re-parking
            _record(0, 3, "juice_bottle"),  # done at the second try
        ],
    )
    sweep = load_sweep([a, b])
    families = sweep.families()
    posture = families[0]
    assert posture.key == family_of(sweep.tasks[("pick-place seed 200", 0, "auto", 1)][0])
    assert posture.key.surface == "bookshelf" and "any of N grasps" in posture.key.sentence
    assert (posture.attempts, posture.tasks_lost, posture.recovered) == (2, 1, 1)
    assert [f.key.kind for f in families] == ["ik_plan", "precondition", "ik_plan"]
    assert sweep.task_rates() == (6, 4, 2)  # 6 tasks, 4 done, 2 at the first try
    assert sweep.task_rates(["glass_cup"]) == (5, 4, 2)
    text = format_sweep(sweep, ["glass_cup"])
    assert "| without glass_cup | 5 | 4 (80.0 %) | 2 (40.0 %) |" in text
    assert sweep.moved_as_asked("backed_up") == (1, 1)
    assert sweep.moved_as_asked("parked_aside") == (1, 0)
    assert "backed up as the robot asked, before the arm moved: 1 (1 of them done)" in text
    assert "parked to a side as it asked, for its cameras to see the way: 1 (0 of them" in text


def test_a_surface_kind_drops_its_number() -> None:
    assert surface_kind("table_73 -> floor_area") == "table"
    assert surface_kind("floor_area") == "floor"
    assert surface_kind("high_table") == "high_table"


def test_the_command_reads_result_files_and_refuses_others(tmp_path: Path) -> None:
    good = _write(tmp_path / "a.json", 1, [_record(0, 1, "mug", NO_POSTURE.format(n=2))])
    cmd = [sys.executable, "-m", "laserpick.cli", "bench", "--families", str(good)]
    ran = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert ran.returncode == 0, ran.stderr
    assert "| ik_plan | The arm cannot take any of N grasps" in ran.stdout
    ran = subprocess.run([*cmd, str(tmp_path / "none.json")], capture_output=True, text=True)
    assert ran.returncode == 2 and "cannot read" in ran.stderr
