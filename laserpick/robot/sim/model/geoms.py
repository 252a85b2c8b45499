"""The robot model's geoms: collision bitmasks, and the helper that turns a shape of the
robot's description (`description.visuals`) into a geom, its name, kind, size, pose and
colour all read from the shape."""

from __future__ import annotations

import mujoco
import numpy as np

from laserpick.description.visuals import PARTS, Part, Shape
from laserpick.robot.sim.objects import GROUP_ROBOT
from laserpick.transforms import quat_from_matrix

G = mujoco.mjtGeom
J = mujoco.mjtJoint

# Collision bitmasks. Two geoms touch if (type_a & affinity_b) or (type_b & affinity_a).
# The scooter shell never touches the floor (its planar joints carry it), and the arm does not
# touch itself (mink keeps it clear); everything else collides.
STATIC_TYPE, STATIC_AFFINITY = 1, 2  # floor and surfaces
ARM_TYPE, ARM_AFFINITY = 4, 1 | 2 | 8  # arm and gripper
SCOOTER_TYPE, SCOOTER_AFFINITY = 8, 2  # scooter shell, basket
# Objects use type 2 / affinity 1|2|4|8 (see `objects.groups`).

#: What every geom of the arm and the gripper shares: drawn with the robot, and the arm's
#: bitmasks.
ARM_GEOM = {"group": GROUP_ROBOT, "contype": ARM_TYPE, "conaffinity": ARM_AFFINITY}
#: What every geom of the scooter's shell shares: drawn with the robot, the scooter's
#: bitmasks, and no mass (the body carries the scooter's).
SHELL_GEOM = {
    "group": GROUP_ROBOT,
    "contype": SCOOTER_TYPE,
    "conaffinity": SCOOTER_AFFINITY,
    "mass": 0.0,
}

#: The robot's described parts by name; each is the model's body of that name.
PARTS_BY_NAME: dict[str, Part] = {part.name: part for part in PARTS}

_KIND = {
    "box": G.mjGEOM_BOX,
    "sphere": G.mjGEOM_SPHERE,
    "capsule": G.mjGEOM_CAPSULE,
    "cylinder": G.mjGEOM_CYLINDER,
}


def quat_list(R: np.ndarray) -> list[float]:
    """The wxyz quaternion of rotation matrix `R`, as MjSpec takes it."""
    return quat_from_matrix(R).tolist()


def add_shape(body: mujoco.MjsBody, shape: Shape, **physics) -> mujoco.MjsGeom:
    """Add `shape` to `body` as a geom of its name, kind, size, pose (in the body's frame) and
    colour, and set each keyword of `physics` (mass, contact bits, friction ...) on it. A
    capsule given by its end points keeps them (MJCF `fromto`): MuJoCo derives its pose."""
    size = list(shape.size if shape.fromto is None else shape.size[:1])
    g = body.add_geom(name=shape.name, type=_KIND[shape.kind], size=size + [0] * (3 - len(size)))
    if shape.fromto is None:
        g.pos, g.quat = list(shape.pose[:3, 3]), quat_list(shape.pose[:3, :3])
    else:
        g.pos, g.fromto = [0, 0, 0], list(shape.fromto)
    g.rgba = list(shape.rgba)
    for key, value in physics.items():
        setattr(g, key, value)
    return g
