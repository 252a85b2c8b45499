"""How many malloc arenas the server's threads share (glibc on Linux).

glibc gives each thread that allocates under contention an arena of its own, up to eight per
core, and keeps there what the numpy arrays of captures, clouds and frames freed: the
server's resident memory then climbs as threads take turns. Measured by `bench/soak.py`:
+91 MB in 4 minutes with glibc's default, +26 MB in 5 minutes with two arenas, the event
loop's lag and the real-time factor within their targets in both.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import sys

__all__ = ["SERVER_ARENAS", "limit_malloc_arenas"]

#: Arenas for a server process: one for the threads that keep time, one for the rest.
SERVER_ARENAS = 2
#: glibc's `mallopt` parameter number for the arena limit.
_M_ARENA_MAX = -8


def limit_malloc_arenas(arenas: int = SERVER_ARENAS) -> bool:
    """Cap glibc's malloc arenas at `arenas`, unless `MALLOC_ARENA_MAX` already says how many.
    Call before the process starts its threads. Whether the cap was set (False off glibc)."""
    if not sys.platform.startswith("linux") or "MALLOC_ARENA_MAX" in os.environ:
        return False
    name = ctypes.util.find_library("c")
    if name is None:
        return False
    try:
        libc = ctypes.CDLL(name)
        return bool(libc.mallopt(_M_ARENA_MAX, arenas))
    except (OSError, AttributeError):  # not glibc: musl has no mallopt
        return False
