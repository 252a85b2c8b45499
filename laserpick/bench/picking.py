"""The scripted operator of the benchmarks, working through the `Session` as every input does.

It plays the user of 004's experiments: it looks at the scene (the simulator's truth says
where each object is and how it looks from the cameras), aims the laser at an object's visible
top with hand-tremor noise, confirms, and, in manual selection, steps through the grasp
clusters to one on the object it meant, the way a person looking at the outlines over what
they see of the objects would. Every
command goes through the session's methods with `Actor("bench")`; the pipeline behind it never
sees the truth. The `Referee` then scores what happened, and the experimenter (`tidy`) resets
what a helper in the lab would: the basket emptied, a stuck arm moved home by hand.

Units: m, s and rad; points in `base` unless a name says `world`.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from laserpick.behaviours import warm_drop_postures
from laserpick.bench.attempts import Attempt, motion_timings, stage_timings
from laserpick.bench.referee import Referee, View
from laserpick.pipeline.balance import hold_lever
from laserpick.pipeline.rest_poses import at_rest
from laserpick.robot.sim.robot import SimRobot
from laserpick.robot.sim.scenes import Scene
from laserpick.server.session import (
    HOLDING_STATES,
    Actor,
    Selection,
    Session,
    StrategyName,
    TaskState,
)
from laserpick.settings import Settings, get_settings
from laserpick.types import Failure

BENCH = Actor("bench")
#: Hand tremor: the aim's angular noise, standard deviation (rad). About 5 mm at 1 m, a
#: steady hand resting on the scooter's armrest. Ours; 004 does not measure it.
TREMOR_STD = math.radians(0.3)
#: Marks the operator makes again after the mark itself failed (the dots missed, or no object
#: under them), as 004's users re-aimed.
REMARKS = 2
#: Times the operator aims before confirming, until the dot they see lies on the object, or
#: within DOT_ON_SPOT (m) of a place spot. A dot that grazed past a low object's top onto
#: the wall behind is seen and re-aimed: a person confirms once they see the dot on the
#: object. Aimed from the seat at the 87 cm counter, 8 cm below the pointer, the beam meets
#: the top so flat that the hand's tremor (0.3 deg) moves the dot 12 cm along it.
AIMS = 5
DOT_ON_SPOT = 0.03
#: Longest a session job may take (s of wall time) before the run is declared hung.
JOB_TIMEOUT = 600.0
#: The farthest (m) a user choosing by hand lets a grasp hold an object off the middle of
#: what they see of it: an object held far from its centre of mass, across the line between
#: the fingers, swings about that line in the pads (a TV remote held near one end turns onto
#: its side), and a person, who cannot see the centre of mass, holds it across its middle.
LEVER_MAX = 0.02
#: How near (m) a cluster's best grasp must lie to one the user saw fail to plan for them to
#: take it for the same and pass it by: half 004's cluster bound (section 7.2). Neighbouring
#: clusters' best grasps along a remote lay 1.6-3 cm apart.
UNPLANNED_NEAR = 0.01
#: The session's progress messages at the moment the hand lets go of the object.
RELEASED = frozenset({"Released into the basket.", "Placed."})


def trial_settings(seed: int) -> Settings:
    """The settings of one trial: the defaults, with the session's and the sensors' random
    draws seeded by the trial's seed (so a trial replays exactly)."""
    settings = get_settings().model_copy(deep=True)
    settings.server.seed = seed
    settings.sensor.seed = seed
    return settings


def open_session(scene: Scene, seed: int, settle: float = 0.5) -> Session:
    """A session on a headless (deterministic, faster than real time) robot in `scene`, its
    drop postures worked out before the trial as `laserpick serve` does as it starts
    (`warm_drop_postures`): not charged to the first pick for the basket's planning."""
    settings = trial_settings(seed)
    robot = SimRobot(scene, realtime=False, settings=settings)
    robot.sim.settle(settle)
    warm_drop_postures(settings.behaviour).join()
    return Session(robot, settings=settings)


