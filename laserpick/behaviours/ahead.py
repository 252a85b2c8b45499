"""Searching ahead: the search for a motion started on a thread while the arm still runs
the motions before it, from where they end. The arm then stands still only for the part of
the search that outlasts them.

That part is measured by the robot's clock (`JointState.stamp`): on hardware the wall clock,
in the stepped simulator its own, which runs several times faster than the wall clock. The
thread there gets less of the motion's time than on hardware, and its wall-clock time, slowed
by sharing the cores with the simulator, is charged in full: the wait is not undercounted.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Generic, TypeVar

import numpy as np

from laserpick.robot.interface import Robot

__all__ = ["Ahead"]

T = TypeVar("T")


class Ahead(Generic[T]):
    """One search running ahead of the arm, for the motion that starts at `start` (6,) rad,
    searched for `owners` (the search function and what it read: the held object and its
    surroundings; a use where any of them differs is refused)."""

    def __init__(
        self, robot: Robot, start: np.ndarray, owners: tuple[object, ...], search: Callable[[], T]
    ) -> None:
        self.start = np.array(start, float)
        self.owners = owners
        self._robot = robot
        self._since = robot.joint_state().stamp
        self._done = threading.Event()
        self._out: T | None = None
        self._error: BaseException | None = None
        self._wall = 0.0
        threading.Thread(target=self._run, args=(search,), name="search-ahead", daemon=True).start()

    def _run(self, search: Callable[[], T]) -> None:
        t0 = time.perf_counter()
        try:
            self._out = search()
        except BaseException as e:  # handed to the caller of `result`
            self._error = e
        finally:
            self._wall = time.perf_counter() - t0
            self._done.set()

    def fits(self, owners: tuple[object, ...], q: np.ndarray, tolerance: float) -> bool:
        """Whether this search was for these very `owners` and starts within `tolerance`
        (rad, each joint) of the arm's `q` (6,) rad."""
        same = len(owners) == len(self.owners) and all(
            a is b for a, b in zip(owners, self.owners, strict=True)
        )
        return same and float(np.max(np.abs(q - self.start))) <= tolerance

    def result(self) -> tuple[T, float]:
        """The search's result, once it is done, and how long (s) the arm stood still for it:
        the search's wall-clock time less the robot time since it started, at least 0. An
        exception the search raised is raised here."""
        self._done.wait()
        if self._error is not None:
            raise self._error
        moved = self._robot.joint_state().stamp - self._since
        return self._out, max(0.0, self._wall - moved)  # type: ignore[return-value]
