"""Rules of the codebase that a test can hold: ruff is clean, and the pipeline sees only what
a real robot's sensors see (it imports neither mujoco nor robot/)."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FORBIDDEN = ("mujoco", "laserpick.robot", "laserpick.bench", "mink")


def _imports(path: Path) -> list[str]:
    tree = ast.parse(path.read_text(), filename=str(path))
    names: list[str] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:  # relative: resolve against the package
                pkg = ".".join(path.relative_to(ROOT).with_suffix("").parts[: -node.level])
                names.append(f"{pkg}.{node.module}" if node.module else pkg)
            elif node.module:
                names.append(node.module)
    return names


def test_pipeline_imports_neither_mujoco_nor_robot():
    files = sorted((ROOT / "laserpick" / "pipeline").rglob("*.py"))
    assert files, "pipeline/ has no modules?"
    offenders = [
        f"{f.relative_to(ROOT)}: {name}"
        for f in files
        for name in _imports(f)
        if name == "mujoco" or name.startswith(FORBIDDEN)
    ]
    assert not offenders, "pipeline/ must not see the simulator or its truth:\n" + "\n".join(
        offenders
    )


def test_import_checker_catches_a_forbidden_import(tmp_path):
    # The rule above is only as good as its parser: prove it flags the forms that matter.
    bad = ROOT / "laserpick" / "pipeline" / "_probe_forbidden.py"
    bad.write_text("import mujoco\nfrom ..robot import sim\n")
    try:
        names = _imports(bad)
    finally:
        bad.unlink()
    assert "mujoco" in names and "laserpick.robot" in names


def test_ruff_is_clean():
    res = subprocess.run(
        [sys.executable, "-m", "ruff", "check", "--no-cache", str(ROOT)],
        capture_output=True,
        text=True,
    )
    assert res.returncode == 0, res.stdout + res.stderr
