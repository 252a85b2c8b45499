"""The actuators: the arm's position servos, the gripper, the base's velocity servos."""

from __future__ import annotations

import math

import mujoco

from laserpick.description import dims
from laserpick.robot.sim.model.names import (
    ARM_JOINTS,
    BASE_JOINTS,
    FINGER_JOINTS,
    GRIPPER_ACTUATOR,
)


def add_actuators(spec: mujoco.MjSpec) -> None:
    """Add the arm's six position servos, the gripper's (the left finger, the right one
    mirrored by a joint equality) and the base's three velocity servos to `spec`."""
    for i, name in enumerate(ARM_JOINTS):
        act = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        kp = 3000.0 if i < 3 else 600.0
        act.set_to_position(kp=kp, kv=2 * math.sqrt(kp * (6.0 if i < 3 else 0.5)))
        act.ctrlrange = [float(dims.UR5_Q_MIN[i]), float(dims.UR5_Q_MAX[i])]
        act.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
        act.forcerange = [-dims.UR5_TORQUE_MAX[i], dims.UR5_TORQUE_MAX[i]]
        act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
    # One actuator drives the left finger; an equality mirrors it on the right, as the
    # 2F-85's linkage does. The force range is the grip force limit.
    grip = spec.add_actuator(
        name=GRIPPER_ACTUATOR, target=FINGER_JOINTS[0], trntype=mujoco.mjtTrn.mjTRN_JOINT
    )
    grip.set_to_position(kp=4000.0, kv=60.0)
    grip.ctrlrange = [0.0, dims.GRIPPER_STROKE / 2]
    grip.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
    grip.forcerange = [-dims.GRIPPER_FORCE_MAX, dims.GRIPPER_FORCE_MAX]
    grip.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
    eq = spec.add_equality(
        type=mujoco.mjtEq.mjEQ_JOINT, name1=FINGER_JOINTS[1], name2=FINGER_JOINTS[0]
    )
    eq.objtype = mujoco.mjtObj.mjOBJ_JOINT
    eq.data[:5] = [0, 1, 0, 0, 0]
    # The linkage is rigid: at MuJoCo's default softness the coupling gives way under the grip
    # force, and the driven finger pushes the object 1.1 cm off the hand's centre. This is
    # the stiffest MuJoCo keeps stable: a time constant of two steps.
    eq.solref = [2 * spec.option.timestep, 1.0]
    eq.solimp = [0.99, 0.999, 0.001, 0.5, 2.0]
    # Base: velocity servos on the planar joints; the drive turns (v, w) into these.
    for name, kv in zip(BASE_JOINTS, (4000.0, 4000.0, 2000.0), strict=True):
        act = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.set_to_velocity(kv=kv)
        act.forcerange = [-5000.0, 5000.0]
        act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
