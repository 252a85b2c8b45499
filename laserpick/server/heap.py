"""How glibc's malloc keeps the server's heap (Linux): few arenas, large blocks mapped apart,
and what the jobs freed given back to the system (the session's heap keeper says when).

The server's threads allocate the numpy arrays of captures, clouds and grasp candidates by
the hundred megabytes a job, and free them when it ends. glibc keeps what was freed:

- each thread that allocates under contention gets an arena of its own, up to eight per
  core, which keeps what it freed (`limit_malloc_arenas`; a soak grew 91 MB in 4 minutes
  with glibc's default, 26 MB in 5 with two arenas);
- a block of the mmap threshold or more gets pages of its own, unmapped when freed; glibc
  raises the threshold to the largest such block freed, up to 32 MiB, so after the first
  large array the arrays of every capture land in an arena (`fix_mmap_threshold`);
- an arena gives back only the free space at its top: the holes that freed arrays leave
  below a block still in use stay resident (`release_free_memory` gives their pages back).

Measured by `bench/soak.py` with the arenas capped alone: after 8 minutes the arenas held
258 MB free of 474 MB, and resident memory had grown by 151 MB since the warm-up.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools
import os
import sys

__all__ = [
    "MMAP_THRESHOLD",
    "SERVER_ARENAS",
    "fix_mmap_threshold",
    "limit_malloc_arenas",
    "release_free_memory",
]

#: Arenas for a server process: one for the threads that keep time, one for the rest.
SERVER_ARENAS = 2
#: Blocks of this many bytes or more are mapped apart (B). Smaller ones would have their pages
#: faulted in at every allocation: at 128 KiB, a capture and its fusion took 2 to 3 times as
#: long. From 4 MiB numpy asks for huge pages, so a large array's pages come cheap.
MMAP_THRESHOLD = 4 * 2**20
#: glibc's `mallopt` parameter numbers.
_M_MMAP_THRESHOLD = -3
_M_ARENA_MAX = -8


@functools.cache
def _glibc() -> ctypes.CDLL | None:
    """The C library when it is glibc (it has `malloc_trim`), else None."""
    if not sys.platform.startswith("linux"):
        return None
    name = ctypes.util.find_library("c")
    if name is None:
        return None
    try:
        libc = ctypes.CDLL(name)
    except OSError:
        return None
    # musl has neither mallopt nor malloc_trim.
    return libc if hasattr(libc, "mallopt") and hasattr(libc, "malloc_trim") else None


def _mallopt(param: int, value: int, env: str) -> bool:
    libc = _glibc()
    if libc is None or env in os.environ:
        return False
    return bool(libc.mallopt(param, value))


def limit_malloc_arenas(arenas: int = SERVER_ARENAS) -> bool:
    """Cap glibc's malloc arenas at `arenas`, unless `MALLOC_ARENA_MAX` already says how many.
    Call before the process starts its threads. Whether the cap was set (False off glibc)."""
    return _mallopt(_M_ARENA_MAX, arenas, "MALLOC_ARENA_MAX")


def fix_mmap_threshold(threshold: int = MMAP_THRESHOLD) -> bool:
    """Map blocks of `threshold` bytes or more apart, at that size for good (glibc no longer
    raises it), unless `MALLOC_MMAP_THRESHOLD_` already says where. Call before the first
    large allocation. Whether it was set (False off glibc)."""
    return _mallopt(_M_MMAP_THRESHOLD, threshold, "MALLOC_MMAP_THRESHOLD_")


def release_free_memory() -> bool:
    """Give the pages of every arena's free blocks back to the system (glibc's `malloc_trim`):
    after a job, what its arrays left free. Takes each arena's lock in turn. Whether any
    memory was given back (False off glibc)."""
    libc = _glibc()
    return libc is not None and bool(libc.malloc_trim(0))
