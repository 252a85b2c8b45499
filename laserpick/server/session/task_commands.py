"""The task's commands: execute (pick, or drop what the hand holds), cancel, resync after a
person stepped in, the task and selection modes, and putting a new robot in."""

from __future__ import annotations

from collections.abc import Callable

from laserpick.robot.interface import Robot
from laserpick.server.session.core import SessionCore
from laserpick.server.session.states import (
    Actor,
    Conflict,
    Mode,
    Selection,
    StrategyName,
    TaskState,
)


class TaskCommands(SessionCore):
    """Commands on the task as a whole."""

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
                self._forget_task()
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
            self._forget_task()
            self.failure = None
            state = self._resting_state()
            self._set(state, "Holding." if state == TaskState.HOLDING else "Ready.")
            self._record(actor, "resync", "ok")

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

    def replace_robot(self, actor: Actor, build: Callable[[], Robot], scene: str) -> None:
        """Put in the robot `build()` makes, in a new world named `scene` (a simulator's
        scene reset), and start afresh on it. It is built outside the session's lock (a
        simulator takes a second or two), so state reads and the e-stop stay quick
        meanwhile; the old robot is closed. Conflict while busy or e-stopped."""
        with self._scene_lock:
            with self._lock:
                self._require_robot_change(actor)
            new = build()
            with self._lock:
                try:
                    self._require_robot_change(actor)
                except Conflict:
                    new.close()
                    raise
                old = self.robot
                self._attach(new)
            old.close()
            for fn in list(self._scene_listeners):
                fn(new)
            self._job_freed.set()  # the old world's arrays are free now
            with self._lock:
                self._emit("scene", scene=scene, message=f"Scene {scene!r} loaded.")
                self._record(actor, "scene", "ok", message=scene)

    def _require_robot_change(self, actor: Actor) -> None:
        if self.busy:
            raise self._refuse(actor, "scene", f"busy ({self._job_name}); cancel it first")
        if self.estopped:
            raise self._refuse(actor, "scene", "the e-stop is latched; reset it first")
