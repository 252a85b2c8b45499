"""The operator session: the one task state machine behind every input.

Console buttons, REST calls, the switch and joystick adapters and the benchmarks all call the
methods of one `Session`; nothing else changes task state (rule 2 of the design). The task:

    idle ─aim→ aiming ─confirm→ marked → perceived → grasps_ready ─execute→ executing
      ↑                                                                      │
      └──────────── (dropped in the basket, or placed, then stowed) ←── holding
                                                     awaiting_place ─confirm→ placing

- idle: nothing under way; the laser may be off.
- aiming: the aiming beam is lit; aim and nudge move it.
- marked: both beams lit; the frames are being captured and the mark found.
- perceived: the target is segmented and lit by the projector; grasps are being found (or
  were not: `detect` tries again, perhaps with another strategy).
- grasps_ready: clusters and a current candidate; next, prev, select and auto move it.
- executing: the arm picks (for the Jeeves strategy the base drove to the object first).
- holding: the object is in the hand (carried to the basket in pick-and-drop; after a
  cancel, waiting for `execute` to drop it or for a place mark).
- awaiting_place: pick-and-place holds the object high and waits for the place mark.
- placing: the arm sets the object down at the mark, then stows.

Long work (perception, grasp detection, every arm motion) runs on one worker thread, so no
caller waits on it and the API stays responsive. A failure returns to a safe resting state
with a typed `Failure`; cancel aborts the job, halts the arm and retreats; the e-stop halts
at once and latches. The watchdog halts motion commanded by a lease holder who goes silent.

Frames: points in `base` (m) unless a method says `world`; angles in radians.
"""

from __future__ import annotations

import itertools
import logging
import math
import threading
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field, replace
from enum import StrEnum
from typing import Any, Literal

import numpy as np

from laserpick.behaviours import GRIPPER_TIME, SUPPORT_SCATTER, Behaviours, Outcome
from laserpick.description import dims
from laserpick.description.kinematics import tcp_pose
from laserpick.pipeline.cloud import fuse, ray_hit
from laserpick.pipeline.collision import CollisionChecker, not_carried, self_filter
from laserpick.pipeline.grasp_choice import GraspSet, at_pose, find_grasps
from laserpick.pipeline.laser_spots import detect_mark
from laserpick.pipeline.perceive import Perception, perceive
from laserpick.pipeline.projector import highlight_disc, highlight_points
from laserpick.pipeline.recall import Recalled, ViewMemory, moved, moved_points
from laserpick.pipeline.selection import GraspCursor
from laserpick.pipeline.surface import still_standing
from laserpick.robot.sim.robot import SimRobot
from laserpick.robot.sim.scenes import Scene
from laserpick.server.journal import Journal
from laserpick.server.lease import ControlLease
from laserpick.settings import Settings, get_settings
from laserpick.transforms import invert, planar_pose
from laserpick.types import DepthFrame, Failure, FusedCloud, Grasp

log = logging.getLogger(__name__)

Mode = Literal["pick_and_drop", "pick_and_place"]
Selection = Literal["auto", "manual"]
#: gpd: 004's 6-DOF candidates; overhead: EL-E's (000 section 4.4); jeeves: drive the base to
#: the target's centroid, then grasp from above (003 section IV).
StrategyName = Literal["gpd", "overhead", "jeeves"]
Source = Literal["console", "rest", "switch", "joystick", "bench", "system"]


ESTOP_REASON = "Stopped by the e-stop; the arm stays where it is."
#: What the user hears when a place's post-condition fails (`_fell`).
PLACED_NOT_STANDING = (
    "I set the object down, but I no longer see it where I let go of it: it may have fallen"
    " off the spot. Mark it again to pick it up."
)
#: The watchdog's period (s), and the gap between its ticks that means the process stalled.
WATCHDOG_TICK, WATCHDOG_STALL = 0.02, 0.1
#: Longest the API's event loop may lag (s) before the watchdog judges silence regardless.
IO_STALL_MAX = 2.0
#: A capture older than this (s) is not reused for aiming or a clicked mark.
CAPTURE_MAX_AGE = 5.0
#: The scooter has moved since the pick once the odometry says this far (m) or this turn
#: (rad): the planner's clearance. What stood around the held object is then taken anew.
HELD_MOVED = 0.01
HELD_TURNED = math.radians(1.0)
#: Said after a failure for which the arm found no way out holding the object.
PUT_BACK = "I found no way out holding it, so I set it back down where it was."


class TaskState(StrEnum):
    IDLE = "idle"
    AIMING = "aiming"
    MARKED = "marked"
    PERCEIVED = "perceived"
    GRASPS_READY = "grasps_ready"
    EXECUTING = "executing"
    HOLDING = "holding"
    AWAITING_PLACE = "awaiting_place"
    PLACING = "placing"


#: States where the laser may be aimed (and the mark, or the place mark, confirmed).
AIMABLE = frozenset(
    {
        TaskState.IDLE,
        TaskState.AIMING,
        TaskState.PERCEIVED,
        TaskState.GRASPS_READY,
        TaskState.HOLDING,
        TaskState.AWAITING_PLACE,
    }
)
#: States that hold an object: aiming there chooses where to place it.
HOLDING_STATES = frozenset({TaskState.HOLDING, TaskState.AWAITING_PLACE})


class Conflict(Exception):
    """A command that the current state does not allow (HTTP 409). `state` is the state."""

    def __init__(self, message: str, state: TaskState) -> None:
        super().__init__(message)
        self.state = state


@dataclass(frozen=True)
class Actor:
    """Who asks: the input source, and the lease token when it came through the API (None
    for in-process callers such as the 3D console, which the watchdog does not watch)."""

    source: Source
    token: str | None = None


SYSTEM = Actor("system")


