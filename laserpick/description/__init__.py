"""What a real robot's URDF would carry: every dimension and hardware limit (`dims`), the
UR5's kinematics (`kinematics`) and the robot's collision shapes (`shapes`). SI units; poses
in the scooter's `base` frame (x forward, y left, z up). Every other room reads these; this
room imports none of them.
"""

from laserpick.description import dims, kinematics, shapes
from laserpick.description.dims import GRIPPER_HAND, HandGeometry
from laserpick.description.kinematics import ik_tcp, tcp_pose
from laserpick.description.shapes import body_frames

__all__ = [
    "GRIPPER_HAND",
    "HandGeometry",
    "body_frames",
    "dims",
    "ik_tcp",
    "kinematics",
    "shapes",
    "tcp_pose",
]
