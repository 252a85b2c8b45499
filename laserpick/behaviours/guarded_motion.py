"""Guarded motion: what every behaviour is built on. `GuardedMotion` holds the robot, the
settings, what the hand holds, and runs trajectories on the arm: it waits for the arm to
reach a trajectory's start, reads a protective stop, and backs the arm away after one.

A failed motion ends in a `Failure` with a sentence the user can read, never a bare
controller message."""

from __future__ import annotations

import functools
import logging
import time
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from laserpick.behaviours.ahead import Ahead
from laserpick.behaviours.hand import wait_for_gripper
from laserpick.behaviours.held import Held, WayIn
from laserpick.behaviours.outcome import SEARCH, Outcome
from laserpick.pipeline.collision import CollisionChecker
from laserpick.pipeline.joint_search import joint_path_via
from laserpick.pipeline.lines import cartesian_line
from laserpick.pipeline.motion_limits import timed
from laserpick.robot.interface import PROTECTIVE_STOP, Robot
from laserpick.settings import Settings, get_settings
from laserpick.types import Failure, Trajectory

__all__ = ["GuardedMotion", "nearest_on"]

log = logging.getLogger(__name__)


def nearest_on(path: np.ndarray, q: np.ndarray) -> int:
    """The index of the configuration of `path` (N, 6) rad nearest to q (6,), by the largest
    joint difference: where on a trajectory the arm stands."""
    return int(np.argmin(np.max(np.abs(path - q), axis=1)))


