"""What every part of the session shares: the robot, the task state and its findings, events
and the journal, the guards on commands, and the worker thread that runs the jobs.

Long work (perception, grasp detection, every arm motion) runs on one worker thread, so no
caller waits on it and the API stays responsive.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from laserpick.behaviours import Behaviours
from laserpick.pipeline.grasp_choice import GraspSet
from laserpick.pipeline.perceive import Perception
from laserpick.pipeline.selection import GraspCursor
from laserpick.robot.interface import Robot
from laserpick.server.journal import Journal
from laserpick.server.lease import ControlLease
from laserpick.server.session.states import (
    Actor,
    Conflict,
    Mode,
    Selection,
    StrategyName,
    TaskState,
    check_transition,
)
from laserpick.settings import Settings
from laserpick.types import Failure, Projector

if TYPE_CHECKING:
    from laserpick.pipeline.recall import ViewMemory
    from laserpick.server.session.captures import Capture
    from laserpick.server.session.foresight import Foreseen

log = logging.getLogger(__name__)


@dataclass
class Findings:
    """What the current task has found so far: the perception, the grasps and the cursor
    over them, the place mark (m, `base`), and the seconds each stage took."""

    perception: Perception | None = None
    grasps: GraspSet | None = None
    cursor: GraspCursor | None = None
    place_mark: np.ndarray | None = None
    timings: dict[str, float] = field(default_factory=dict)


class SessionCore:
    """The state the session's parts share, and the helpers they all use. Set up by
    `Session.__init__`, which also (re)starts the task on a robot."""

    settings: Settings
    journal: Journal | None
    lease: ControlLease
    robot: Robot
    behaviours: Behaviours
    projector: Projector
    state: TaskState
    task: Findings
    failure: Failure | None
    message: str
    mode: Mode
    selection: Selection
    strategy: StrategyName
    views: ViewMemory
    _projection: np.ndarray | None
    _capture: Capture | None
    _foreseen: Foreseen | None
    _rng: np.random.Generator

    def _init_core(self, settings: Settings, journal: Journal | None) -> None:
        self.settings = settings
        self.journal = journal
        self.lease = ControlLease(self.settings.server.lease_timeout_s)
        self._lock = threading.RLock()
        self._scene_lock = threading.Lock()  #: one robot replacement at a time
        self._listeners: list[Callable[[dict[str, Any]], None]] = []
        self._scene_listeners: list[Callable[[Robot], None]] = []

    def _init_worker(self) -> None:
        self._worker = ThreadPoolExecutor(max_workers=1, thread_name_prefix="laserpick-session")
        self._job: Future[None] | None = None
        self._job_name = ""
        self._cancel = threading.Event()
        self._cancel_reason = "Cancelled by the operator."  #: why `_cancel` was set
        self._motion_token: str | None = None  #: whose heartbeat the running motion needs
        self._job_freed = threading.Event()  #: a job ended: its arrays are free to give back

    # --- listeners, events and the journal ----------------------------------------------------

    def on_event(self, fn: Callable[[dict[str, Any]], None]) -> None:
        """Call `fn(event)` for every discrete event (from any thread; keep it quick)."""
        self._listeners.append(fn)

    def on_scene(self, fn: Callable[[Robot], None]) -> None:
        """Call `fn(robot)` after `replace_robot` put a new robot in (the 3D view rebuilds)."""
        self._scene_listeners.append(fn)

    def announce(self, name: str, /, **fields: Any) -> None:
        """Send a discrete event to every listener (the events websocket among them): for
        in-process clients, e.g. the 3D view saying the highlight is on screen."""
        self._emit(name, **fields)

    def _emit(self, name: str, /, **fields: Any) -> None:
        event = {"type": "event", "name": name, "t": time.time(), "state": self.state.value}
        event.update(fields)
        for fn in list(self._listeners):
            try:
                fn(event)
            except Exception:  # a listener's bug must not stop the task
                log.exception("event listener failed")

    def _record(
        self,
        actor: Actor,
        action: str,
        outcome: str,
        failure: Failure | None = None,
        message: str = "",
        timings: dict[str, float] | None = None,
    ) -> None:
        if self.journal is None:
            return
        try:
            self.journal.record(
                source=actor.source,
                action=action,
                outcome=outcome,
                failure=failure.kind if failure else None,
                message=failure.message if failure else message,
                timings=timings,
                detail={"state": self.state.value},
            )
        except Exception:  # the robot must not stop because the disk is full
            log.exception("journal write failed")

    def _progress(self, message: str) -> None:
        self.message = message
        self._emit("progress", message=message)

    # --- the task state -----------------------------------------------------------------------

    def _set(self, state: TaskState, message: str | None = None) -> None:
        """Go to `state` (`states.TRANSITIONS` must allow it), saying `message`."""
        check_transition(self.state, state)
        self.state = state
        if message is not None:
            self.message = message
        self._emit("state", message=self.message)

    def _fail(self, failure: Failure, state: TaskState) -> None:
        self.failure = failure
        self._set(state, failure.message)
        self._emit("failure", kind=failure.kind, message=failure.message)

    def _forget_task(self) -> None:
        """Drop what the task found, and the projector's highlight of it."""
        self.task = Findings()
        self._projection = None

    # --- guards -------------------------------------------------------------------------------

    @property
    def busy(self) -> bool:
        return self._job is not None and not self._job.done()

    @property
    def estopped(self) -> bool:
        return self.robot.state().estopped

    def _refuse(self, actor: Actor, action: str, message: str) -> Conflict:
        self._record(actor, action, "refused", message=message)
        return Conflict(message, self.state)

    def _require(
        self, actor: Actor, action: str, states: Sequence[TaskState] | frozenset[TaskState]
    ) -> None:
        if self.busy:
            raise self._refuse(actor, action, f"busy ({self._job_name}); cancel it first")
        if self.state not in states:
            allowed = ", ".join(sorted(s.value for s in states))
            raise self._refuse(
                actor, action, f"not allowed while {self.state.value} (allowed when: {allowed})"
            )

    def _require_motion(self, actor: Actor, action: str) -> None:
        if self.estopped:
            raise self._refuse(actor, action, "the e-stop is latched; reset it first")

    # --- the worker thread --------------------------------------------------------------------

    def _start(self, actor: Actor, name: str, job: Callable[[], None], *, motion: bool) -> None:
        self._cancel.clear()
        self.failure = None
        self._job_name = name
        self._motion_token = actor.token if motion else None
        self._job = self._worker.submit(self._run_job, actor, name, job)

    def _run_job(self, actor: Actor, name: str, job: Callable[[], None]) -> None:
        t0 = time.perf_counter()
        task = self.task  # a finished job replaces self.task; its timings are this one's
        try:
            job()
        except Exception as exc:  # a bug in a job must leave the robot at rest, not running
            log.exception("session job %s failed", name)
            self.robot.halt()
            with self._lock:
                failure = Failure("execute", f"Internal error while {name}: {exc}")
                self._fail(failure, TaskState.IDLE)
        finally:
            self._job_freed.set()
            with self._lock:
                self._motion_token = None
                task.timings[f"{name}_total"] = time.perf_counter() - t0
                timings = {k: round(v, 4) for k, v in task.timings.items()}
                outcome = (
                    "cancelled" if self._cancel.is_set() else "failed" if self.failure else "done"
                )
                self._record(actor, name, outcome, self.failure, self.message, timings)
                self._emit("job", job=name, outcome=outcome, message=self.message, timings=timings)
