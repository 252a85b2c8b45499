"""Jeeves' centroid approach (003 section IV) on the simulated robot: the scooter drives
until the target sits at the arm's grasping spot, and keeps sight of it on the way."""

from __future__ import annotations

import numpy as np

from laserpick.behaviours import Behaviours
from laserpick.bench.protocols import jeeves_scene
from laserpick.bench.referee import Referee
from laserpick.pipeline.cloud import fuse
from laserpick.pipeline.perceive import perceive
from laserpick.robot.sim.robot import SimRobot
from laserpick.robot.sim.truth import Captured
from laserpick.types import Failure


def test_the_centroid_approach_keeps_sight_of_the_object_through_its_last_turn():
    """Jeeves' approach to a can on the near left of its table ends turning right; the
    scooter still turns while it stops, and the last look must follow it by the odometry:
    looking where the can had been, the stopped scooter would see nothing."""
    robot = SimRobot(jeeves_scene("soda_can", "loc1"), realtime=False)
    try:
        robot.sim.settle(0.5)
        frames, labels = robot.capture_with_labels()
        top = Captured(robot, frames, labels).visible_top(fuse(frames), "soda_can")
        assert top is not None
        beh = Behaviours(robot)
        out = beh.approach(perceive(frames, point=top))
        assert not isinstance(out, Failure), out
        seen = out.target_points.mean(axis=0)
        truth = Referee(robot).position("soda_can")
        assert np.linalg.norm(seen[:2] - truth[:2]) < 0.03  # it is the can, where it stands
        spot = np.array(beh.settings.approach.grasp_spot)
        assert abs(truth[0] - spot[0]) < 0.1 and abs(truth[1] - spot[1]) < 0.25
    finally:
        robot.close()
