"""The two-finger parallel gripper on the flange: its housing and coupling, the TCP site, and
the fingers with their pads on slide joints. The geoms are the shapes of the described
`gripper` and finger parts (`description.visuals`); this adds their masses and the pads'
contact."""

from __future__ import annotations

import mujoco

from laserpick.description import dims
from laserpick.description.visuals import finger
from laserpick.robot.sim.model.geoms import ARM_GEOM, PARTS_BY_NAME, J, add_shape
from laserpick.robot.sim.model.names import TCP_SITE

#: kg of each geom of the gripper's body and of each finger.
GEOM_MASS = {
    "gripper/housing": dims.GRIPPER_MASS * 0.8,
    "gripper/coupling": 0.05,
    "gripper/finger_left": 0.05,
    "gripper/finger_right": 0.05,
    "gripper/pad_left": 0.01,
    "gripper/pad_right": 0.01,
}
#: The pads' contact: rubber's friction with torsion (condim 4), stiff but slightly soft, as
#: a firm rubber pad rather than steel, and winning over the object's contact settings.
PAD_CONTACT = {
    "condim": 4,
    "friction": list(dims.PAD_FRICTION),
    "solref": [0.004, 1.0],
    "solimp": [0.95, 0.99, 0.001, 0.5, 2.0],
    "priority": 1,
}
#: The housing's and the finger plates' contact: as stiff as the pads' (aluminium does not
#: give), their stiffness winning the mix with what they touch (`solmix`) while friction and
#: contact dimensions stay the larger of the two. With MuJoCo's default softness a spice jar
#: squeezed against the palm sank 15 mm into it while carried, and sprang out when let go.
HAND_CONTACT = {
    "solref": PAD_CONTACT["solref"],
    "solimp": PAD_CONTACT["solimp"],
    "solmix": 1000.0,
}


def add_gripper(flange: mujoco.MjsBody, fingers_move: bool) -> mujoco.MjsBody:
    """A two-finger parallel gripper. Local frame = flange: z approach, y closing, x hand axis."""
    g = flange.add_body(name="gripper", pos=[0, 0, 0])
    g.gravcomp = 1.0
    for shape in PARTS_BY_NAME[g.name].shapes:
        add_shape(g, shape, mass=GEOM_MASS[shape.name], **ARM_GEOM, **HAND_CONTACT)
    g.add_site(name=TCP_SITE, pos=[0, 0, dims.GRIPPER_TCP_OFFSET], size=[0.006, 0, 0], group=5)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        _add_finger(g, side, sign, fingers_move)
    return g


def _add_finger(g: mujoco.MjsBody, side: str, sign: float, fingers_move: bool) -> None:
    """One finger, `sign` +1 on the left (+y) and -1 on the right: its plate and its pad, on a
    slide joint along the closing axis, or held fully open when the fingers do not move."""
    f = g.add_body(name=f"finger_{side}", pos=[0, 0, 0])
    f.gravcomp = 1.0
    if fingers_move:
        j = f.add_joint(name=f"finger_{side}", type=J.mjJNT_SLIDE, axis=[0, sign, 0])
        j.range = [0.0, dims.GRIPPER_STROKE / 2]
        j.limited = mujoco.mjtLimited.mjLIMITED_TRUE
        j.armature = 0.01
        j.damping = [5.0, 0.0, 0.0]
        part = PARTS_BY_NAME[f.name]  # the joint moves it
    else:
        # The kinematic model holds the fingers fully open.
        part = finger(side, travel=dims.GRIPPER_STROKE / 2)
    plate, pad = part.shapes
    add_shape(f, plate, mass=GEOM_MASS[plate.name], **ARM_GEOM, **HAND_CONTACT)
    add_shape(f, pad, mass=GEOM_MASS[pad.name], **ARM_GEOM, **PAD_CONTACT)