class ScriptedOperator:
    """The user and the experimenter of one trial, on one session.

    rng: the operator's own draws (tremor, choices), seeded per trial (and per task, where
        a protocol calls `begin_task`).
    tremor: the aim's angular noise, standard deviation (rad).
    """

    def __init__(
        self,
        session: Session,
        rng: np.random.Generator,
        *,
        trial: int = 0,
        seed: int = 0,
        tremor: float = TREMOR_STD,
    ) -> None:
        self.session = session
        self.rng = rng
        self.trial, self.seed, self.tremor = trial, seed, tremor
        self.actor = BENCH
        self.referee = Referee(session.robot)
        self._tasks = 0
        #: Per object, where (m, `world`) grasps the user chose failed to plan: on their next
        #: try they toggle past them, as a person who saw "none could be planned" would.
        self._unplanned: dict[str, list[np.ndarray]] = {}
        #: The look the user aimed their last mark by (None: they aimed at a given point).
        self._view: View | None = None
        #: How the user backs the scooter up straight by so many m from where they parked for
        #: the task, and whether they parked there: the protocols that drive set it for each
        #: task (None: the user stays where they are).
        self.back_up: Callable[[float], bool] | None = None
        #: How the user parks so many m to the scooter's left (negative: right) of where they
        #: parked for the task, and whether they parked there (set as `back_up` is).
        self.park_left: Callable[[float], bool] | None = None
        self._events: list[dict[str, Any]] = []
        # Stamped with the simulated time as they happen (listeners run on the emitting thread).
        session.on_event(lambda e: self._events.append({**e, "sim_time": self._sim_time()}))

    @property
    def robot(self) -> SimRobot:
        return self.session.robot

    def _sim_time(self) -> float:
        return float(self.robot.sim.snapshot().time)

    # --- talking to the session -------------------------------------------------------------

    def wait(self) -> None:
        """Wait until the session's job (if any) is over."""
        end = time.monotonic() + JOB_TIMEOUT
        while self.session.busy:
            if time.monotonic() > end:
                self.session.cancel(BENCH)
                raise RuntimeError(f"a session job ran over {JOB_TIMEOUT:.0f} s; cancelled")
            time.sleep(0.002)

    def _events_since(self, k: int, name: str) -> list[dict[str, Any]]:
        return [e for e in self._events[k:] if e.get("name") == name]

    def aim(self, point: np.ndarray, on: str | None = None, watched: bool = False) -> None:
        """Aim the laser at `point` (m, `base`), off by the hand's tremor. on: an object the
        user looks for the dot on; watched: the user looks for the dot within DOT_ON_SPOT of
        `point`. Until it lies there, they aim again (up to AIMS times)."""
        for _ in range(AIMS):
            self.session.aim_at(BENCH, point, "base")
            dyaw, dpitch = self.rng.normal(0.0, self.tremor, 2)
            self.session.nudge(BENCH, float(dyaw), float(dpitch))
            if on is not None and not self.referee.dot_on(on):
                continue
            if watched and not self.dot_near(point):
                continue
            return

    def dot_near(self, point: np.ndarray) -> bool:
        """Whether the aiming beam's dot lies within DOT_ON_SPOT of `point` (m, `base`)."""
        hits = self.robot.laser_hits()
        return bool(hits) and np.linalg.norm(self.referee.to_base(hits[0]) - point) < DOT_ON_SPOT

    def drive(self, v: float, w: float) -> None:
        """Hold the drive command (m/s, rad/s) for 0.1 s of robot time: a joystick."""
        self.session.drive(BENCH, v, w, 0.3)
        self.robot.sleep(0.1)

    def base_pose(self) -> np.ndarray:
        """Where the scooter stands, (x, y, yaw) in `world`: the user sees it."""
        return self.robot.base_pose()

    def begin_task(self, task: int) -> None:
        """Seed the user's, the session's and the cameras' draws for task `task` of the trial
        from (the trial's seed, `task`) alone. Without it, whatever an earlier task did (where
        an object ended up, how many grasps were sampled) shifts every later draw, and a change
        that mends one task sends the rest of its trial other ways. The world the task finds
        still depends on the tasks before it."""
        user, session, sensors = np.random.SeedSequence([self.seed, task]).spawn(3)
        self.rng = np.random.default_rng(user)
        self.session.reseed(session)
        self.robot.reseed_sensors(sensors)

    # --- one attempt ------------------------------------------------------------------------

    def new_attempt(self, instance: str, selection: Selection, strategy: StrategyName) -> Attempt:
        placement = self.robot.sim.scene.placement(instance)  # type: ignore[union-attr]
        self._tasks += 1
        return Attempt(
            self.trial,
            self.seed,
            instance,
            placement.model.name,
            placement.surface,
            selection,
            strategy,
            task=self._tasks,
        )

    def mark(self, rec: Attempt, aim: np.ndarray | None = None) -> bool:
        """Mark `rec.instance` until the session has grasps for it (True), or give up after
        REMARKS re-marks, or on a failure that re-marking does not cure (the session then
        rests idle; `rec` says why). aim: where to aim (m, `base`; default: the middle of the
        object's visible top, where a person would aim)."""
        s = self.session
        # Aiming at the object, the user looks for the dot on it; aiming at a given point
        # (002's laser scan, which tries points up to the object's edges), they do not.
        on = rec.instance if aim is None else None
        self._view = None
        aim = self._look(rec.instance) if aim is None else aim
        if aim is None:
            rec.fail("detect_laser", "no camera sees the object")
            return False
        for _ in range(REMARKS + 1):
            rec.marks += 1
            self.aim(aim, on=on)
            k = len(self._events)
            s.confirm(BENCH)
            self.wait()
            rec.timings = stage_timings(self._events_since(k, "job"))
            if s.state == TaskState.GRASPS_READY:
                rec.failure, rec.message = None, ""  # an earlier mark's miss is behind us
                return True
            failure = s.failure or Failure("execute", f"the session rests {s.state.value}")
            rec.fail(failure.kind, failure.message)
            asked = failure.back_up if on is not None and not rec.backed_up else None
            if asked is not None and self.back_up is not None:
                # The robot asked the user to back up before the arm moved: they do, once a
                # try, as a person told so would, and mark again from there.
                s.cancel(BENCH)
                rec.backed_up = asked
                if not self.back_up(asked):  # could not park there
                    self._view = None
                    return False
                aim = self._look(rec.instance)
                if aim is None:  # no camera sees it from there
                    return False
                continue
            if s.state != TaskState.AIMING:  # found the object, but no grasp: not the aim
                break
        s.cancel(BENCH)
        return False

    def _look(self, instance: str) -> np.ndarray | None:
        """Look at the scene from where the user sits (kept as `_view`), and where they aim
        at `instance`: the middle of its visible top (m, `base`); None where no camera sees
        it."""
        self._view = self.referee.view()
        return self._view.top(instance)

    def choose(self, instance: str, seen: dict[str, np.ndarray]) -> None:
        """Manual selection (004 section 7.2): step through the clusters, best first, to the
        first whose best grasp closes on `instance` across its middle, as a person who sees
        the gripper's outline over the object would hold it; else to the first on `instance`
        at all; none such: back to the system's choice. What the user sees of each object
        is `seen`, the points the cameras saw on it (m, `base`; `View.points`): a grasp is
        on the object whose seen points lie nearest its TCP, within 4 cm, and across its
        middle with a `lever` of at most LEVER_MAX about the middle of its seen extent
        (`seen_middle`). Clusters where a choice failed to plan before are passed by while
        another on `instance` is left: a person does not choose again what they saw fail."""
        s = self.session
        failed = self._unplanned.get(instance, [])
        middle = seen_middle(seen[instance]) if instance in seen else None
        best: tuple[tuple[bool, bool], int] | None = None  # (tried, off balance), cluster
        for k in range(s.status()["grasps"]["clusters"]):
            s.select_grasp(BENCH, k, 0)
            pose = np.asarray(s.status()["current"]["pose"])
            if middle is None or self.referee.object_at(pose[:3, 3], seen) != instance:
                continue
            at = self.referee.to_world(pose[:3, 3])
            tried = any(np.linalg.norm(at - p) < UNPLANNED_NEAR for p in failed)
            rank = (tried, hold_lever(pose, middle) > LEVER_MAX)
            if rank == (False, False):
                return
            if best is None or rank < best[0]:
                best = (rank, k)
        if best is not None:
            s.select_grasp(BENCH, best[1], 0)
        else:
            s.auto_grasp(BENCH)

    def saw_unplanned(self, instance: str, position: np.ndarray) -> None:
        """The user saw the grasp they chose at `position` (m, `base`) on `instance` fail to
        plan: `choose` passes its cluster by from now on."""
        self._unplanned.setdefault(instance, []).append(self.referee.to_world(position))

    def pick(self, rec: Attempt, aim: np.ndarray | None = None) -> bool:
        """Mark `rec.instance`, choose a grasp the way `rec.selection` says, and execute.
        In pick-and-drop the session carries the object to the basket and stows; in
        pick-and-place it holds it up and awaits the place mark. True when the object was
        lifted; `rec` has the verdict on detection and the failure, if any."""
        s = self.session
        s.set_mode(BENCH, selection=rec.selection, strategy=rec.strategy)  # type: ignore[arg-type]
        if not self.mark(rec, aim):
            return False
        before = self.referee.all_object_points()  # judge grasps by the scene they were made for
        centre = self.referee.centre_of_mass(rec.instance)  # the referee's, for `rec.lever`
        if rec.selection == "manual":
            # The user chooses by what they see: the look they aimed by (nothing has moved
            # since), or, where they aimed at a given point, a look now.
            self.choose(rec.instance, (self._view or self.referee.view()).points())
        chosen = np.asarray(s.status()["current"]["position"])
        k = len(self._events)
        t_sim = self._sim_time()
        s.execute(BENCH)
        self.wait()
        if self._parks_aside(rec):
            return self._pick_from_aside(rec, aim, stage_timings(self._events_since(k, "job")))
        released = self._released_at(k)
        execute_sim = (self._sim_time() if released is None else released) - t_sim
        done = self._events_since(k, "job")
        rec.timings = stage_timings(done, execute_sim)  # the task's last job reports all its stages
        rec.timings |= motion_timings(self._events[k:], t_sim, released)
        executed = self._events_since(k, "grasp_executed")
        if executed:
            chosen = np.asarray(executed[-1]["grasp"]["position"])
            rec.lever = round(hold_lever(np.asarray(executed[-1]["grasp"]["pose"]), centre), 4)
            closed = executed[-1].get("closed_width")
            if closed is not None:
                rec.grip = (executed[-1]["grasp"]["width"], closed)
        rec.detected = self.referee.object_at(chosen, before) == rec.instance
        if rec.selection == "manual" and not executed and s.failure and s.failure.kind == "ik_plan":
            self.saw_unplanned(rec.instance, chosen)
        lifted = any(e.get("state") == "holding" for e in self._events_since(k, "state"))
        rec.grasped = lifted and rec.detected  # what was lifted was the marked object
        if executed and not rec.detected:
            rec.fail("wrong_object", "the grasp executed was on another object")
        elif s.failure is not None:
            rec.fail(s.failure.kind, s.failure.message)
        return rec.grasped and rec.detected

    def _parks_aside(self, rec: Attempt) -> bool:
        """Whether the user re-parks to a side and tries again within `rec`: the robot said,
        before the arm moved, where to park for its cameras to see the way it needs
        (`Failure.park_left`), and the user has not re-parked within this try yet."""
        failure = self.session.failure
        asked = None if failure is None else failure.park_left
        return asked is not None and not rec.parked_aside and self.park_left is not None

    def _pick_from_aside(
        self, rec: Attempt, aim: np.ndarray | None, spent: dict[str, float]
    ) -> bool:
        """Park where the robot asked (`_parks_aside`), once a try, as a person told so would,
        and mark, choose and pick again from there (`pick`). The seconds the try spent
        before (`spent`, per stage: its planning, mostly) stay in `rec`'s timings."""
        failure, s = self.session.failure, self.session
        assert failure is not None and failure.park_left is not None and self.park_left
        s.cancel(BENCH)
        rec.parked_aside = failure.park_left
        if not self.park_left(failure.park_left):
            rec.timings = spent
            rec.fail(failure.kind, failure.message)
            return False
        lifted = self.pick(rec, aim)
        for stage, seconds in spent.items():
            rec.timings[stage] = rec.timings.get(stage, 0.0) + seconds
        return lifted

    def _released_at(self, k: int) -> float | None:
        """Simulated time (s) the job begun at event `k` let go of the object (dropped or set
        down), None if it has not: the attempt's execution ends there, not after the stow."""
        for e in self._events[k:]:
            if e.get("name") == "progress" and e.get("message") in RELEASED:
                return float(e["sim_time"])
        return None

    def pick_and_drop(self, rec: Attempt, aim: np.ndarray | None = None) -> Attempt:
        """One 004 section 8.1 attempt: success is the simulator's word that the marked
        object lies in the basket (`tidy` then takes it out, as a helper empties the basket).
        aim: as for `mark`."""
        self.session.set_mode(BENCH, mode="pick_and_drop")
        if self.pick(rec, aim) and rec.failure is None:
            self.robot.sleep(0.5)
            rec.success = self.referee.in_basket(rec.instance)
            if not rec.success:
                rec.fail("execute", "the object did not land in the basket")
        # 004 section 8.1 counts a grasp as successful once the object is in the basket: one
        # lifted but dropped on the way, or kept because no way to the basket was found, is not.
        rec.grasped = rec.success
        self.tidy()
        return rec

    def place(self, spot: np.ndarray) -> Placed:
        """Mark `spot` (m, `base`) as where the held object goes, and let the session place it."""
        s = self.session
        if s.state not in HOLDING_STATES:  # holding after a failed place: aiming marks again
            # Why the hand emptied, where the session said (it fell while the user drove).
            nothing = Failure("precondition", f"nothing to place (the session is {s.state.value})")
            return Placed(s.failure or nothing, None)
        self.aim(spot, watched=True)
        hits = self.robot.laser_hits()
        hit = self.referee.to_base(hits[0]) if hits else None
        s.confirm(BENCH)
        self.wait()
        if hit is None and s.failure is None:
            return Placed(Failure("detect_laser", "the laser lit nothing"), None)
        return Placed(s.failure, hit)

    # --- the experimenter -------------------------------------------------------------------

    def tidy(self) -> None:
        """Reset what an attempt left: every object in the basket is taken out of the scene
        (the fetched one, or another a wrong grasp dropped there: it would stand in the beam's
        way), so is one that missed the basket and came to rest on the scooter (across the
        basket's rim, on the deck: a helper would not leave it there for the next drops to
        land on), so is an object still in the hand, an arm the session left neither stowed
        nor standing by is moved home by hand, and the session is told."""
        s, robot = self.session, self.robot
        for name in self.referee.instances():
            if self.referee.in_basket(name) or self.referee.rests_on_scooter(name):
                self.referee.take_out(name)
        if s.state in (TaskState.HOLDING, TaskState.AWAITING_PLACE) or robot.gripper_state().closed:
            # What the hand holds is found before it opens: in the second the gripper takes,
            # a held object falls clear of the fingers, and would lie where the scooter
            # stands, in the way of the next parking.
            in_hand = (
                [n for n in self.referee.instances() if self.referee.near_hand(n)]
                if s.behaviours.held is not None
                else []
            )
            robot.gripper(False)
            robot.sleep(1.0)
            for name in in_hand:
                self.referee.take_out(name)
        if not at_rest(robot.joint_state().q):
            # By hand, as the experimenter would: a stow from here has no cloud to plan
            # around (the session, which had one, did not get the arm home), and can drive
            # the fingers into the furniture.
            self.referee.move_arm_home()
        s.resync(BENCH)


def seen_middle(points: np.ndarray) -> np.ndarray:
    """The middle of what the cameras saw of an object (m, `base`): the middle of the bounds
    of its seen `points` (n, 3). Where a person would take an object's middle to be: its
    visible extent, not its centre of mass, which no one sees."""
    pts = np.asarray(points, dtype=float)
    return (pts.min(axis=0) + pts.max(axis=0)) / 2


@dataclass(frozen=True)
class Placed:
    """How a place went: the session's failure (None: placed), and where the laser dot was
    (m, `base`, simulator truth) when the place mark was confirmed."""

    failure: Failure | None
    hit: np.ndarray | None
