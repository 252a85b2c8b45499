"""Jeeves' centroid approach (003 section IV): drive the scooter until the target sits at
the arm's grasping spot, re-perceiving it as the scooter moves."""

from __future__ import annotations

import numpy as np

from laserpick.behaviours.guarded_motion import GuardedMotion
from laserpick.pipeline.approach import centroid_approach
from laserpick.pipeline.perceive import Perception, perceive
from laserpick.transforms import invert, planar_pose
from laserpick.types import Failure

__all__ = ["Approaching"]


class Approaching(GuardedMotion):
    """The drive to the target (`approach`)."""

    def approach(self, perception: Perception) -> Perception | Failure:
        """Jeeves' centroid approach (003 section IV): drive the base until the perceived
        target's centroid sits at the arm's grasping spot, re-perceiving it every
        `approach_period` as the scooter moves (where to look comes from the wheel
        odometry: the target's top, a point on its surface). Returns the last perception of
        the target, for the grasp."""
        if perception.segmentation is None:
            return Failure("precondition", "There is no target to drive to.")
        b = self.settings.behaviour
        pose = self.robot.base_pose()
        for _ in range(b.approach_max_steps):
            if self.should_stop():
                self.robot.drive(0.0, 0.0, 0.1)
                return Failure("execute", "The drive to the object was cancelled.")
            points = perception.target_points.astype(float)
            centroid = points.mean(axis=0)
            top = points[points[:, 2] > points[:, 2].max() - 0.01].mean(axis=0)
            cmd = centroid_approach(centroid, self.settings.approach)
            if cmd.done:
                self.robot.drive(0.0, 0.0, 0.1)
                self.robot.sleep(1.0)  # the ramp down; then look once more, at rest
            else:
                self.robot.drive(cmd.v, cmd.w, 0.5)
                self.robot.sleep(b.approach_period)
            # The scooter moved since the last look (in the ramp down too: turning at 0.46
            # rad/s, by 13 degrees): where the target's top is now comes from the odometry.
            new_pose = self.robot.base_pose()
            moved = invert(planar_pose(*new_pose)) @ planar_pose(*pose)
            pose = new_pose
            perception = perceive(self.robot.capture(), point=(moved @ np.append(top, 1.0))[:3])
            if perception.segmentation is None:
                self.robot.drive(0.0, 0.0, 0.1)
                return Failure("detect_laser", "I lost sight of the object.")
            if cmd.done:
                return perception
        self.robot.drive(0.0, 0.0, 0.1)
        return Failure("execute", "The scooter did not reach the object.")
