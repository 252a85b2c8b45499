"""The benchmark runner: protocols reproducible by seed in this process, in worker processes
and on Ray, the `laserpick bench` command's files, and the result's summary."""

from __future__ import annotations

import dataclasses
import json
import platform
import subprocess
import sys
import time
from pathlib import Path

import mujoco
import numpy as np
import pytest
from PIL import Image

from laserpick.bench import PROTOCOL_NAMES
from laserpick.bench.protocols import PROTOCOLS, Options
from laserpick.bench.report import markdown
from laserpick.bench.results import RESULT_PACKAGES, environment, outcomes, summarize
from laserpick.bench.runner import run
from laserpick.description import dims

DATA = Path(__file__).parent / "data"


def test_the_command_line_knows_every_protocol() -> None:
    assert tuple(PROTOCOLS) == PROTOCOL_NAMES


def test_a_trial_that_breaks_off_is_reported_not_lost(monkeypatch) -> None:
    """An exception in one trial is named with its seed; the other trials' records stay."""

    def flaky(trial: int, seed: int, opt: Options) -> list:
        if trial == 1:
            raise RuntimeError("simulated breakage")
        return []

    spec = PROTOCOLS["isolation"]
    monkeypatch.setitem(PROTOCOLS, "isolation", dataclasses.replace(spec, run=flaky))
    out = run("isolation", trials=3, seed=10, workers=1)
    assert len(out["errors"]) == 1
    assert "trial 1 (seed 11)" in out["errors"][0] and "simulated breakage" in out["errors"][0]
    assert "broke off" in markdown(out)


PARENT_OF_A_POOL = """
import os, sys, time
from laserpick.bench.runner import worker_pool
pool = worker_pool(1)
print(pool.submit(os.getpid).result(), flush=True)
time.sleep(60)
"""


def test_workers_end_when_the_bench_is_killed() -> None:
    """A bench killed with SIGKILL cannot end its pool; its worker must notice and end itself."""
    parent = subprocess.Popen(
        [sys.executable, "-c", PARENT_OF_A_POOL], stdout=subprocess.PIPE, text=True
    )
    try:
        worker = int(parent.stdout.readline())
        assert _running(worker)
    finally:
        parent.kill()
        parent.wait()
    deadline = time.monotonic() + 10.0
    while _running(worker) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not _running(worker), "the orphaned worker is still running"


