"""What an adapter tells its user: every line on stdout with the time since the adapter
started at which it happened (s, monotonic clock, which the runner shares), and, with
`--speak`, the short spoken form through espeak-ng.

    [    3.000] highlight laser.up
    [    3.412] lost the server at http://127.0.0.1:8000: connection refused

Thread-safe: the input loop and the connection thread both announce.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from typing import TextIO

SPEAKER = "espeak-ng"
SPEECH_RATE = 170  #: words per minute


class Announcer:
    """Prints (and optionally speaks) announcements. clock: monotonic seconds; out: where lines
    go (default stdout); speak: say the spoken form through `espeak-ng` when it is installed
    (a newer announcement cuts an unfinished one short)."""

    def __init__(
        self,
        *,
        clock: Callable[[], float] = time.monotonic,
        out: TextIO | None = None,
        speak: bool = False,
        which: Callable[[str], str | None] = shutil.which,
        popen: Callable[..., subprocess.Popen] = subprocess.Popen,
    ) -> None:
        self.clock = clock
        self.t0 = clock()
        self.out = out
        self._lock = threading.Lock()
        self._popen = popen
        self._speech: subprocess.Popen | None = None
        self._speaker = which(SPEAKER) if speak else None
        if speak and self._speaker is None:
            self.note(f"{SPEAKER} is not installed: announcing on stdout only")

    def note(self, text: str, at: float | None = None) -> None:
        """A line on stdout only (connection news, refusals), stamped `at` (s on `clock`;
        default now)."""
        with self._lock:
            stream = self.out or sys.stdout
            t = self.clock() if at is None else at
            print(f"[{t - self.t0:9.3f}] {text}", file=stream, flush=True)

    def say(self, text: str, spoken: str | None = None, at: float | None = None) -> None:
        """A line on stdout, and `spoken` (default the text) through speech when enabled.

        `at` (s on `clock`; default now): when what it announces happened. A scan step is
        stamped with the time it was due, so the log keeps the schedule when a loaded
        machine prints the line late (84 ms once, under the full test suite).
        """
        self.note(text, at)
        if self._speaker is not None:
            self._speak(spoken or text)

    def _speak(self, words: str) -> None:
        with self._lock:
            if self._speech is not None and self._speech.poll() is None:
                self._speech.terminate()
            try:
                self._speech = self._popen(
                    [self._speaker, "-s", str(SPEECH_RATE), words],
                    stdin=subprocess.DEVNULL,
                    stdout=subprocess.DEVNULL,
                    stderr=subprocess.DEVNULL,
                )
            except OSError:
                self._speaker = None  # gone since start-up: keep to stdout

    def close(self) -> None:
        with self._lock:
            if self._speech is not None and self._speech.poll() is None:
                try:
                    self._speech.wait(2.0)
                except subprocess.TimeoutExpired:
                    self._speech.terminate()
