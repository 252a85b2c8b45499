"""The session's status as `schemas.Status`: what a console shows, read at 30 Hz.

Points in `base` (m), angles (rad), times (s); numbers rounded for the wire.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from laserpick.pipeline.selection import GraspCursor
from laserpick.robot.interface import GripperState, LaserState
from laserpick.server import schemas
from laserpick.server.session.core import SessionCore
from laserpick.types import Grasp


def rounded(a: np.ndarray | None, digits: int = 4) -> list[float] | None:
    """`a`'s values as a flat list of floats rounded to `digits`; None stays None."""
    return None if a is None else [round(float(x), digits) for x in np.ravel(a)]


def grasp_summary(g: Grasp) -> dict[str, Any]:
    """A grasp as JSON: pose (4x4, `base`), width (m), score and its five factors, and
    whether its pads meet the object about their middle (such grasps are offered first)."""
    scores = g.scores
    return {
        "pose": [rounded(row) for row in g.pose],
        "position": rounded(g.position),
        "approach": rounded(g.approach),
        "width": round(float(g.width), 4),
        "score": round(float(g.score), 4),
        "factors": None
        if scores is None
        else {k: round(float(getattr(scores, k)), 4) for k in ("Cw", "Cj", "Ca", "Cs", "Cp")},
        "cluster": g.cluster,
        "pads_centred": g.pads_centred,
    }


def _gripper(state: GripperState) -> schemas.GripperStatus:
    return schemas.GripperStatus(
        width=round(float(state.width), 4),
        force=round(float(state.force), 2),
        closed=bool(state.closed),
        holding=bool(state.holding),
    )


def _laser(state: LaserState) -> schemas.LaserStatus:
    return schemas.LaserStatus(
        on=bool(state.on),
        confirmed=bool(state.confirmed),
        yaw=round(float(state.yaw), 4),
        pitch=round(float(state.pitch), 4),
    )


def _grasps(cursor: GraspCursor) -> schemas.GraspsStatus:
    return schemas.GraspsStatus(
        clusters=len(cursor.clusters.clusters),
        sizes=[len(c) for c in cursor.clusters.clusters],
        cluster=cursor.cluster,
        candidate=cursor.candidate,
        describe=cursor.describe(),
    )


def _target(points: np.ndarray | None) -> schemas.TargetStatus | None:
    if points is None or len(points) == 0:
        return None
    return schemas.TargetStatus(points=len(points), centroid=rounded(points.mean(axis=0)))


class StatusReads(SessionCore):
    """The status, built from one reading of the robot and the task under the lock."""

    def status_model(self) -> schemas.Status:
        """Everything a console shows (`GET /state`). Cheap: read at 30 Hz."""
        robot = self.robot.state()
        laser = self.robot.laser.state
        with self._lock:
            task = self.task
            cursor = task.cursor
            perception = task.perception
            mark = perception.mark.point if perception is not None and perception.mark else None
            target = perception.target_points if perception is not None else None
            lease = self.lease.info()
            failure = self.failure
            return schemas.Status(
                state=self.state.value,
                busy=self.busy,
                job=self._job_name if self.busy else None,
                message=self.message,
                mode=self.mode,
                selection=self.selection,
                strategy=self.strategy,
                estopped=bool(robot.estopped),
                drive_stop=robot.drive_stop or None,
                sim_time=round(float(robot.stamp), 4),
                rtf=round(float(robot.rtf), 3),
                read_at=round(float(robot.read_at), 4),
                joints=schemas.JointStatus(q=rounded(robot.joints.q), qd=rounded(robot.joints.qd)),
                base_pose=rounded(robot.base_pose),
                gripper=_gripper(robot.gripper),
                laser=_laser(laser),
                mark=rounded(mark),
                place_mark=rounded(task.place_mark),
                target=_target(target),
                grasps=None if cursor is None else _grasps(cursor),
                current=None
                if cursor is None
                else schemas.GraspStatus(**grasp_summary(cursor.current)),
                timings={k: round(float(v), 4) for k, v in task.timings.items()},
                failure=None
                if failure is None
                else schemas.FailureStatus(
                    kind=failure.kind,
                    message=failure.message,
                    back_up=failure.back_up,
                    park_left=failure.park_left,
                ),
                lease=schemas.LeaseStatus(
                    held=lease.held, holder=lease.holder, source=lease.source
                ),
            )

    def status(self) -> dict[str, Any]:
        """`status_model()` as JSON-ready values (what the events stream sends)."""
        return self.status_model().model_dump()
