"""What a bench result records of the code it ran: the commit and whether the checkout was
clean (`results.source_revision`), on throwaway git checkouts (no simulator)."""

from __future__ import annotations

import subprocess
from pathlib import Path

from laserpick.bench.results import RESULTS_FOLDER, result, source_revision


def _git(root: Path, *args: str) -> str:
    env = ["-c", "user.name=bench", "-c", "user.email=bench@example.invalid"]
    done = subprocess.run(["git", *env, "-C", str(root), *args], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


def _checkout(root: Path) -> str:
    """A git checkout at `root` with one commit; returns the commit."""
    root.mkdir()
    _git(root, "init", "-q")
    (root / "code.py").write_text("x = 1\n")
    _git(root, "add", "code.py")
    _git(root, "commit", "-q", "-m", "code")
    return _git(root, "rev-parse", "HEAD")


def test_a_clean_checkout_records_its_commit(tmp_path: Path) -> None:
    root = tmp_path / "repo"
    commit = _checkout(root)
    assert source_revision(root) == {"commit": commit, "tree_clean": True}


def test_changes_make_the_tree_unclean_but_bench_results_do_not(tmp_path: Path) -> None:
    root = tmp_path / "repo"
    commit = _checkout(root)
    (root / RESULTS_FOLDER).mkdir()
    (root / RESULTS_FOLDER / "isolation.json").write_text("{}\n")
    assert source_revision(root) == {"commit": commit, "tree_clean": True}
    (root / "code.py").write_text("x = 2\n")
    assert source_revision(root) == {"commit": commit, "tree_clean": False}
    _git(root, "checkout", "-q", "code.py")
    (root / "new.py").write_text("y = 1\n")  # untracked code counts too
    assert source_revision(root) == {"commit": commit, "tree_clean": False}


def test_outside_a_checkout_the_commit_is_unknown(tmp_path: Path) -> None:
    assert source_revision(tmp_path) == {"commit": "unknown", "tree_clean": None}
    # A folder inside a checkout is not the checkout whose code runs (an installed copy in
    # a virtual environment kept inside some repository).
    root = tmp_path / "repo"
    _checkout(root)
    (root / "site-packages").mkdir()
    assert source_revision(root / "site-packages") == {"commit": "unknown", "tree_clean": None}


def test_a_result_records_the_commit_beside_the_version() -> None:
    out = result("isolation", 1, 1, [], {}, 0.0)
    assert out["commit"] == source_revision()["commit"]
    assert out["tree_clean"] in (True, False, None)
    keys = list(out)
    assert keys.index("commit") == keys.index("version") + 1
