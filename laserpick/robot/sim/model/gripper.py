"""The two-finger parallel gripper on the flange: housing, coupling, TCP site, fingers and pads."""

from __future__ import annotations

import mujoco

from laserpick.description import dims
from laserpick.robot.sim.model.geoms import (
    ARM_AFFINITY,
    ARM_TYPE,
    DARK_RGBA,
    PAD_RGBA,
    ROBOT_RGBA,
    G,
    J,
    add_geom,
)
from laserpick.robot.sim.model.names import TCP_SITE
from laserpick.robot.sim.objects import GROUP_ROBOT

#: Finger plate thickness along the closing axis (m).
FINGER_THICKNESS = 0.008


def add_gripper(flange: mujoco.MjsBody, fingers_move: bool) -> mujoco.MjsBody:
    """A two-finger parallel gripper. Local frame = flange: z approach, y closing, x hand axis."""
    g = flange.add_body(name="gripper", pos=[0, 0, 0])
    g.gravcomp = 1.0
    L = dims.GRIPPER_BASE_LENGTH
    add_geom(
        g,
        "gripper/housing",
        G.mjGEOM_BOX,
        (dims.GRIPPER_BODY_DEPTH / 2, dims.GRIPPER_BODY_WIDTH / 2, L / 2 - 0.01),
        (0, 0, L / 2 + 0.01),
        rgba=list(DARK_RGBA),
        group=GROUP_ROBOT,
        mass=dims.GRIPPER_MASS * 0.8,
        contype=ARM_TYPE,
        conaffinity=ARM_AFFINITY,
    )
    add_geom(
        g,
        "gripper/coupling",
        G.mjGEOM_CYLINDER,
        (0.038, 0.006),
        (0, 0, 0.006),
        rgba=list(ROBOT_RGBA),
        group=GROUP_ROBOT,
        mass=0.05,
        contype=ARM_TYPE,
        conaffinity=ARM_AFFINITY,
    )
    g.add_site(name=TCP_SITE, pos=[0, 0, dims.GRIPPER_TCP_OFFSET], size=[0.006, 0, 0], group=5)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        _add_finger(g, side, sign, fingers_move)
    return g


def _add_finger(g: mujoco.MjsBody, side: str, sign: float, fingers_move: bool) -> None:
    """One finger, `sign` +1 on the left (+y) and -1 on the right: its plate and its pad, on a
    slide joint along the closing axis, or held fully open when the fingers do not move."""
    L, F = dims.GRIPPER_BASE_LENGTH, dims.GRIPPER_FINGER_LENGTH
    finger_t = FINGER_THICKNESS
    pad_t = dims.GRIPPER_PAD_THICKNESS
    f = g.add_body(name=f"finger_{side}", pos=[0, 0, 0])
    f.gravcomp = 1.0
    if fingers_move:
        j = f.add_joint(name=f"finger_{side}", type=J.mjJNT_SLIDE, axis=[0, sign, 0])
        j.range = [0.0, dims.GRIPPER_STROKE / 2]
        j.limited = mujoco.mjtLimited.mjLIMITED_TRUE
        j.armature = 0.01
        j.damping = [5.0, 0.0, 0.0]
        q_open = 0.0
    else:
        # The kinematic model holds the fingers fully open.
        q_open = dims.GRIPPER_STROKE / 2
    y_pad = sign * (q_open + pad_t / 2)
    y_plate = sign * (q_open + pad_t + finger_t / 2)
    add_geom(
        f,
        f"gripper/finger_{side}",
        G.mjGEOM_BOX,
        (0.012, finger_t / 2, F / 2),
        (0, y_plate, L + F / 2),
        rgba=list(ROBOT_RGBA),
        group=GROUP_ROBOT,
        mass=0.05,
        contype=ARM_TYPE,
        conaffinity=ARM_AFFINITY,
    )
    add_geom(
        f,
        f"gripper/pad_{side}",
        G.mjGEOM_BOX,
        (dims.GRIPPER_PAD_WIDTH / 2, pad_t / 2, dims.GRIPPER_PAD_DEPTH / 2),
        (0, y_pad, L + F - dims.GRIPPER_PAD_DEPTH / 2),
        rgba=list(PAD_RGBA),
        group=GROUP_ROBOT,
        mass=0.01,
        contype=ARM_TYPE,
        conaffinity=ARM_AFFINITY,
        condim=4,
        friction=list(dims.PAD_FRICTION),
        # Stiff, slightly soft-contact pads: a firm rubber pad rather than steel.
        solref=[0.004, 1.0],
        solimp=[0.95, 0.99, 0.001, 0.5, 2.0],
        priority=1,
    )
