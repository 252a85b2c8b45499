"""Each example in examples/ runs as a newcomer would run it, in a process of its own."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from serve_process import REPO, ServeProcess

from laserpick.robot.recording import read_recording

pytestmark = pytest.mark.timeout(420)

EXAMPLES = REPO / "examples"


def run_example(name: str, *args: str, timeout: float = 300) -> str:
    """Run examples/`name` with `args`; its stdout. Fails with its output if it fails."""
    env = dict(os.environ)
    env["PYTHONPATH"] = str(REPO) + os.pathsep + env.get("PYTHONPATH", "")
    res = subprocess.run(
        [sys.executable, str(EXAMPLES / name), *args],
        cwd=REPO,
        env=env,
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    assert res.returncode == 0, f"{name} failed:\n{res.stdout}\n{res.stderr[-4000:]}"
    return res.stdout


def test_every_example_says_what_it_shows_and_how_to_run_it():
    scripts = sorted(EXAMPLES.glob("*.py"))
    assert [p.name[:3] for p in scripts] == ["01_", "02_", "03_"]
    for path in scripts:
        text = path.read_text()
        assert text.startswith('"""'), path.name
        assert f"python examples/{path.name}" in text, f"{path.name}: say how to run it"


def test_01_a_rest_client_fetches_an_object(tmp_path: Path):
    server = ServeProcess(tmp_path).start()
    try:
        out = run_example("01_rest_client.py", "--url", server.url, "--object", "mug_1")
    finally:
        server.close()
    assert "aiming at mug_1" in out
    assert "grasps_ready: Grasps ready" in out
    assert re.search(r"^idle: Dropped in the basket", out, re.MULTILINE), out


def test_02_perceives_one_recorded_capture(isolation_recording: Path):
    # `laserpick record DIR --scene isolation --aim-at-object mug_1`, made once (conftest)
    out = run_example("02_perceive_one_capture.py", str(isolation_recording))
    assert "(laser, seen by" in out
    assert re.search(r"^grasp 0: cluster 0, TCP at", out, re.MULTILINE), out


def test_03_loads_a_scene_with_its_own_mesh(tmp_path: Path):
    out = run_example(
        "03_own_meshes_scene.py",
        "--dir",
        str(tmp_path / "scene"),
        "--record",
        str(tmp_path / "rec"),
    )
    seen = re.search(r"^my_block: rests at .* m in base, (\d+) cloud points on it", out, re.M)
    assert seen and int(seen.group(1)) > 200, out
    assert (tmp_path / "scene" / "hex_block_mm.stl").is_file()
    assert len(read_recording(tmp_path / "rec").captures[0].frames) == 5
