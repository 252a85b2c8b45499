"""What the robot model's geoms share: collision bitmasks, colours and the helpers that add a
geom and turn a rotation matrix into a quaternion."""

from __future__ import annotations

import mujoco
import numpy as np

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

ROBOT_RGBA = (0.62, 0.66, 0.72, 1.0)
JOINT_RGBA = (0.20, 0.45, 0.75, 1.0)
SCOOTER_RGBA = (0.75, 0.12, 0.12, 1.0)
DARK_RGBA = (0.12, 0.12, 0.13, 1.0)
PAD_RGBA = (0.05, 0.05, 0.05, 1.0)


def quat_list(R: np.ndarray) -> list[float]:
    """The wxyz quaternion of rotation matrix `R`, as MjSpec takes it."""
    return quat_from_matrix(R).tolist()


def add_geom(body: mujoco.MjsBody, name: str, kind: mujoco.mjtGeom, size, pos=(0, 0, 0), **kw):
    """Add a geom to `body`: `size` padded to three numbers, `pos` (m) in the body's frame, and
    every keyword set as an attribute of the geom."""
    g = body.add_geom(name=name, type=kind, size=list(size) + [0] * (3 - len(size)), pos=list(pos))
    for key, value in kw.items():
        setattr(g, key, value)
    return g
