"""Part builders for the library: boxes and cylinders standing on a height, and the shapes
made of several parts (a bowl, a stuffed toy, a banana, a mug). Lengths in m."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from laserpick.robot.sim.objects.geometry import axis_angle_quat, quat_mul, support, yaw_quat
from laserpick.robot.sim.objects.object_model import ObjectModel, OpticalKind, Part

#: A part's rotation that turns its z along the object's x (wxyz).
X_AXIS = tuple(axis_angle_quat((0, 1, 0), math.pi / 2))


def box_part(
    hx: float, hy: float, hz: float, x: float = 0.0, y: float = 0.0, z0: float = 0.0, **kw
) -> Part:
    """A box with half-sizes (hx, hy, hz) whose bottom face is at height z0."""
    return Part("box", (hx, hy, hz), (x, y, z0 + hz), **kw)


def cylinder_part(
    r: float, h: float, x: float = 0.0, y: float = 0.0, z0: float = 0.0, **kw
) -> Part:
    """An upright cylinder of radius r and full height h whose bottom is at height z0."""
    return Part("cylinder", (r, h / 2), (x, y, z0 + h / 2), **kw)


def make_object(
    name: str,
    category: str,
    parts: Sequence[Part],
    mass: float,
    friction: float,
    rgba: tuple[float, float, float, float],
    optical: OpticalKind = "opaque",
) -> ObjectModel:
    """Build an object model and compute its upright height from its parts."""
    parts = tuple(parts)
    probe = ObjectModel(
        name=name,
        category=category,
        parts=parts,
        mass=mass,
        friction=friction,
        rgba=rgba,
        optical=optical,
        height=0.0,
    )
    bottom = -support(probe, (0, 0, -1))
    if abs(bottom) > 1e-6:
        raise ValueError(f"library object {name!r} does not start at z = 0 (bottom {bottom})")
    return dataclasses.replace(probe, height=support(probe, (0, 0, 1)))


def bowl_parts() -> list[Part]:
    """A small bowl (13 cm rim, 6 cm tall): a base disc and a ring of 14 tilted wall slabs.

    MuJoCo collides a mesh by its convex hull, which would fill the bowl, so the walls are
    separate thin boxes and the bowl stays hollow for the gripper's fingers.
    """
    parts = [cylinder_part(0.035, 0.008)]
    n, r_bot, r_top, h, t = 14, 0.035, 0.065, 0.06, 0.004
    tilt = math.atan2(r_top - r_bot, h)
    half_len = math.hypot(r_top - r_bot, h) / 2
    r_mid = (r_bot + r_top) / 2
    half_w = math.pi * r_top / n + 0.001
    for k in range(n):
        phi = 2 * math.pi * k / n
        q = quat_mul(yaw_quat(phi), axis_angle_quat((0, 1, 0), tilt))
        # The slab's lowest corner touches z = 0: lift it by its vertical half-extent.
        zc = half_len * math.cos(tilt) + t * math.sin(tilt)
        parts.append(
            Part(
                "box",
                (t, half_w, half_len),
                (r_mid * math.cos(phi), r_mid * math.sin(phi), zc),
                tuple(float(x) for x in q),
            )
        )
    return parts


def stuffed_toy_parts(scale: float) -> list[Part]:
    """A sitting stuffed doll: a flat-bottomed seat, two short legs, torso, arms and head.

    It sits like 003's doll, a balancing pose, but on a flat seat so it stays put; it is
    7.5 cm deep (x) at scale 1, so the gripper can close on it front to back.
    """
    s = scale
    return [
        Part("cylinder", (0.03 * s, 0.015 * s), (0, 0, 0.015 * s)),
        Part("capsule", (0.014 * s, 0.006 * s), (0.024 * s, 0.017 * s, 0.014 * s), X_AXIS),
        Part("capsule", (0.014 * s, 0.006 * s), (0.024 * s, -0.017 * s, 0.014 * s), X_AXIS),
        Part("ellipsoid", (0.028 * s, 0.036 * s, 0.045 * s), (0, 0, 0.07 * s)),
        Part("capsule", (0.011 * s, 0.02 * s), (0.005 * s, 0.042 * s, 0.075 * s)),
        Part("capsule", (0.011 * s, 0.02 * s), (0.005 * s, -0.042 * s, 0.075 * s)),
        Part("sphere", (0.034 * s,), (0, 0, 0.14 * s)),
    ]


def banana_parts() -> list[Part]:
    """A banana lying flat: three capsules along a gentle arc in the xy plane."""
    r, half = 0.018, 0.03
    parts = []
    for k, ang in enumerate((-0.45, 0.0, 0.45)):
        x = (k - 1) * 0.062
        y = 0.012 if k != 1 else 0.0
        q = quat_mul(yaw_quat(ang), np.array(X_AXIS))
        parts.append(Part("capsule", (r, half), (x, y, r), tuple(float(v) for v in q)))
    return parts


def mug_parts() -> list[Part]:
    """A small mug: a 7.2 cm body and a D handle of three bars on its +x side."""
    r, h = 0.036, 0.09
    return [
        cylinder_part(r, h),
        box_part(0.011, 0.006, 0.005, x=r + 0.006, z0=0.07),
        box_part(0.011, 0.006, 0.005, x=r + 0.006, z0=0.015),
        box_part(0.005, 0.006, 0.032, x=r + 0.017, z0=0.018),
    ]