class GuardedMotion:
    """The arm's motions as the behaviours run them, one at a time from the caller's thread.

    progress: called with a short sentence at each step, for the console and logs.
    should_stop: polled before every motion; once it returns True (the operator cancelled,
    or the watchdog fired) no new motion starts and the behaviour ends with a failure.
    held: what the hand holds (None: nothing); way_in: how it came to hold it, while that
    way is known (every motion since the grasp ran to its end); ahead: a search started for
    the motion after the ones running (`Ahead`), taken up where the arm then stands at its
    start.
    """

    def __init__(
        self,
        robot: Robot,
        settings: Settings | None = None,
        rng: np.random.Generator | None = None,
        progress: Callable[[str], None] | None = None,
        should_stop: Callable[[], bool] | None = None,
    ) -> None:
        self.robot = robot
        self.should_stop = should_stop or (lambda: False)
        self.settings = settings or get_settings()
        self.rng = rng if rng is not None else np.random.default_rng(0)
        self.progress = progress or (lambda msg: log.info(msg))
        self.held: Held | None = None
        self.way_in: WayIn | None = None
        #: the search for what the arm does next, running while it finishes what it does now
        self.ahead: Ahead | None = None

    def current_q(self) -> np.ndarray:
        """The arm's joint angles now (6,) (rad)."""
        return self.robot.joint_state().q

    def run(self, traj: Trajectory, what: str) -> Failure | None:
        """Run `traj` to its end; None when it got there, else why not, in a sentence that
        names `what` the motion was doing. The arm first catches up with the start (a
        trajectory ends by its clock while the servos may still lag, and the controller
        refuses a start 0.05 rad off). A protective stop backs the arm away the way it came
        (`_retrace_after_stop`); a motion over its time is halted."""
        b = self.settings.behaviour
        if self.should_stop():
            return Failure("execute", f"Stopped before {what}: the motion was cancelled.")
        waited = 0.0
        while (
            np.max(np.abs(self.current_q() - traj.q[0])) > b.start_tolerance
            and waited < b.start_wait
        ):
            self.robot.sleep(0.05)
            waited += 0.05
        if np.max(np.abs(self.current_q() - traj.q[0])) > b.start_stuck:
            self.robot.halt()
            self.way_in = None
            return Failure(
                "execute",
                f"The arm stopped short of where {what} starts: it may be touching something.",
            )
        handle = self.robot.execute(traj)
        status = self.robot.wait(handle, traj.duration + b.motion_slack)
        if status == "done":
            if self.way_in is not None and self.held is not None:
                self.way_in = replace(self.way_in, driven=(*self.way_in.driven, traj.q))
            return None
        self.way_in = None  # stopped part way: the way back is no longer known
        if status == "running":
            self.robot.halt()  # not the latching e-stop: that one stays the user's
            return Failure("execute", f"The arm did not finish {what} in time; it was stopped.")
        if handle.message.startswith(PROTECTIVE_STOP):
            felt = handle.message.removeprefix(PROTECTIVE_STOP)
            done = "stopped and backed away" if self._retrace_after_stop(traj) else "stopped"
            return Failure("execute", f"The arm was pushed back while {what} ({felt}): {done}.")
        return Failure("execute", f"The arm stopped while {what}: {handle.message}.")

    def _retrace_after_stop(self, traj: Trajectory) -> bool:
        """After a protective stop on `traj`, go back the way it came to where it started:
        the arm was there a moment ago, so that way is clear, and the arm is then neither
        pressed against what it met nor left standing in the cameras' view (where it hides
        the next mark's object from them). Not when the user has cancelled: the arm then
        stays where it stopped. Holding something, it goes back at the carrying speed.
        Returns whether it got back."""
        if self.should_stop():
            return False
        b = self.settings.behaviour
        q = self.current_q()
        reached = nearest_on(traj.q, q)
        back = np.vstack([q, traj.q[reached::-1]])
        # Keep the turning points, about back_step apart: a trajectory is sampled densely.
        moved = np.concatenate([[0.0], np.cumsum(np.max(np.abs(np.diff(back, axis=0)), axis=1))])
        keep = np.flatnonzero(np.diff(np.floor(moved / b.back_step), prepend=-1) > 0)
        path = back[np.union1d(keep, [len(back) - 1])]
        if len(path) < 2 or np.max(np.abs(path[-1] - q)) < b.start_tolerance:
            return True
        s = self.settings.motion
        way_back = timed(path, s, carrying=self.held is not None)
        handle = self.robot.execute(way_back)
        return self.robot.wait(handle, way_back.duration + b.motion_slack) == "done"

    def searched_ahead(self, search: Callable, held: Held) -> tuple[Any, float]:
        """What the search ahead (`ahead`) found, where it was `search` for `held` among its
        surroundings and the arm stands at its start; else None. With the seconds (s) the
        arm stood still for it (`Ahead.result`). Taken either way: `ahead` is None after."""
        ahead, self.ahead = self.ahead, None
        tolerance = self.settings.behaviour.start_tolerance
        if ahead is None or not ahead.fits(
            (search, held, held.surroundings), self.current_q(), tolerance
        ):
            return None, 0.0
        return ahead.result()

    def go_to(
        self,
        q_goal: np.ndarray,
        checker: CollisionChecker,
        what: str,
        via: Sequence[np.ndarray] = (),
        **kw,
    ) -> Outcome:
        """A collision-free joint move to q_goal (6,) rad (`joint_path_via`, then `follow`).
        kw: passed to `joint_path` (`payload`, TCP frame: what the hand carries, which also
        holds the move to the carrying limits, `motion_limits`). The outcome's timings
        give the wall-clock seconds the search took (`SEARCH`)."""
        s, t0 = self.settings.motion, time.perf_counter()
        path = joint_path_via(self.current_q(), q_goal, checker, self.rng, s, via, **kw)
        searched = {SEARCH: time.perf_counter() - t0}
        if path is None:
            msg = f"No collision-free path was found for {what}."
            return Outcome(Failure("ik_plan", msg), timings=searched)
        return Outcome(self.follow(path, checker, what, **kw), timings=searched)

    def follow(
        self, path: np.ndarray, checker: CollisionChecker, what: str, **kw
    ) -> Failure | None:
        """Run the searched joint `path` (K, 6) rad (`run`), its corners blended where the
        check it was searched with (`checker`, kw) passes, within the carrying limits where
        kw has a `payload`."""
        carrying = kw.get("payload") is not None
        clear = functools.partial(checker.path_clear, **kw)  # the legs' search's own check
        return self.run(timed(path, self.settings.motion, carrying=carrying, clear=clear), what)

    def descend(
        self, path: np.ndarray, tcp_speed: float, what: str, *, felt: float = 0.0
    ) -> Failure | None:
        """Run the straight way down `path` (N, 6) at `tcp_speed` (m/s), guarded: where the
        hand or what it holds feels more than `place_contact_force` over the `felt` (N) it
        already bears at the start, it stops there, and the failure says what it met."""
        s = self.settings.motion
        down = timed(path, s, tcp_speed=tcp_speed)
        guard = s.place_contact_force + felt
        return self.run(down.guarded(guard), what)

    def rise_straight(self, T: np.ndarray, what: str) -> None:
        """Rise in a straight line to TCP pose T (4, 4, `base`) at the approach speed, if the
        arm can (no check for collisions: the way back up is the way it came down)."""
        s = self.settings.motion
        up = cartesian_line(self.current_q(), T, s.cartesian_step)
        if up is not None:
            self.run(timed(up, s, tcp_speed=s.approach_speed), what)

    def release(self) -> None:
        """Open the hand and give it the time to open: it holds nothing from here."""
        self.robot.gripper(False)
        wait_for_gripper(self.robot)
        self.held = None
        self.way_in = None
        self.ahead = None
