"""`Session`: the task state machine around one robot, assembled from its parts."""

from __future__ import annotations

import math

import numpy as np

from laserpick.behaviours import Behaviours
from laserpick.pipeline.recall import ViewMemory
from laserpick.robot.interface import Robot
from laserpick.server.journal import Journal
from laserpick.server.session.core import Findings
from laserpick.server.session.grasp_choice import GraspChoice
from laserpick.server.session.heap_keeper import HeapKeeper
from laserpick.server.session.jobs import Jobs
from laserpick.server.session.laser_commands import LaserCommands
from laserpick.server.session.motion import MotionCommands
from laserpick.server.session.states import TaskState
from laserpick.server.session.status import StatusReads
from laserpick.server.session.task_commands import TaskCommands
from laserpick.server.session.watchdog import Watchdog
from laserpick.settings import Settings, get_settings


class Session(
    LaserCommands,
    GraspChoice,
    TaskCommands,
    MotionCommands,
    Jobs,
    Watchdog,
    HeapKeeper,
    StatusReads,
):
    """The task state machine around one robot.

    robot: any `Robot`, whose pointer the session aims (`robot.laser`); in real time
    (`robot.realtime`) views on the way are kept on a thread of their own. journal: where
    every command and outcome is recorded. settings: default `get_settings()`.
    """

    def __init__(
        self,
        robot: Robot,
        *,
        journal: Journal | None = None,
        settings: Settings | None = None,
    ) -> None:
        self._init_core(settings or get_settings(), journal)
        self._init_worker()
        self._init_views()
        self._init_foresight()
        self._init_watchdog()
        self._init_drive()
        self.mode = "pick_and_drop"
        self.selection = "auto"
        self.strategy = "gpd"
        self._rng = np.random.default_rng(self.settings.server.seed)
        self._attach(robot)
        self._start_watchdog()
        self._start_heap_keeper()

    def _attach(self, robot: Robot) -> None:
        """Start afresh on `robot`: no task, nothing captured, no views kept."""
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
        self.task = Findings()
        self.failure = None
        self.message = "Ready. Aim the laser at an object."
        self._projection = None
        self._capture = None
        self._foreseen = None
        p = self.settings.perception
        self.views = ViewMemory(
            p.recall_spacing,
            math.radians(p.recall_turn_deg),
            p.recall_views,
            p.recall_max_age,
            p,
        )

    def close(self) -> None:
        """Halt, stop the worker, the views and foresight threads and the watchdog, and close
        the robot."""
        self._closing.set()
        self._cancel.set()
        self.robot.halt()
        self._worker.shutdown(wait=True, cancel_futures=True)
        self._close_views()
        self._close_foresight()
        self._stop_watchdog()
        self._stop_heap_keeper()
        self.robot.close()

    def reseed(self, seed: int | np.random.SeedSequence) -> None:
        """Draw the planner's and the grasp sampler's random numbers from here on as a fresh
        session seeded with `seed` would. Between jobs only: they draw from it."""
        if self.busy:
            raise RuntimeError("the session is busy; reseed it between jobs")
        # In place: the behaviours hold the same generator.
        self._rng.bit_generator.state = np.random.default_rng(seed).bit_generator.state
