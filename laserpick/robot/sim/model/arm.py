"""The UR5 in the model: six links on DH frames with their collision capsules and joint housings.

The UR5 bodies follow the standard DH convention exactly: body i is frame i-1 turned by q_i about
its z axis, and body i+1 sits at (a_i, 0, d_i) turned by alpha_i about x. So MuJoCo's forward
kinematics is the DH forward kinematics, and the analytic IK applies unchanged.
"""

from __future__ import annotations

import mujoco
import numpy as np

from laserpick.description import dims
from laserpick.description.shapes import HOUSING_CAPSULES, LINK_CAPSULES
from laserpick.robot.sim.model.geoms import (
    ARM_AFFINITY,
    ARM_TYPE,
    DARK_RGBA,
    JOINT_RGBA,
    ROBOT_RGBA,
    G,
    J,
    add_geom,
    quat_list,
)
from laserpick.robot.sim.model.gripper import add_gripper
from laserpick.robot.sim.model.names import ARM_PREFIX, FLANGE_SITE, arm_joint_name
from laserpick.robot.sim.objects import GROUP_ROBOT
from laserpick.transforms import rotx, rotz


def capsule_between(
    body: mujoco.MjsBody, name: str, a, b, radius: float, mass: float, rgba=ROBOT_RGBA
) -> mujoco.MjsGeom:
    """An arm collision capsule from point a to point b in the body's frame (m)."""
    return add_geom(
        body,
        name,
        G.mjGEOM_CAPSULE,
        (radius,),
        fromto=[*a, *b],
        mass=mass,
        rgba=list(rgba),
        group=GROUP_ROBOT,
        contype=ARM_TYPE,
        conaffinity=ARM_AFFINITY,
    )


def add_ur5(parent: mujoco.MjsBody, fingers_move: bool) -> mujoco.MjsBody:
    """The UR5 and its gripper under `parent`; returns the gripper body."""
    d, a, alpha = dims.UR5_D, dims.UR5_A, dims.UR5_ALPHA
    m, r = dims.UR5_LINK_MASSES, dims.UR5_LINK_RADII
    base = parent.add_body(
        name=ARM_PREFIX + "base",
        pos=dims.ARM_MOUNT_POS.tolist(),
        quat=quat_list(rotz(dims.ARM_MOUNT_YAW)),
    )
    capsule_between(base, ARM_PREFIX + "base/c", (0, 0, 0.0), (0, 0, 0.03), r[0], m[0], DARK_RGBA)

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
        share = m[i + 1] / len(LINK_CAPSULES[i])
        for k, (p0, p1, rad) in enumerate(LINK_CAPSULES[i]):
            if np.allclose(p0, p1):
                p1 = (p1[0], p1[1], p1[2] + 1e-3)
            capsule_between(body, ARM_PREFIX + f"link{i + 1}/c{k}", p0, p1, rad, share)
        # The joint's housing, for looks and collision: a ball or a short capsule.
        _, end, radius = HOUSING_CAPSULES[i]  # centred on the origin, along z
        hous = body.add_geom(name=ARM_PREFIX + f"link{i + 1}/joint", pos=[0, 0, 0])
        if end[2] > 0:
            hous.type, hous.size = G.mjGEOM_CAPSULE, [radius, end[2], 0]
        else:
            hous.type, hous.size = G.mjGEOM_SPHERE, [radius, 0, 0]
        hous.rgba = list(JOINT_RGBA)
        hous.group = GROUP_ROBOT
        hous.mass = 0.0
        hous.contype, hous.conaffinity = ARM_TYPE, ARM_AFFINITY
    flange = body.add_body(name=ARM_PREFIX + "flange", pos=[0, 0, d[5]])
    flange.add_site(name=FLANGE_SITE, pos=[0, 0, 0], size=[0.005, 0, 0], group=5)
    return add_gripper(flange, fingers_move)
