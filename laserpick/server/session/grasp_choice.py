"""The grasp cursor's commands: step through the clusters and their candidates, select one,
or go back to the system's choice (004 section 7.2)."""

from __future__ import annotations

from typing import Literal

from laserpick.pipeline.selection import GraspCursor
from laserpick.server.session.core import SessionCore
from laserpick.server.session.states import Actor, TaskState


class GraspChoice(SessionCore):
    """Moving the current grasp while grasps are ready."""

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