@dataclass
class _Task:
    """What the current task has found so far."""

    perception: Perception | None = None
    grasps: GraspSet | None = None
    cursor: GraspCursor | None = None
    place_mark: np.ndarray | None = None
    timings: dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class _Capture:
    """One capture: the frames, their fused cloud (in `base`), the scooter's (x, y, yaw) pose
    and the monotonic time (s) when it was taken. Replaced whole, so readers on other threads
    never see a cloud with another capture's pose."""

    frames: tuple[DepthFrame, ...]
    cloud: FusedCloud
    pose: np.ndarray
    at: float


@dataclass(frozen=True)
class _Foreseen:
    """A clicked mark worked out before the click that confirms it: the perception at
    `point` (m, `base`) in `capture`, and the projector image lighting its target (None when
    there is none)."""

    capture: _Capture
    point: np.ndarray
    perception: Perception
    lit: np.ndarray | None

    def of(self, capture: _Capture | None, point: np.ndarray) -> bool:
        """Whether this is the mark at `point` (m, `base`) worked out in `capture`."""
        return self.capture is capture and np.array_equal(self.point, point)


def _vec(a: np.ndarray | None, digits: int = 4) -> list[float] | None:
    return None if a is None else [round(float(x), digits) for x in np.ravel(a)]


def grasp_summary(g: Grasp) -> dict[str, Any]:
    """A grasp as JSON: pose (4x4, `base`), width (m), score and its five factors, and
    whether its pads meet the object about their middle (such grasps are offered first)."""
    scores = g.scores
    return {
        "pose": [_vec(row) for row in g.pose],
        "position": _vec(g.position),
        "approach": _vec(g.approach),
        "width": round(float(g.width), 4),
        "score": round(float(g.score), 4),
        "factors": None
        if scores is None
        else {k: round(float(getattr(scores, k)), 4) for k in ("Cw", "Cj", "Ca", "Cs", "Cp")},
        "cluster": g.cluster,
        "pads_centred": g.pads_centred,
    }