def _running(pid: int) -> bool:
    """Whether process `pid` exists and is not a zombie waiting to be reaped."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except FileNotFoundError:
        return False
    return "\nState:\tZ" not in status


def test_a_run_replays_the_same_in_workers_and_on_ray() -> None:
    """Two selection trials (auto and manual on the same pair each): in this process, in two
    spawned worker processes, and on a local Ray instance. The verdicts must agree. The
    second trial alone (`--seed 4 --trials 1`) replays it: a trial's number is only a label
    (docs/bench.md, "Replaying one trial")."""
    import ray

    options = Options(selection="auto", strategy="gpd")
    inline = run("selection", trials=2, seed=3, options=options, workers=1)
    pooled = run("selection", trials=2, seed=3, options=options, workers=2)
    alone = run("selection", trials=1, seed=4, options=options, workers=1)
    try:
        ray.init(address="local", num_cpus=2, include_dashboard=False, log_to_driver=False)
        on_ray = run("selection", trials=2, seed=3, options=options, ray_address="auto")
    finally:
        ray.shutdown()
    assert inline["attempts"] == 4
    assert {r["selection"] for r in inline["records"]} == {"auto", "manual"}
    assert set(inline["modes"]) == {"auto", "manual"}
    assert outcomes(pooled) == outcomes(inline)
    assert outcomes(on_ray) == outcomes(inline)
    second = [o[1:] for o in outcomes(inline) if o[0] == 1]
    assert second and [o[1:] for o in outcomes(alone)] == second
    assert on_ray["options"]["ray"] == "auto"
    for r in inline["records"]:  # each attempt was timed, stage by stage
        if r["failure"] not in ("detect_laser", "precondition", "detect_grasp"):
            assert r["timings"]["plan"] > 0
            assert r["timings"]["attempt_total"] >= r["timings"]["plan"]
        if r["success"]:  # the wait for the way to the basket, the object in the hand:
            assert r["timings"]["plan_carry"] >= 0  # none where found while it lifted
        if r["grasped"]:  # a lifted object: the width planned and the gap closed to, in m
            planned, closed = r["grip"]
            assert 0 < planned <= dims.GRIPPER_STROKE and closed > dims.GRIPPER_EMPTY_GAP


def test_bench_command_on_a_user_mesh_scene(tmp_path: Path) -> None:
    """`laserpick bench --scene` with OBJ and STL models: the JSON holds the schema's fields
    and the attempts on the scene's objects, and the report and plots are written."""
    out = tmp_path / "user.json"
    cmd = [sys.executable, "-m", "laserpick.cli", "bench", "--protocol", "isolation"]
    cmd += ["--trials", "1", "--objects", "2", "--scene", str(DATA / "user_scene.yaml")]
    cmd += ["--out", str(out), "--workers", "1"]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    result = json.loads(out.read_text())
    for key in ("protocol", "seed", "trials", "attempts", "grasp_success_rate"):
        assert key in result
    assert set(result["failures"]) == {
        "detect_laser",
        "precondition",
        "detect_grasp",
        "ik_plan",
        "wrong_object",
        "execute",
    }
    assert result["attempts"] == len(result["records"]) == 2
    assert result["options"]["scene"].endswith("user_scene.yaml")
    scene_models = {"block", "hex_can", "soda_can"}
    assert {r["model"] for r in result["records"]} <= scene_models
    assert sum(result["failures"].values()) == sum(not r["success"] for r in result["records"])
    assert set(result["timings_s"]) >= {"acquire_cloud", "detect_laser", "attempt_total"}
    # The packages the outcomes depend on, as the run found them installed.
    env = result["environment"]
    assert env["packages"]["mujoco"] == mujoco.__version__
    assert env["packages"]["numpy"] == np.__version__
    assert env["python"] == platform.python_version() and env["cpu"]
    report = out.with_suffix(".md").read_text()
    assert "isolation" in report and "93.8" in report  # ours beside 004's figure
    assert f"mujoco {mujoco.__version__}" in report
    pngs = sorted(tmp_path.glob("user*.png"))
    assert len(pngs) == 2
    for png in pngs:
        with Image.open(png) as im:
            assert im.width >= 600 and len(im.getcolors(1 << 20) or []) > 2
    assert "isolation" in done.stderr  # the progress bar


def test_the_packages_a_result_records_are_the_ones_bootstrap_pins() -> None:
    """constraints.txt pins each package a bench result records, exactly, and `make
    bootstrap` installed those versions: the figures replay in this environment."""
    pins = {}
    for line in (Path(__file__).parents[1] / "constraints.txt").read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            name, version = line.split("==")
            pins[name.strip()] = version.strip()
    assert sorted(pins) == sorted(RESULT_PACKAGES)
    assert environment()["packages"] == pins


def test_bench_command_refuses_a_broken_scene(tmp_path: Path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: bad\nsurfaces: [{name: t, kind: table}]\n")
    cmd = [sys.executable, "-m", "laserpick.cli", "bench", "--protocol", "isolation"]
    done = subprocess.run(cmd + ["--scene", str(bad)], capture_output=True, text=True)
    assert done.returncode == 2
    assert "bad.yaml" in done.stderr and "surfaces" in done.stderr
    assert not (tmp_path / "bench-results").exists()


def test_retries_at_one_object_count_as_one_task() -> None:
    """In-situ tries until the object is fetched: two failed tries and a success are one
    task done, and three attempts of which one succeeded."""

    def rec(task: int, success: bool, failure: str | None) -> dict:
        return {
            "trial": 0,
            "task": task,
            "selection": "auto",
            "model": "mug",
            "detected": failure != "wrong_object",
            "grasped": success,
            "success": success,
            "failure": failure,
            "timings": {"plan": 0.1, "attempt_total": 1.0},
        }

    records = [rec(1, False, "ik_plan"), rec(1, False, "execute"), rec(1, True, None)]
    records += [rec(2, False, "wrong_object")]
    s = summarize(records)
    assert s["attempts"] == 4 and s["tasks"] == 2
    assert s["task_success_rate"] == pytest.approx(0.5)
    assert s["detect_success_rate"] == pytest.approx(0.75)
    assert s["grasp_success_rate"] == pytest.approx(1 / 3)
    assert s["failures"]["ik_plan"] == 1 and s["failures"]["wrong_object"] == 1
    assert s["objects"]["mug"]["task_success"] == 1
