"""The simulated robot: a UR5 on a mobility scooter in MuJoCo, one implementation of `Robot`.

The model (scooter, arm, gripper, sensors, projector), scenes and objects, the physics loop,
the depth cameras, arm control (mink) and the laser's ray casts. Simulator truth is read here
to simulate; what scores and plays the operator reads it through `robot.sim.truth`.
"""

from laserpick.robot.sim.robot import SimRobot
from laserpick.robot.sim.scenes import Scene, SceneError, load_scene, parse_scene

__all__ = ["Scene", "SceneError", "SimRobot", "load_scene", "parse_scene"]
