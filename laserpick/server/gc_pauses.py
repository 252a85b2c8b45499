"""How long Python's cyclic garbage collector stops the process: every thread waits while it
runs, the watchdog and the event loop that reads the heartbeats included.

Times are `time.perf_counter()` seconds; pauses are reported in ms.
"""

from __future__ import annotations

import gc
import time
from collections import deque
from typing import Any

__all__ = ["GcPauses"]

#: Collections kept for the report.
_KEPT = 10_000


class GcPauses:
    """Times every collection from the moment `start()` hooks into `gc.callbacks`."""

    def __init__(self) -> None:
        self._began: float | None = None
        self._pauses: deque[tuple[float, int, float]] = deque(maxlen=_KEPT)  #: (end, gen, s)

    def start(self) -> None:
        if self._on_gc not in gc.callbacks:
            gc.callbacks.append(self._on_gc)

    def stop(self) -> None:
        if self._on_gc in gc.callbacks:
            gc.callbacks.remove(self._on_gc)

    def _on_gc(self, phase: str, info: dict[str, Any]) -> None:
        now = time.perf_counter()
        if phase == "start":
            self._began = now
        elif self._began is not None:
            self._pauses.append((now, int(info.get("generation", -1)), now - self._began))
            self._began = None

    def stats(self, window: float | None = None) -> dict[str, float | int]:
        """Collections in the last `window` s (all kept when None): how many, how many of the
        oldest generation, and the longest pause (ms)."""
        since = -float("inf") if window is None else time.perf_counter() - window
        kept = [(g, s) for t, g, s in list(self._pauses) if t >= since]
        return {
            "collections": len(kept),
            "full_collections": sum(1 for g, _ in kept if g == 2),
            "longest_ms": round(max((s for _, s in kept), default=0.0) * 1e3, 2),
        }
