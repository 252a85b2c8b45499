"""The server's heap (`laserpick.server.heap`): arenas capped, large blocks mapped apart, and
the holes freed arrays left given back on release."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
GLIBC = sys.platform.startswith("linux")
#: The environment without glibc's own malloc settings.
CLEAN_ENV = {k: v for k, v in os.environ.items() if not k.startswith("MALLOC_")}


def run(code: str, env: dict[str, str] | None = None) -> list[str]:
    """Run `code` in a fresh interpreter; its printed lines."""
    out = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        env=env or CLEAN_ENV,
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    return out.stdout.split()


def test_the_settings_are_made_on_glibc_and_left_to_the_environment_when_it_names_them() -> None:
    code = """
        from laserpick.server.heap import fix_mmap_threshold, limit_malloc_arenas
        print(limit_malloc_arenas(), fix_mmap_threshold())
    """
    assert run(code) == [str(GLIBC)] * 2
    env = {**CLEAN_ENV, "MALLOC_ARENA_MAX": "4", "MALLOC_MMAP_THRESHOLD_": "131072"}
    assert run(code, env) == ["False", "False"]


#: Prints how much resident memory (MB) 16 arrays of SIZE bytes, each followed by a small
#: block that stays, still hold once the arrays are freed; then again after
#: `release_free_memory`. A thread does the work, as the server's threads do, so the arrays
#: land in an arena of its own whatever the interpreter's start left in the main heap. A
#: 16 MiB array freed first raises glibc's own threshold above SIZE.
HOLES = """
    import threading
    import numpy as np
    from laserpick.server.heap import fix_mmap_threshold, release_free_memory

    def rss():
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * 4096 / 2**20

    def holes():
        np.ones(16 << 20, np.uint8)
        before, kept, arrays = rss(), [], []
        for _ in range(16):
            arrays.append(np.ones({size}, np.uint8))
            kept.append(bytearray(4096))
        del arrays
        print(round(rss() - before))
        release_free_memory()
        print(round(rss() - before))

    if {fixed}:
        fix_mmap_threshold()
    worker = threading.Thread(target=holes)
    worker.start()
    worker.join()
"""


@pytest.mark.skipif(not GLIBC, reason="glibc's malloc")
def test_arrays_from_the_threshold_up_are_given_back_as_they_are_freed() -> None:
    """16 arrays of 6 MiB, freed: mapped apart, they leave nothing resident. Left to glibc,
    whose threshold rose past them, they stay in the arena, held below the small blocks."""
    size = 6 << 20
    assert float(run(HOLES.format(fixed=True, size=size))[0]) < 10
    assert float(run(HOLES.format(fixed=False, size=size))[0]) > 60


@pytest.mark.skipif(not GLIBC, reason="glibc's malloc")
def test_what_arrays_below_the_threshold_left_free_is_given_back_on_release() -> None:
    """16 arrays of 3 MiB, under the threshold, leave their holes resident until
    `release_free_memory` gives the holes' pages back."""
    held, released = map(float, run(HOLES.format(fixed=True, size=3 << 20)))
    assert held > 30
    assert released < 10
