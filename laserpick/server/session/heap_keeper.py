"""Giving back what the jobs left free, only while the robot is at rest.

A job's arrays (captures, clouds, grasp candidates) leave holes in glibc's arenas that stay
resident until `server.heap.release_free_memory` gives their pages back. That call takes
each arena's lock in turn, and the simulation's control loop allocates from the same
arenas. So the release runs only while no job runs (jobs alone move the gripper) and the
arm and the base are still: no halt ever waits on it. A motion commanded during the release
may start as much later as the release takes.

Times are `time.monotonic()` seconds.
"""

from __future__ import annotations

import logging
import threading
import time

import numpy as np

from laserpick.robot.interface import RobotState
from laserpick.server.heap import release_free_memory
from laserpick.server.session.core import SessionCore

log = logging.getLogger(__name__)

#: How often the keeper looks whether the robot is at rest (s).
HEAP_TICK = 0.25
#: At rest: every joint slower than this (rad/s), and the base too (m/s and rad/s).
REST_SPEED = 1e-3
#: Also give back this often (s) without a job ending: the state frames of many watchers
#: free arrays too.
HEAP_PERIOD = 60.0


def at_rest(state: RobotState) -> bool:
    """Whether nothing of the robot moves in `state`: no arm motion in progress, every joint
    and the base below `REST_SPEED`."""
    if state.moving:
        return False
    joints = np.abs(np.asarray(state.joints.qd, dtype=float))
    base = np.abs(np.asarray(state.base_velocity, dtype=float))
    return bool(joints.max(initial=0.0) < REST_SPEED and base.max(initial=0.0) < REST_SPEED)


class HeapKeeper(SessionCore):
    """The thread that gives freed memory back to the system while the robot is at rest."""

    def _start_heap_keeper(self) -> None:
        """Start the keeper on a robot in real time (a bench steps its simulation on the
        caller's thread, which the keeper must not read across); it ends when `_closing` is
        set (after `_start_watchdog`)."""
        self._heap_keeper: threading.Thread | None = None
        if not self.robot.realtime:
            return
        self._heap_keeper = threading.Thread(
            target=self._keep_heap, name="laserpick-heap", daemon=True
        )
        self._heap_keeper.start()

    def _stop_heap_keeper(self) -> None:
        if self._heap_keeper is not None:
            self._heap_keeper.join(timeout=1.0)

    def _keep_heap(self) -> None:
        last = time.monotonic()
        while not self._closing.wait(HEAP_TICK):
            due = self._job_freed.is_set() or time.monotonic() - last > HEAP_PERIOD
            if not due or self.busy:
                continue
            try:
                still = at_rest(self.robot.state())
            except Exception:  # a robot being replaced or closed: try again next tick
                log.debug("no robot state for the heap keeper", exc_info=True)
                continue
            if still:
                self._job_freed.clear()
                t0 = time.perf_counter()
                release_free_memory()
                last = time.monotonic()
                log.debug("gave the free heap back in %.1f ms", 1e3 * (time.perf_counter() - t0))
