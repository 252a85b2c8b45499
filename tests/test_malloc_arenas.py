"""The server caps glibc's malloc arenas, unless the environment already does."""

from __future__ import annotations

import os
import subprocess
import sys

CODE = "from laserpick.cli.malloc_arenas import limit_malloc_arenas as f; print(f())"


def test_the_cap_is_set_on_glibc_and_left_to_the_environment_when_it_names_one() -> None:
    def run(env: dict[str, str]) -> str:
        out = subprocess.run([sys.executable, "-c", CODE], env=env, capture_output=True, text=True)
        assert out.returncode == 0, out.stderr
        return out.stdout.strip()

    base = {k: v for k, v in os.environ.items() if k != "MALLOC_ARENA_MAX"}
    assert run(base) == ("True" if sys.platform.startswith("linux") else "False")
    assert run({**base, "MALLOC_ARENA_MAX": "4"}) == "False"
