"""`laserpick serve` as a real subprocess, for the tests that talk to a live server."""

from __future__ import annotations

import os
import queue
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def free_port() -> int:
    """A TCP port that was free on 127.0.0.1 a moment ago."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def stop_process(proc: subprocess.Popen) -> None:
    """Terminate, then kill if it does not go within 10 s."""
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(5)


class ServeProcess:
    """`laserpick serve` on free (or given) ports with its journal in `tmp`; stdout is read
    by a thread, stderr goes to a file. `start()` waits for the ready line. host: its
    `--host` (None: not passed, so the server binds its default). `env` adds to this
    process's environment, or removes a variable given None."""

    def __init__(
        self,
        tmp: Path,
        *,
        scene: str = "isolation",
        host: str | None = "127.0.0.1",
        api_port: int | None = None,
        viser_port: int | None = None,
        env: dict[str, str | None] | None = None,
        extra_args: tuple[str, ...] = (),
    ) -> None:
        self.tmp = tmp
        self.api_port = api_port or free_port()
        self.viser_port = viser_port or free_port()
        self.journal = tmp / "journal.sqlite3"
        self.url = f"http://127.0.0.1:{self.api_port}"
        self.viser_url = f"http://127.0.0.1:{self.viser_port}"
        full_env = dict(os.environ)
        full_env.pop("LASERPICK_OPERATOR_PASSWORD", None)
        full_env["PYTHONPATH"] = str(REPO) + os.pathsep + full_env.get("PYTHONPATH", "")
        for name, value in (env or {}).items():
            if value is None:
                full_env.pop(name, None)
            else:
                full_env[name] = value
        self.stderr_path = tmp / "serve.stderr"
        self._stderr = self.stderr_path.open("w")
        self.proc = subprocess.Popen(
            [
                *[sys.executable, "-m", "laserpick.cli", "serve"],
                *(["--host", host] if host is not None else []),
                *["--port", str(self.api_port), "--viser-port", str(self.viser_port)],
                *["--scene", scene, "--journal", str(self.journal)],
                *extra_args,
            ],
            cwd=REPO,
            env=full_env,
            stdout=subprocess.PIPE,
            stderr=self._stderr,
            text=True,
        )
        self.lines: queue.Queue[str] = queue.Queue()
        self.output: list[str] = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.output.append(line)
            self.lines.put(line)

    def log(self) -> str:
        self._stderr.flush()
        return "".join(self.output) + "--- stderr ---\n" + self.stderr_path.read_text()[-4000:]

    def start(self, timeout: float = 90.0) -> ServeProcess:
        """Wait until the server says it is ready; self."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            try:
                line = self.lines.get(timeout=0.2)
            except queue.Empty:
                if self.proc.poll() is not None:
                    break
                continue
            if line.startswith("laserpick: console at "):
                return self
        raise AssertionError(f"`laserpick serve` never said 'console at':\n{self.log()}")

    def close(self) -> None:
        stop_process(self.proc)
        self._stderr.close()