class Session:
    """The task state machine around one simulated robot.

    robot: a real-time `SimRobot` (the session drives the laser, a simulated hand-held
    pointer, as well as the robot). journal: where every command and outcome is recorded.
    """

    def __init__(
        self,
        robot: SimRobot,
        *,
        journal: Journal | None = None,
        settings: Settings | None = None,
    ) -> None:
        self.settings = settings or get_settings()
        self.journal = journal
        self.lease = ControlLease(self.settings.server.lease_timeout_s)
        self._lock = threading.RLock()
        self._scene_lock = threading.Lock()  #: one scene reset at a time
        self._listeners: list[Callable[[dict[str, Any]], None]] = []
        self._scene_listeners: list[Callable[[SimRobot], None]] = []
        self._worker = ThreadPoolExecutor(max_workers=1, thread_name_prefix="laserpick-session")
        self._job: Future[None] | None = None
        #: Views kept while driving are taken here in real time, so a drive command never
        #: waits on a capture.
        self._view_pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="laserpick-views")
        self._view_job: Future[None] | None = None
        #: A clicked mark is worked out here as soon as it is aimed (`_foresee`), so that the
        #: confirming click finds its target segmented and the highlight on its way.
        self._foresight = ThreadPoolExecutor(
            max_workers=1, thread_name_prefix="laserpick-foresight"
        )
        self._foresee_seqs = itertools.count(1)
        self._foresee_seq = 0  #: the newest request; older ones not yet begun are dropped
        self._job_name = ""
        self._cancel = threading.Event()
        self._cancel_reason = "Cancelled by the operator."  #: why `_cancel` was set
        self._io_alive: float | None = None  #: monotonic time of the API loop's last tick
        self._motion_token: str | None = None  #: whose heartbeat the running motion needs
        self._drive_token: str | None = None
        self._drive_until = 0.0
        #: (token, seq) of the last numbered drive applied: older ones are dropped.
        self._drive_seq: tuple[str | None, int] = (None, -1)
        self.mode: Mode = "pick_and_drop"
        self.selection: Selection = "auto"
        self.strategy: StrategyName = "gpd"
        self._rng = np.random.default_rng(self.settings.server.seed)
        self._attach(robot)
        self._closing = threading.Event()
        self._watchdog = threading.Thread(
            target=self._watch, name="laserpick-watchdog", daemon=True
        )
        self._watchdog.start()

    def _attach(self, robot: SimRobot) -> None:
        self.robot = robot
        self.behaviours = Behaviours(
            robot,
            self.settings,
            rng=self._rng,
            progress=self._progress,
            should_stop=self._cancel.is_set,
        )
        self.projector = robot.projector()
        self.state = TaskState.IDLE
        self.task = _Task()
        self.failure: Failure | None = None
        self.message = "Ready. Aim the laser at an object."
        self._projection: np.ndarray | None = None
        self._capture: _Capture | None = None
        self._foreseen: _Foreseen | None = None
        p = self.settings.perception
        self.views = ViewMemory(
            p.recall_spacing,
            math.radians(p.recall_turn_deg),
            p.recall_views,
            p.recall_max_age,
            p,
        )

    def close(self) -> None:
        """Halt, stop the worker and the watchdog, and close the robot."""
        self._closing.set()
        self._cancel.set()
        self.robot.halt()
        self._worker.shutdown(wait=True, cancel_futures=True)
        self._view_pool.shutdown(wait=True, cancel_futures=True)
        self._foresight.shutdown(wait=True, cancel_futures=True)
        self._watchdog.join(timeout=1.0)
        self.robot.close()

    def reseed(self, seed: int | np.random.SeedSequence) -> None:
        """Draw the planner's and the grasp sampler's random numbers from here on as a fresh
        session seeded with `seed` would. Between jobs only: they draw from it."""
        if self.busy:
            raise RuntimeError("the session is busy; reseed it between jobs")
        # In place: the behaviours hold the same generator.
        self._rng.bit_generator.state = np.random.default_rng(seed).bit_generator.state

    # --- listeners --------------------------------------------------------------------------

    def on_event(self, fn: Callable[[dict[str, Any]], None]) -> None:
        """Call `fn(event)` for every discrete event (from any thread; keep it quick)."""
        self._listeners.append(fn)

    def on_scene(self, fn: Callable[[SimRobot], None]) -> None:
        """Call `fn(robot)` after a scene reset replaced the robot (the 3D view rebuilds)."""
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

    def _set(self, state: TaskState, message: str | None = None) -> None:
        self.state = state
        if message is not None:
            self.message = message
        self._emit("state", message=self.message)

    def _fail(self, failure: Failure, state: TaskState) -> None:
        self.failure = failure
        self._set(state, failure.message)
        self._emit("failure", kind=failure.kind, message=failure.message)

    # --- guards -----------------------------------------------------------------------------

    @property
    def busy(self) -> bool:
        return self._job is not None and not self._job.done()

    @property
    def estopped(self) -> bool:
        return self.robot.sim.snapshot().estopped

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
            with self._lock:
                self._motion_token = None
                task.timings[f"{name}_total"] = time.perf_counter() - t0
                timings = {k: round(v, 4) for k, v in task.timings.items()}
                outcome = (
                    "cancelled" if self._cancel.is_set() else "failed" if self.failure else "done"
                )
                self._record(actor, name, outcome, self.failure, self.message, timings)
                self._emit("job", job=name, outcome=outcome, message=self.message, timings=timings)

    # --- the laser --------------------------------------------------------------------------

    def _after_aim(self) -> None:
        """Aiming: a new target drops what was found for the old one."""
        if self.state in HOLDING_STATES:
            self._set(TaskState.AWAITING_PLACE, "Mark where to put it, then confirm.")
        elif self.state != TaskState.AIMING:
            self.task = _Task()
            self._projection = None
            self._set(TaskState.AIMING, "Aim at the object, then confirm.")

    def aim(self, actor: Actor, yaw: float, pitch: float) -> None:
        """Point the laser at (yaw, pitch) rad in `base` (clamped to the pointer's limits)."""
        with self._lock:
            self._require(actor, "laser/aim", AIMABLE)
            self.robot.laser.aim(yaw, pitch)
            self._after_aim()
            self._record(actor, "laser/aim", "ok")

    def aim_at(
        self,
        actor: Actor,
        point: np.ndarray,
        frame: Literal["base", "world"],
        *,
        foresee: bool = False,
    ) -> None:
        """Point the laser at a point (m) in `base` or `world`. foresee: aimed at an object
        by a click, work out the mark there at once (`_foresee`): a confirm at this very
        point then finds it done."""
        p = self._to_base(np.asarray(point, dtype=float), frame)
        reach = self.settings.server.max_reach
        if np.linalg.norm(p[:2]) > reach:
            raise ValueError(
                f"point is {np.linalg.norm(p[:2]):.1f} m from the scooter; the laser is aimed"
                f" within {reach:.0f} m"
            )
        with self._lock:
            self._require(actor, "laser/aim", AIMABLE)
            self.robot.laser.aim_at(p)
            self._after_aim()
            self._record(actor, "laser/aim", "ok")
            if foresee and self.state == TaskState.AIMING:
                self._foresee(p)

    def ray_point(
        self, origin: np.ndarray, direction: np.ndarray, frame: Literal["base", "world"]
    ) -> np.ndarray:
        """Where a ray (a click in the 3D view) first meets the fused cloud (m, `base`).
        ValueError when the ray misses everything."""
        o = self._to_base(np.asarray(origin, dtype=float), frame)
        d = self._to_base(np.asarray(direction, dtype=float), frame, direction=True)
        hit = ray_hit(self.cloud().points, o, d, radius=self.settings.server.cloud_voxel)
        if hit is None:
            raise ValueError("the ray meets no point of the cloud")
        return hit

    def aim_ray(
        self,
        actor: Actor,
        origin: np.ndarray,
        direction: np.ndarray,
        frame: Literal["base", "world"],
    ) -> np.ndarray:
        """Point the laser where a ray (a click in the 3D view) first meets the fused cloud,
        foreseeing the mark there (`aim_at`); the hit point in `base` (m). ValueError when
        the ray misses everything."""
        hit = self.ray_point(origin, direction, frame)
        self.aim_at(actor, hit, "base", foresee=True)
        return hit

    def nudge(self, actor: Actor, dyaw: float, dpitch: float) -> None:
        """Turn the laser by small steps (rad), as a joystick or switch does."""
        with self._lock:
            self._require(actor, "laser/nudge", AIMABLE)
            self.robot.laser.nudge(dyaw, dpitch)
            self._after_aim()
            self._record(actor, "laser/nudge", "ok")

    def laser_off(self, actor: Actor) -> None:
        with self._lock:
            self._require(actor, "laser/off", AIMABLE)
            self.robot.laser.off()
            if self.state == TaskState.AIMING:
                self._set(TaskState.IDLE, "Laser off.")
            self._record(actor, "laser/off", "ok")

    def confirm(self, actor: Actor, point: np.ndarray | None = None) -> None:
        """Light both beams: mark the object (then perceive and find grasps), or, holding an
        object in pick-and-place, mark where it goes (then place it).

        point: where a confirming click landed (m, `base`). The mark is then that point, as
        from a touch screen, and not the dots found in a new capture."""
        with self._lock:
            self._require(actor, "laser/confirm", (TaskState.AIMING, TaskState.AWAITING_PLACE))
            if not self.robot.laser.state.on:
                raise self._refuse(actor, "laser/confirm", "the laser is off; aim it first")
            self.robot.laser.confirm()
            self._record(actor, "laser/confirm", "ok")
            if self.state == TaskState.AWAITING_PLACE:
                self._require_motion(actor, "laser/confirm")
                self._start(actor, "placing", self._place_job, motion=True)
            else:
                if self.strategy == "jeeves":
                    self._require_motion(actor, "laser/confirm")
                self._set(TaskState.MARKED, "Marked. Looking at the object.")
                seen = self._foreseen
                if point is not None and seen is not None and seen.of(self._capture, point):
                    # Worked out since the aim, and the job will take this same result:
                    # the projector lights the target now, not after the job's first step.
                    self._projection = seen.lit
                job = self._perceive_job if point is None else lambda: self._perceive_job(point)
                self._start(actor, "perceiving", job, motion=self.strategy == "jeeves")

    def detect(self, actor: Actor) -> None:
        """Find grasps again for the perceived target (e.g. after changing the strategy)."""
        with self._lock:
            self._require(actor, "detect", (TaskState.PERCEIVED, TaskState.GRASPS_READY))
            if self.strategy == "jeeves":
                self._require_motion(actor, "detect")
            self._set(TaskState.PERCEIVED, "Finding grasps.")
            self._start(actor, "detecting", self._grasp_job, motion=self.strategy == "jeeves")

    # --- grasp choice -----------------------------------------------------------------------

    def _cursor(self, actor: Actor, action: str) -> GraspCursor:
        self._require(actor, action, (TaskState.GRASPS_READY,))
        assert self.task.cursor is not None
        return self.task.cursor

    def step_grasp(self, actor: Actor, step: int, level: Literal["cluster", "candidate"]) -> None:
        """Move the current grasp by one cluster, or one candidate within the cluster."""
        action = "grasps/next" if step > 0 else "grasps/prev"
        with self._lock:
            cur = self._cursor(actor, action)
            if level == "cluster":
                cur.next() if step > 0 else cur.prev()
            else:
                cur.next_candidate() if step > 0 else cur.prev_candidate()
            self._grasp_changed(actor, action)

    def select_grasp(self, actor: Actor, cluster: int, candidate: int) -> None:
        """Make a cluster's candidate (0-based) the current grasp; IndexError if out of range."""
        with self._lock:
            cur = self._cursor(actor, "grasps/select")
            cur.select(cluster, candidate)
            self._grasp_changed(actor, "grasps/select")

    def auto_grasp(self, actor: Actor) -> None:
        """Back to the system's choice: the best grasp of the best cluster."""
        with self._lock:
            cur = self._cursor(actor, "grasps/auto")
            cur.select(0, 0)
            self._grasp_changed(actor, "grasps/auto")

    def _grasp_changed(self, actor: Actor, action: str) -> None:
        assert self.task.cursor is not None
        self.message = self.task.cursor.describe()
        self._emit("grasp", message=self.message)
        self._record(actor, action, "ok", message=self.message)

    # --- execution --------------------------------------------------------------------------

    def execute(self, actor: Actor) -> None:
        """Pick with the current grasp (manual) or the best that plans (auto); in holding,
        drop what the hand holds in the basket."""
        with self._lock:
            self._require(actor, "execute", (TaskState.GRASPS_READY, TaskState.HOLDING))
            self._require_motion(actor, "execute")
            if self.state == TaskState.HOLDING:
                self._start(actor, "dropping", self._drop_job, motion=True)
                return
            grasps, cursor = self.task.grasps, self.task.cursor
            assert grasps is not None and cursor is not None
            if self.selection == "manual":
                members = grasps.clusters.clusters[cursor.cluster]
                chosen = members[cursor.candidate]
                rest = [grasps.clusters.grasps[i] for i in members if i != chosen]
                order = [cursor.current, *rest]
            else:
                order = grasps.ordered()
            self._set(TaskState.EXECUTING, "Picking.")
            self._start(actor, "picking", lambda: self._pick_job(order), motion=True)

    def cancel(self, actor: Actor) -> None:
        """Abort what is under way: halt the arm and base; a job then retreats to a safe pose.
        Without a job, drop the found target (or the place mark) and rest."""
        with self._lock:
            if self.busy:
                self._cancel_reason = "Cancelled by the operator."
                self._cancel.set()
                self.robot.halt()
                self._progress("Cancelling.")
            elif self.state in (TaskState.AIMING, TaskState.PERCEIVED, TaskState.GRASPS_READY):
                self.robot.laser.off()
                self.task = _Task()
                self._projection = None
                self._set(TaskState.IDLE, "Cancelled.")
            elif self.state == TaskState.AWAITING_PLACE:
                self.robot.laser.off()
                self._set(TaskState.HOLDING, "Holding. Execute drops it in the basket.")
            self._record(actor, "cancel", "ok")

    def resync(self, actor: Actor) -> None:
        """After a person stepped in by hand (took the object out of the gripper, or moved the
        arm): forget the task and rest in the state the robot now shows, holding or idle."""
        with self._lock:
            if self.busy:
                raise self._refuse(actor, "resync", f"busy ({self._job_name}); cancel it first")
            if not self.robot.gripper_state().holding:
                self.behaviours.held = None
            self.task = _Task()
            self._projection = None
            self.failure = None
            state = self._resting_state()
            self._set(state, "Holding." if state == TaskState.HOLDING else "Ready.")
            self._record(actor, "resync", "ok")

    def drive(
        self, actor: Actor, v: float, w: float, duration: float, seq: int | None = None
    ) -> None:
        """Drive the base at v (m/s) and w (rad/s) for at most `duration` s (<= 0.5 s: a
        dead-man; send it again to keep going). What was perceived is stale afterwards.

        `seq` numbers a client's drive commands. Requests on different connections can be
        handled out of order, and a drive overtaking the stop sent after it would move the
        base for another half second; so a numbered command older than the last one applied
        from the same token is dropped."""
        with self._lock:
            self._require(actor, "drive", AIMABLE)
            self._require_motion(actor, "drive")
            if seq is not None:
                last_token, last_seq = self._drive_seq
                if actor.token == last_token and seq <= last_seq:
                    return
                self._drive_seq = (actor.token, seq)
            self.robot.drive(v, w, duration)
            self._drive_token = actor.token
            self._drive_until = time.monotonic() + duration
            if self.state in (TaskState.PERCEIVED, TaskState.GRASPS_READY):
                self.task = _Task()
                self._projection = None
                aiming = self.robot.laser.state.on
                self._set(TaskState.AIMING if aiming else TaskState.IDLE, "Driving.")
            self._capture = None
        self._keep_view()

    def _keep_view(self) -> None:
        """On the way, keep a view each `recall_spacing` m or `recall_turn_deg` (the
        `ViewMemory`): where the scooter stops, its fixed cameras have blind spots that were
        in view on the way in. In real time the capture runs on its own thread, so the drive
        command does not wait on it; headless, it runs at once, so a run replays exactly."""
        robot = self.robot
        # Only with the arm stowed and the hand empty, as they are when a grasp is planned:
        # a view never shows the arm elsewhere, nor an object riding along in the hand.
        stowed = at_pose(robot.joint_state().q, dims.UR5_HOME_Q)
        if not stowed or robot.gripper_state().holding or not self.views.due(robot.base_pose()):
            return
        if not robot.sim.realtime:
            self._take_view(robot)
        elif self._view_job is None or self._view_job.done():
            self._view_job = self._view_pool.submit(self._take_view, robot)

    def _take_view(self, robot: SimRobot) -> None:
        pose, q = robot.base_pose(), robot.joint_state().q
        try:
            frames = robot.capture()
        except Exception:  # a view is extra evidence; a drive goes on without it
            log.exception("A view on the way could not be captured.")
            return
        if robot is self.robot:  # not a view of a scene replaced meanwhile
            self.views.add(frames, pose, q)

    def _recalled(self) -> Recalled:
        """The views kept on the way in, in `base` as the scooter stands now."""
        return self.views.recall(self.robot.base_pose(), self.robot.joint_state().stamp)

    def _await_estop(self, latched: bool, timeout: float = 0.5) -> None:
        """Wait (briefly) until the simulation has applied an e-stop or its reset, so that the
        next command sees it: commands reach the simulation thread at its next step."""
        end = time.monotonic() + timeout
        while self.estopped != latched and time.monotonic() < end:
            time.sleep(0.001)

    def stop(self, actor: Actor) -> None:
        """E-stop: arm and base halt within one control tick and stay halted until reset."""
        self.robot.stop()
        self._cancel_reason = ESTOP_REASON
        self._cancel.set()
        self._await_estop(True)
        with self._lock:
            self._drive_until = 0.0
            self.message = "E-STOP. Motion is halted until the stop is reset."
            self._emit("estop", message=self.message)
            self._record(actor, "stop", "ok")

    def reset_stop(self, actor: Actor) -> None:
        with self._lock:
            if self.busy:
                raise self._refuse(actor, "stop/reset", "the stopped job is still winding down")
            self.robot.reset_stop()
            self._await_estop(False)
            self.message = "Stop reset."
            self._emit("estop_reset", message=self.message)
            self._record(actor, "stop/reset", "ok")

    def set_mode(
        self,
        actor: Actor,
        mode: Mode | None = None,
        selection: Selection | None = None,
        strategy: StrategyName | None = None,
    ) -> None:
        """Change the task mode, the selection mode or the grasp strategy (None: keep)."""
        with self._lock:
            if self.busy:
                raise self._refuse(actor, "mode", f"busy ({self._job_name}); cancel it first")
            self.mode = mode or self.mode
            self.selection = selection or self.selection
            self.strategy = strategy or self.strategy
            self._emit("mode", mode=self.mode, selection=self.selection, strategy=self.strategy)
            summary = f"{self.mode} {self.selection} {self.strategy}"
            self._record(actor, "mode", "ok", message=summary)

    def reset_scene(self, actor: Actor, scene: Scene) -> None:
        """Replace the world with `scene`: a fresh robot at the scene's start pose. The new
        model is built outside the session's lock (it takes a second or two), so state reads
        and the e-stop stay quick meanwhile."""
        with self._scene_lock:
            with self._lock:
                self._require_scene_change(actor)
            new = SimRobot(scene, realtime=True, settings=self.settings)
            with self._lock:
                try:
                    self._require_scene_change(actor)
                except Conflict:
                    new.close()
                    raise
                old = self.robot
                self._attach(new)
            old.close()
            for fn in list(self._scene_listeners):
                fn(new)
            with self._lock:
                self._emit("scene", scene=scene.name, message=f"Scene {scene.name!r} loaded.")
                self._record(actor, "scene", "ok", message=scene.name)

    def _require_scene_change(self, actor: Actor) -> None:
        if self.busy:
            raise self._refuse(actor, "scene", f"busy ({self._job_name}); cancel it first")
        if self.estopped:
            raise self._refuse(actor, "scene", "the e-stop is latched; reset it first")

    # --- the jobs (worker thread) -----------------------------------------------------------

    def _foresee(self, point: np.ndarray) -> Future[_Foreseen | None]:
        """Work out the mark at `point` (m, `base`) in the capture it was aimed in, on the
        foresight thread: the perception a confirm there uses, and its highlight, which the
        3D view sends ahead, hidden, to show at the confirm. Resolves to None when there is
        no fresh capture (the scooter moved), or when a newer request came before it began."""
        seq = self._foresee_seq = next(self._foresee_seqs)
        return self._foresight.submit(self._work_out, self._capture, point, seq)

    def _work_out(self, capture: _Capture | None, point: np.ndarray, seq: int) -> _Foreseen | None:
        seen = self._foreseen
        if seen is not None and seen.of(capture, point):
            return seen
        if seq != self._foresee_seq or capture is None or capture is not self._fresh_capture():
            return None
        perception = perceive(
            capture.frames, point=point, settings=self.settings.perception, cloud=capture.cloud
        )
        lit = highlight_points(self.projector, perception.target_points) if perception.ok else None
        seen = _Foreseen(capture, np.array(point, float), perception, lit)
        self._foreseen = seen
        with self._lock:
            self._emit("foreseen")
        return seen

    @property
    def foreseen(self) -> tuple[FusedCloud, np.ndarray] | None:
        """The cloud and the projector image of the mark worked out ahead of its confirm,
        while that capture is the latest: what the 3D view may send ahead, hidden."""
        seen = self._foreseen
        if seen is None or seen.lit is None or seen.capture is not self._capture:
            return None
        return seen.capture.cloud, seen.lit

    def _perceive_job(self, point: np.ndarray | None = None) -> None:
        """Capture, find the mark in the IR images, segment. With `point` (a confirming click,
        m in `base`), the mark is that point, worked out in the capture it was aimed in while
        that is still fresh (`_foresee`: mostly done before the click)."""
        seen = self._foresee(point).result() if point is not None else None
        if seen is not None:
            perception, lit, captured = seen.perception, seen.lit, 0.0
        else:
            t0 = time.perf_counter()
            frames = self.robot.capture()
            captured = time.perf_counter() - t0
            perception = perceive(frames, point=point, settings=self.settings.perception)
            self._remember(frames, perception.cloud)
            lit = (
                highlight_points(self.projector, perception.target_points)
                if perception.ok
                else None
            )
        with self._lock:
            self.task.timings = {"capture": captured, **perception.timings}
            if self._cancel.is_set():
                self.robot.laser.off()
                self.task = _Task()
                self._projection = None
                self._set(TaskState.IDLE, "Cancelled.")
                return
            if perception.failure is not None:
                self._projection = None
                yaw, pitch = self.robot.laser.state.yaw, self.robot.laser.state.pitch
                self.robot.laser.aim(yaw, pitch)  # back to the single aiming beam
                self._fail(perception.failure, TaskState.AIMING)
                return
            self.robot.laser.off()
            self.task.perception = perception
            self._projection = lit
            self._set(TaskState.PERCEIVED, "Target found. Finding grasps.")
        self._grasp_job()

    def _grasp_job(self) -> None:
        perception = self.task.perception
        assert perception is not None
        strategy = self.strategy
        if strategy == "jeeves":
            self._progress("Driving to the object.")
            approached = self.behaviours.approach(perception)
            if isinstance(approached, Failure) or not approached.ok:
                failure = approached if isinstance(approached, Failure) else approached.failure
                assert failure is not None
                with self._lock:
                    self._fail(failure, TaskState.PERCEIVED)
                return
            perception = approached
        found = find_grasps(
            perception,
            dims.UR5_READY_Q,
            q_capture=self.robot.joint_state().q,
            strategy="vertical" if strategy == "jeeves" else strategy,
            settings=self.settings,
            rng=self._rng,
            recalled=self._recalled(),
        )
        with self._lock:
            self.task.perception = perception
            if self._cancel.is_set():
                self._set(TaskState.PERCEIVED, "Cancelled.")
                return
            if isinstance(found, Failure):
                self._fail(found, TaskState.PERCEIVED)
                return
            self.task.timings.update(found.timings)
            self.task.grasps = found
            self.task.cursor = GraspCursor(found.clusters)
            self._set(TaskState.GRASPS_READY, f"Grasps ready: {self.task.cursor.describe()}.")

    def _pick_job(self, order: list[Grasp]) -> None:
        grasps = self.task.grasps
        assert grasps is not None
        out = self.behaviours.pick(grasps, order)
        if self.behaviours.held is not None:
            # The object has left its place: the views of the way in must not keep it there.
            above = grasps.stands_on + SUPPORT_SCATTER
            self.views.forget(grasps.carried, self.robot.base_pose(), above)
        self.task.timings.update(out.timings)
        if out.grasp is not None:  # the grasp that planned: in auto, not always the first
            self._emit(
                "grasp_executed",
                grasp=grasp_summary(out.grasp),
                tried=out.attempts,
                closed_width=None if out.closed_width is None else round(out.closed_width, 4),
            )
        if not out.ok:
            assert out.failure is not None
            self._end_badly(out.failure)
            return
        with self._lock:
            self._set(TaskState.HOLDING, "Holding the object.")
        if self.mode == "pick_and_drop":
            self._drop_job()
            return
        tucked = self.behaviours.tuck()
        if not tucked.ok:
            assert tucked.failure is not None
            self._end_badly(tucked.failure, tucked=tucked)
            return
        with self._lock:
            self._set(TaskState.AWAITING_PLACE, "Mark where to put it, then confirm.")

    def _drop_job(self) -> None:
        self._held_here()
        b = self.behaviours
        out = b.drop_in_basket()
        if out.failure is not None and out.failure.kind == "ik_plan" and b.held is not None:
            # No way to the basket from where the lift left the object, it is tucked in and
            # carried from there: a pill bottle lifted in the bookshelf's gap found none,
            # and was then tucked in and kept (in-situ).
            self._progress("Tucking the object in on the way to the basket.")
            tucked = b.tuck()
            if not tucked.ok:
                self._end_badly(out.failure, tucked=tucked)
                return
            out = b.drop_in_basket()
        if not out.ok:
            assert out.failure is not None
            self._end_badly(out.failure)
            return
        self._stow_and_rest("Dropped in the basket." + (f" {out.caution}" if out.caution else ""))

    def _place_job(self) -> None:
        with self._lock:
            self._set(TaskState.PLACING, "Looking at the place mark.")
        frames = self.robot.capture()
        self.robot.laser.off()
        mark = detect_mark(frames, self.settings.perception)
        if isinstance(mark, Failure):
            with self._lock:
                self.robot.laser.aim(self.robot.laser.state.yaw, self.robot.laser.state.pitch)
                self._fail(mark, TaskState.AWAITING_PLACE)
            return
        cloud = fuse(frames, self.settings.perception)
        self._remember(frames, cloud)
        self.task.place_mark = mark.point
        self._projection = highlight_disc(self.projector, mark.point)
        self._progress("Placing.")
        out = self.behaviours.place(cloud, mark.point)
        if not out.ok:
            assert out.failure is not None
            self._end_badly(out.failure)
            return
        self._stow_and_rest("Placed.", placed=out)

    def _try_look(self) -> _Capture | None:
        """A new capture, or None if the cameras fail (logged)."""
        try:
            return self._look()
        except Exception:
            log.exception("No capture; going on without one.")
            return None

    def _surroundings(self, capture: _Capture | None) -> CollisionChecker | None:
        """What stands around the arm in `capture`, a fresh one: the way home is planned
        around it (a stow planned around an empty cloud put the hand into the 87 cm counter
        on its way to the ready pose). The arm's own points are left out, and the space it
        fills counts as seen; the views kept on the way in add what they saw where no camera
        sees now. None without a capture (the cameras failed): the arm must still go home,
        as it did before it looked (rising first, `Behaviours.go_ready`)."""
        if capture is None:
            return None
        recalled = self._recalled()
        blind = recalled.blind_points(capture.frames)
        return CollisionChecker(
            np.vstack([capture.cloud.points, blind]) if len(blind) else capture.cloud.points,
            margin=self.settings.motion.clearance,
            q_self=self.robot.joint_state().q,
            frames=(*capture.frames, *recalled.frames),
        )

    def _held_here(self) -> None:
        """Where the scooter has moved since the pick with the object in hand, take anew what
        stands around the hand (`Held.surroundings`, which the tuck and the drop are planned
        around): the pick's stand where they stood before the scooter then, so the tuck
        after a place refused elsewhere went around them, and not around what stands before
        the hand now. A capture here, with the views of the drive (`_surroundings`), less the held
        object's own points; where the cameras fail, the pick's, carried here by the
        odometry."""
        held, now = self.behaviours.held, self.robot.base_pose()
        if held is None or held.seen_from is None:
            return
        if not moved(held.seen_from, now, HELD_MOVED, HELD_TURNED):
            return
        q = self.robot.joint_state().q
        around = self._surroundings(self._try_look())
        if around is None:
            pts = moved_points(held.surroundings.points, held.seen_from, now)
            around = CollisionChecker(pts, margin=held.surroundings.margin, filtered=True)
        else:
            around = around.without(~not_carried(around.points, held.at(tcp_pose(q))))
        self.behaviours.held = replace(held, surroundings=around, seen_from=now)

    def _stow_and_rest(self, message: str, placed: Outcome | None = None) -> None:
        """Stow and rest, saying `message`; after a place (`placed`), first check from the
        same capture that the object still stands where it was let go."""
        capture = self._try_look()
        fell = placed is not None and capture is not None and self._fell(capture, placed)
        out = self.behaviours.stow(self._surroundings(capture))
        with self._lock:
            self.task = _Task()
            self._projection = None
            if out.failure is not None:  # the arm not home is said first; a fall with it
                said = out.failure.message + (f" {PLACED_NOT_STANDING}" if fell else "")
                self._fail(Failure(out.failure.kind, said), TaskState.IDLE)
            elif fell:
                self._fail(Failure("execute", PLACED_NOT_STANDING), TaskState.IDLE)
            else:
                self._set(TaskState.IDLE, f"{message} Ready.")

    def _fell(self, capture: _Capture, placed: Outcome) -> bool:
        """Whether the cameras see the surface bare where the place let the object go: it
        fell off the spot, or the opened hand took it along (a pill bottle that clung to a
        pad rose 4.6 cm with it and fell on its side 10 cm away). Nothing is said where they
        cannot tell."""
        if placed.standing is None or placed.spot is None:
            return False
        points = capture.cloud.points
        points = points[self_filter(points, self.robot.joint_state().q)]
        return still_standing(points, placed.standing, float(placed.spot[2])) is False

    def _end_badly(self, failure: Failure, tucked: Outcome | None = None) -> None:
        """After a failed or cancelled step: retreat to a safe pose and rest. An object in the
        hand is kept (never dropped from height): the arm tucks it in and the session holds;
        where no way to tuck it in is found, it is put back where it was picked up, if the
        arm can go back down the way it came (`Behaviours.put_back`), and the arm stows.
        tucked: how the tuck that failed just now went (not tried again)."""
        cancelled = self._cancel.is_set()
        if self.estopped or (cancelled and self._cancel_reason == ESTOP_REASON):
            failure = Failure("execute", ESTOP_REASON)
            with self._lock:
                self._fail(failure, self._resting_state())
            return
        if cancelled:
            failure = Failure("execute", self._cancel_reason)
        self._cancel.clear()  # the retreat itself must be allowed to move
        b = self.behaviours
        if b.held is not None and self.robot.gripper_state().holding:
            if tucked is None:
                self._progress("Tucking in what the hand holds.")
                self._held_here()
                tucked = b.tuck()
            if tucked.failure is not None and tucked.failure.kind == "ik_plan":
                put = b.put_back()
                if put.ok:
                    failure = Failure(failure.kind, f"{failure.message} {PUT_BACK}")
                elif put.failure is not None and put.failure.kind != "precondition":
                    # Tried and stopped on the way down: the user hears why it is still held.
                    failure = Failure(failure.kind, f"{failure.message} {put.failure.message}")
        if b.held is None or not self.robot.gripper_state().holding:
            if self.robot.gripper_state().closed:
                self.robot.gripper(False)
                self.robot.sleep(GRIPPER_TIME)
            b.held = None
            self._progress("Returning the arm.")
            b.stow(self._surroundings(self._try_look()))
        with self._lock:
            if cancelled:
                self._cancel.set()  # so the journal records the job as cancelled
            state = self._resting_state()
            if state == TaskState.IDLE:
                self.task = _Task()
                self._projection = None
            self._fail(failure, state)

    def _resting_state(self) -> TaskState:
        holding = self.behaviours.held is not None and self.robot.gripper_state().holding
        return TaskState.HOLDING if holding else TaskState.IDLE

    # --- the watchdog ------------------------------------------------------------------------

    def _watch(self) -> None:
        """Halt motion commanded by a lease holder who has gone silent (no heartbeat for
        `watchdog_s`, or its websocket dropped)."""
        limit = self.settings.server.watchdog_s
        last = time.monotonic()
        while not self._closing.wait(WATCHDOG_TICK):
            now = time.monotonic()
            stalled, last = now - last > WATCHDOG_STALL, now
            if stalled:
                # This process itself was not running (a loaded machine): heartbeats that
                # arrived meanwhile are still queued, so silence cannot be judged this tick.
                continue
            io_late = now - self._io_alive if self._io_alive is not None else 0.0
            if WATCHDOG_STALL < io_late < IO_STALL_MAX:
                # The thread that reads the sockets is behind (starved of CPU): heartbeats
                # may be waiting unread. A loop stuck for longer halts the motion all the same.
                continue
            with self._lock:
                token = self._motion_token if self.busy else None
                driving = time.monotonic() < self._drive_until and self._drive_token is not None
                drive_token = self._drive_token if driving else None
            for tok, what in ((token, "motion"), (drive_token, "drive")):
                if tok is None or self.lease.silent_for(tok) <= limit:
                    continue
                self.robot.halt()
                with self._lock:
                    if what == "motion":
                        self._cancel_reason = (
                            "The controller went silent, so the motion was halted."
                        )
                        self._cancel.set()
                        self._motion_token = None
                    self._drive_until = 0.0
                    self.message = "The controller went silent: motion halted."
                    self._emit("watchdog", message=self.message)
                    self._record(SYSTEM, "watchdog", "halted", message=self.message)

    def io_alive(self) -> None:
        """Called by the API's event loop on each of its ticks: it is reading the sockets, so
        a missing heartbeat is the client's silence, not the server's."""
        self._io_alive = time.monotonic()

    # --- reads ------------------------------------------------------------------------------

    def _to_base(
        self, v: np.ndarray, frame: Literal["base", "world"], *, direction: bool = False
    ) -> np.ndarray:
        if v.shape != (3,) or not np.all(np.isfinite(v)):
            raise ValueError("a point or direction must be 3 finite numbers")
        if frame == "base":
            return v
        T = invert(planar_pose(*self.robot.base_pose()))
        return T[:3, :3] @ v if direction else T[:3, :3] @ v + T[:3, 3]

    @property
    def latest_cloud(self) -> tuple[FusedCloud, np.ndarray] | None:
        """The last fused cloud (in `base` at capture) and the scooter's (x, y, yaw) pose then,
        without capturing; None before the first capture. For drawing it in `world`."""
        capture = self._capture
        return None if capture is None else (capture.cloud, capture.pose)

    @property
    def projection(self) -> np.ndarray | None:
        """The projector image now lit (height x width uint8), or None when nothing is lit."""
        return self._projection

    def _remember(self, frames: Sequence[DepthFrame], cloud: FusedCloud) -> _Capture:
        capture = _Capture(tuple(frames), cloud, self.robot.base_pose(), time.monotonic())
        self._capture = capture
        return capture

    def _look(self) -> _Capture:
        """A new capture, fused and remembered."""
        frames = self.robot.capture()
        return self._remember(frames, fuse(frames, self.settings.perception))

    def _fresh_capture(self) -> _Capture | None:
        """The last capture, if the scooter has not moved since and it is under
        CAPTURE_MAX_AGE old (people move things)."""
        capture = self._capture
        if capture is None or time.monotonic() - capture.at > CAPTURE_MAX_AGE:
            return None
        if np.max(np.abs(capture.pose - self.robot.base_pose())) > 1e-3:
            return None
        return capture

    def cloud(self) -> FusedCloud:
        """A fused cloud in `base` under CAPTURE_MAX_AGE old: the last, or a new capture."""
        fresh = self._fresh_capture()
        if fresh is not None:
            return fresh.cloud
        return self._look().cloud

    def status(self) -> dict[str, Any]:
        """Everything a console shows, as JSON-ready values. Cheap: read at 30 Hz."""
        snap = self.robot.sim.snapshot()
        laser = self.robot.laser.state
        with self._lock:
            task = self.task
            cursor = task.cursor
            perception = task.perception
            mark = perception.mark.point if perception is not None and perception.mark else None
            target = perception.target_points if perception is not None else None
            lease = self.lease.info()
            out: dict[str, Any] = {
                "state": self.state.value,
                "busy": self.busy,
                "job": self._job_name if self.busy else None,
                "message": self.message,
                "mode": self.mode,
                "selection": self.selection,
                "strategy": self.strategy,
                "estopped": bool(snap.estopped),
                "drive_stop": snap.drive_stop or None,
                "sim_time": round(float(snap.time), 4),
                "rtf": round(float(snap.rtf), 3),
                "joints": {"q": _vec(snap.arm_q), "qd": _vec(snap.arm_qd)},
                "base_pose": _vec(snap.base_pose),
                "gripper": {
                    "width": round(float(snap.gripper_width), 4),
                    "force": round(float(snap.gripper_force), 2),
                    "closed": bool(snap.gripper_closed),
                    "holding": bool(snap.holding),
                },
                "laser": {
                    "on": bool(laser.on),
                    "confirmed": bool(laser.confirmed),
                    "yaw": round(float(laser.yaw), 4),
                    "pitch": round(float(laser.pitch), 4),
                },
                "mark": _vec(mark),
                "place_mark": _vec(task.place_mark),
                "target": None
                if target is None or len(target) == 0
                else {"points": len(target), "centroid": _vec(target.mean(axis=0))},
                "grasps": None
                if cursor is None
                else {
                    "clusters": len(cursor.clusters.clusters),
                    "sizes": [len(c) for c in cursor.clusters.clusters],
                    "cluster": cursor.cluster,
                    "candidate": cursor.candidate,
                    "describe": cursor.describe(),
                },
                "current": None if cursor is None else grasp_summary(cursor.current),
                "timings": {k: round(float(v), 4) for k, v in task.timings.items()},
                "failure": None
                if self.failure is None
                else {"kind": self.failure.kind, "message": self.failure.message},
                "lease": {"held": lease.held, "holder": lease.holder, "source": lease.source},
            }
        return out
