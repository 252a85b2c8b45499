"""How late the API's event loop runs: a task that asks to wake every `PERIOD` and records
how much later than asked it woke. A late wake-up is time no socket was read, so no
heartbeat could arrive: the dead-man's 0.5 s depends on it staying small.

Times are `loop.time()` seconds (asyncio's clock, `time.monotonic()`); lags are reported in
ms.
"""

from __future__ import annotations

import asyncio
import math
import time
from collections import deque

import numpy as np

__all__ = ["PERIOD", "LoopLag"]

#: How often the probe asks to wake (s).
PERIOD = 0.01
#: Wake-ups kept for the percentiles: the last 10 minutes at `PERIOD`.
_KEPT = 60_000


class LoopLag:
    """The probe and its record: `stats(window)` summarises the wake-ups of the last
    `window` seconds (all that are kept when None)."""

    def __init__(self) -> None:
        self._woke: deque[tuple[float, float]] = deque(maxlen=_KEPT)  #: (loop time, lag s)

    async def run(self) -> None:
        loop = asyncio.get_running_loop()
        while True:
            asked = loop.time() + PERIOD
            await asyncio.sleep(PERIOD)
            now = loop.time()
            self._woke.append((now, max(0.0, now - asked)))

    def stats(self, window: float | None = None) -> dict[str, float | int]:
        """How many wake-ups, and their p50, p99 and largest lag (ms)."""
        since = -math.inf if window is None else time.monotonic() - window
        lags = np.array([lag for t, lag in list(self._woke) if t >= since]) * 1e3
        if lags.size == 0:
            return {"samples": 0, "p50_ms": 0.0, "p99_ms": 0.0, "max_ms": 0.0}
        p50, p99 = np.percentile(lags, [50, 99])
        return {
            "samples": int(lags.size),
            "p50_ms": round(float(p50), 2),
            "p99_ms": round(float(p99), 2),
            "max_ms": round(float(lags.max()), 2),
        }
