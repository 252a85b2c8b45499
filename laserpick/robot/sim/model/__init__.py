"""The MJCF of the scooter robot, built in code with MuJoCo's MjSpec from `dims`.

Two models come from the same builders, so they can never disagree about the arm:

* `build_sim_model(scene)`: the world. Ground plane, the scene's surfaces and objects, and the
  scooter on planar base joints (x, y, yaw) carrying the UR5, the gripper, five depth cameras,
  the projector and the laser origin.
* `build_arm_model()`: the arm alone in the `base` frame, on a fixed scooter, with the fingers
  held open. Used by mink IK, Pinocchio cross-checks and collision queries.

`ModelInfo` holds the indices into a compiled sim model that the loop uses every tick.
"""

from laserpick.robot.sim.model.build import (
    build_arm_model,
    build_arm_spec,
    build_sim_model,
    build_sim_spec,
)
from laserpick.robot.sim.model.info import ModelInfo
from laserpick.robot.sim.model.mounts import camera_rotation, depth_intrinsics
from laserpick.robot.sim.model.names import (
    ARM_JOINTS,
    ARM_PREFIX,
    BASE_JOINTS,
    FINGER_JOINTS,
    FLANGE_SITE,
    GRIPPER_ACTUATOR,
    LASER_SITE,
    PROJECTOR_CAMERA,
    SCOOTER_BODY,
    SCOOTER_COLLISION_PREFIX,
    TCP_SITE,
    arm_joint_name,
)

__all__ = [
    "ARM_JOINTS",
    "ARM_PREFIX",
    "BASE_JOINTS",
    "FINGER_JOINTS",
    "FLANGE_SITE",
    "GRIPPER_ACTUATOR",
    "LASER_SITE",
    "PROJECTOR_CAMERA",
    "SCOOTER_BODY",
    "SCOOTER_COLLISION_PREFIX",
    "TCP_SITE",
    "ModelInfo",
    "arm_joint_name",
    "build_arm_model",
    "build_arm_spec",
    "build_sim_model",
    "build_sim_spec",
    "camera_rotation",
    "depth_intrinsics",
]
