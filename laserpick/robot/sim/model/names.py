"""Names of the bodies, joints, sites, cameras and actuators that both robot models share."""

from __future__ import annotations

from laserpick.description import dims

SCOOTER_BODY = "scooter"
ARM_PREFIX = "ur5/"
TCP_SITE = "tcp"
FLANGE_SITE = "flange"
LASER_SITE = "laser/origin"
PROJECTOR_CAMERA = "projector"
BASE_JOINTS = ("base_x", "base_y", "base_yaw")
FINGER_JOINTS = ("finger_left", "finger_right")
GRIPPER_ACTUATOR = "gripper"
SCOOTER_COLLISION_PREFIX = "scooter/"


def arm_joint_name(i: int) -> str:
    """Name of UR5 joint i (0-based) in both models."""
    return ARM_PREFIX + dims.UR5_JOINT_NAMES[i]


ARM_JOINTS = tuple(arm_joint_name(i) for i in range(6))
