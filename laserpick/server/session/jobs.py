"""The jobs, run on the worker thread: perceive the mark, find grasps, pick, drop in the
basket, place at the place mark. A failure returns to a safe resting state with a typed
`Failure` (`retreat`).

Frames: points in `base` (m).
"""

from __future__ import annotations

import time

import numpy as np

from laserpick.behaviours import CARRY_PLANNING, TUCKING_FIRST, Outcome
from laserpick.description import dims
from laserpick.pipeline.cloud import fuse
from laserpick.pipeline.grasp_choice import find_grasps
from laserpick.pipeline.laser_mark import detect_mark
from laserpick.pipeline.perceive import perceive
from laserpick.pipeline.projector import highlight_disc, highlight_points
from laserpick.pipeline.selection import GraspCursor
from laserpick.server.session.foresight import Foresight
from laserpick.server.session.retreat import Retreat
from laserpick.server.session.states import TaskState
from laserpick.server.session.status import grasp_summary
from laserpick.types import Failure, Grasp


class Jobs(Retreat, Foresight):
    """What the worker thread runs for each command that takes time."""

    def _perceive_job(self, point: np.ndarray | None = None) -> None:
        """Capture, find the mark in the IR images, segment. With `point` (a confirming click,
        m in `base`), the mark is that point, worked out in the capture it was aimed in while
        that is still fresh (`foresight`: mostly done before the click)."""
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
                self._forget_task()
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
            recalled=self.recalled(),
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
        out = self.behaviours.pick(grasps, order, to_basket=self.mode == "pick_and_drop")
        if self.behaviours.held is not None:
            # The object has left its place: the views of the way in must not keep it there.
            above = grasps.stands_on + self.settings.behaviour.support_scatter
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
            self._retreat(out.failure)
            return
        with self._lock:
            self._set(TaskState.HOLDING, "Holding the object.")
        if self.mode == "pick_and_drop":
            self._drop_job()
            return
        tucked = self.behaviours.tuck()
        self._count_carry_planning(tucked)
        if not tucked.ok:
            assert tucked.failure is not None
            self._retreat(tucked.failure, tucked=tucked)
            return
        with self._lock:
            self._set(TaskState.AWAITING_PLACE, "Mark where to put it, then confirm.")

    def _drop_job(self) -> None:
        self._retake_held_surroundings()
        b = self.behaviours
        out = b.drop_in_basket()
        self._count_carry_planning(out)
        if out.failure is not None and out.failure.kind == "ik_plan" and b.held is not None:
            # No way to the basket from where the lift left the object (in a narrow gap, say):
            # it is tucked in and carried from there.
            self._progress(TUCKING_FIRST)
            tucked = b.tuck()
            self._count_carry_planning(tucked)
            if not tucked.ok:
                self._retreat(out.failure, tucked=tucked)
                return
            out = b.drop_in_basket()
            self._count_carry_planning(out)
        if not out.ok:
            assert out.failure is not None
            self._retreat(out.failure)
            return
        said = "Dropped in the basket." + (f" {out.caution}" if out.caution else "")
        self.stand_by_and_rest(said)

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
        self._count_carry_planning(out)
        if not out.ok:
            assert out.failure is not None
            self._retreat(out.failure)
            return
        self.stand_by_and_rest("Placed.", placed=out)

    def _count_carry_planning(self, out: Outcome) -> None:
        """Add what `out` spent planning the way of what the hand holds (`CARRY_PLANNING`,
        wall-clock s, the arm standing still meanwhile) to the task's timings."""
        spent = out.timings.get(CARRY_PLANNING, 0.0)
        self.task.timings[CARRY_PLANNING] = self.task.timings.get(CARRY_PLANNING, 0.0) + spent
