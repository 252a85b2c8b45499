"""Views kept on the way: captures taken while driving (`pipeline.recall.ViewMemory`), recalled
where the scooter stops to fill its fixed cameras' blind spots, and what stands around the
arm built from a capture and them.

Frames: points in `base` (m) as the scooter stands now.
"""

from __future__ import annotations

import logging
from concurrent.futures import Future, ThreadPoolExecutor

import numpy as np

from laserpick.pipeline.collision import CollisionChecker
from laserpick.pipeline.recall import Recalled
from laserpick.pipeline.rest_poses import at_rest
from laserpick.robot.interface import Robot
from laserpick.server.session.captures import Capture, CaptureReads

log = logging.getLogger(__name__)


class KeptViews(CaptureReads):
    """Keeps views while driving, on the views thread, and recalls them."""

    def _init_views(self) -> None:
        #: Views kept while driving are taken here in real time, so a drive command never
        #: waits on a capture.
        self._view_pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="laserpick-views")
        self._view_job: Future[None] | None = None

    def _close_views(self) -> None:
        self._view_pool.shutdown(wait=True, cancel_futures=True)

    def _keep_view(self) -> None:
        """On the way, keep a view each `recall_spacing` m or `recall_turn_deg` (the
        `ViewMemory`): where the scooter stops, its fixed cameras have blind spots that were
        in view on the way in. In real time the capture runs on its own thread, so the drive
        command does not wait on it; headless, it runs at once, so a run replays exactly."""
        robot = self.robot
        # Only with the arm at rest (stowed or standing by) and the hand empty, as they are
        # when a grasp is planned: a view never shows the arm reaching out, nor an object
        # riding along in the hand. Its own points are left out by the joint angles kept.
        resting = at_rest(robot.joint_state().q)
        if not resting or robot.gripper_state().holding or not self.views.due(robot.base_pose()):
            return
        if not robot.realtime:
            self._take_view(robot)
        elif self._view_job is None or self._view_job.done():
            self._view_job = self._view_pool.submit(self._take_view, robot)

    def _take_view(self, robot: Robot) -> None:
        pose, q = robot.base_pose(), robot.joint_state().q
        try:
            frames = robot.capture()
        except Exception:  # a view is extra evidence; a drive goes on without it
            log.exception("A view on the way could not be captured.")
            return
        if robot is self.robot:  # not a view of a robot replaced meanwhile
            self.views.add(frames, pose, q)

    def recalled(self) -> Recalled:
        """The views kept on the way in, in `base` as the scooter stands now."""
        return self.views.recall(self.robot.base_pose(), self.robot.joint_state().stamp)

    def surroundings(self, capture: Capture | None) -> CollisionChecker | None:
        """What stands around the arm in `capture`, a fresh one: the way home is planned
        around it, since a cloud without it lets the planner through furniture. The arm's
        own points are left out, and the space it fills counts as seen; the views kept on
        the way in add what they saw where no camera sees now. None without a capture (the
        cameras failed): the arm must still go home, as it did before it looked (rising
        first, `Behaviours.go_ready`)."""
        if capture is None:
            return None
        recalled = self.recalled()
        blind = recalled.blind_points(capture.frames)
        return CollisionChecker(
            np.vstack([capture.cloud.points, blind]) if len(blind) else capture.cloud.points,
            margin=self.settings.motion.clearance,
            q_self=self.robot.joint_state().q,
            frames=(*capture.frames, *recalled.frames),
        )
