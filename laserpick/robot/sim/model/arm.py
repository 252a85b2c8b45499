"""The UR5 in the model: six links on DH frames, each with the described capsules and joint
housing of its part (`description.visuals`).

The UR5 bodies follow the standard DH convention exactly: body i is frame i-1 turned by q_i about
its z axis, and body i+1 sits at (a_i, 0, d_i) turned by alpha_i about x. So MuJoCo's forward
kinematics is the DH forward kinematics, and the analytic IK applies unchanged.
"""

from __future__ import annotations

import mujoco
import numpy as np

from laserpick.description import dims
from laserpick.description.shapes import LINK_CAPSULES
from laserpick.robot.sim.model.geoms import ARM_GEOM, PARTS_BY_NAME, J, add_shape, quat_list
from laserpick.robot.sim.model.gripper import add_gripper
from laserpick.robot.sim.model.names import ARM_PREFIX, FLANGE_SITE, arm_joint_name
from laserpick.transforms import rotx, rotz


def _add_link_geoms(body: mujoco.MjsBody, i: int) -> None:
    """Link i+1's capsules, sharing the link's mass, and its massless joint housing."""
    share = dims.UR5_LINK_MASSES[i + 1] / len(LINK_CAPSULES[i])
    for shape in PARTS_BY_NAME[body.name].shapes:
        mass = 0.0 if shape.name == body.name + "/joint" else share
        add_shape(body, shape, mass=mass, **ARM_GEOM)


def add_ur5(parent: mujoco.MjsBody, fingers_move: bool) -> mujoco.MjsBody:
    """The UR5 and its gripper under `parent`; returns the gripper body."""
    d, a, alpha = dims.UR5_D, dims.UR5_A, dims.UR5_ALPHA
    base = parent.add_body(
        name=ARM_PREFIX + "base",
        pos=dims.ARM_MOUNT_POS.tolist(),
        quat=quat_list(rotz(dims.ARM_MOUNT_YAW)),
    )
    for shape in PARTS_BY_NAME[base.name].shapes:
        add_shape(base, shape, mass=dims.UR5_LINK_MASSES[0], **ARM_GEOM)

    body = base
    for i in range(6):
        if i == 0:
            pos, R = (0.0, 0.0, 0.0), np.eye(3)
        else:
            pos, R = (a[i - 1], 0.0, d[i - 1]), rotx(alpha[i - 1])
        body = body.add_body(name=ARM_PREFIX + f"link{i + 1}", pos=list(pos), quat=quat_list(R))
        body.gravcomp = 1.0  # the UR5 controller compensates gravity; so does ours
        j = body.add_joint(name=arm_joint_name(i), type=J.mjJNT_HINGE, axis=[0, 0, 1])
        j.range = [float(dims.UR5_Q_MIN[i]), float(dims.UR5_Q_MAX[i])]
        j.limited = mujoco.mjtLimited.mjLIMITED_TRUE
        j.armature = 0.1 if i < 3 else 0.02
        j.damping = [1.0 if i < 3 else 0.2, 0.0, 0.0]
        _add_link_geoms(body, i)
    flange = body.add_body(name=ARM_PREFIX + "flange", pos=[0, 0, d[5]])
    flange.add_site(name=FLANGE_SITE, pos=[0, 0, 0], size=[0.005, 0, 0], group=5)
    return add_gripper(flange, fingers_move)
