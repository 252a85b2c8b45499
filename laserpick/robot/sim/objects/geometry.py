"""Geometry of an object model: quaternions, part volumes, the support function, centre of
mass and the narrowest width a gripper must span. Lengths in m, quaternions wxyz."""

from __future__ import annotations

import math
from collections.abc import Sequence

import mujoco
import numpy as np

from laserpick.robot.sim.objects.object_model import ObjectModel, Part
from laserpick.transforms import matrix_from_quat


def quat_mul(a: Sequence[float], b: Sequence[float]) -> np.ndarray:
    """Hamilton product a*b of two wxyz quaternions (apply b first, then a)."""
    out = np.zeros(4)
    mujoco.mju_mulQuat(out, np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    return out


def axis_angle_quat(axis: Sequence[float], angle: float) -> np.ndarray:
    """wxyz quaternion of a rotation by `angle` (rad) about `axis`."""
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    return np.array([math.cos(angle / 2), *(math.sin(angle / 2) * a)])


def yaw_quat(yaw: float) -> np.ndarray:
    """wxyz quaternion of a rotation by `yaw` (rad) about +z."""
    return np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])


def part_volume(part: Part, model: ObjectModel | None = None) -> float:
    """Volume of one part (m^3); mesh parts need their model for the mesh asset."""
    s = part.size
    if part.kind == "box":
        return 8 * s[0] * s[1] * s[2]
    if part.kind == "cylinder":
        return math.pi * s[0] ** 2 * 2 * s[1]
    if part.kind == "sphere":
        return 4 / 3 * math.pi * s[0] ** 3
    if part.kind == "capsule":
        return math.pi * s[0] ** 2 * 2 * s[1] + 4 / 3 * math.pi * s[0] ** 3
    if part.kind == "ellipsoid":
        return 4 / 3 * math.pi * s[0] * s[1] * s[2]
    if model is None:
        raise ValueError("a mesh part's volume needs its model")
    return model.mesh_asset(part.mesh or "").volume


def part_support(part: Part, d: np.ndarray, model: ObjectModel | None = None) -> float:
    """Support function of a part: max over its points p of p . d (m), in the object frame."""
    pos = np.asarray(part.pos, dtype=float)
    rot = matrix_from_quat(part.quat)
    if part.kind == "mesh":
        if model is None:
            raise ValueError("a mesh part's support needs its model")
        verts = model.mesh_asset(part.mesh or "").vertices @ rot.T + pos
        return float(np.max(verts @ d))
    dl = rot.T @ d  # the direction in the part's frame
    s = part.size
    if part.kind == "box":
        ext = float(np.dot(np.abs(dl), s))
    elif part.kind == "sphere":
        ext = s[0] * float(np.linalg.norm(dl))
    elif part.kind == "cylinder":
        ext = s[1] * abs(dl[2]) + s[0] * math.hypot(dl[0], dl[1])
    elif part.kind == "capsule":
        ext = s[1] * abs(dl[2]) + s[0] * float(np.linalg.norm(dl))
    else:  # ellipsoid
        ext = float(np.linalg.norm(np.asarray(s) * dl))
    return float(pos @ d) + ext


def support(model: ObjectModel, d: Sequence[float], quat: Sequence[float] | None = None) -> float:
    """Support function of the whole object: max of p . d over its points (m).

    `d` is in the frame the object is rotated into by `quat` (wxyz, identity when None);
    the object's origin stays at the origin.
    """
    d = np.asarray(d, dtype=float)
    if quat is not None:
        d = matrix_from_quat(quat).T @ d
    return max(part_support(p, d, model) for p in model.parts)


def center_of_mass(model: ObjectModel) -> np.ndarray:
    """Centre of mass (m) in the object frame, assuming uniform density over the parts."""
    vols = np.array([part_volume(p, model) for p in model.parts])
    centres = []
    for p in model.parts:
        if p.kind == "mesh":
            v = model.mesh_asset(p.mesh or "").vertices
            c = matrix_from_quat(p.quat) @ v.mean(axis=0) + np.asarray(p.pos)
        else:
            c = np.asarray(p.pos, dtype=float)
        centres.append(c)
    return (vols[:, None] * np.array(centres)).sum(axis=0) / vols.sum()


def min_width(model: ObjectModel, n: int = 24) -> float:
    """Smallest width of the object over directions on a sphere (m): what a gripper must span.

    It is the narrowest slab the object fits in, i.e. the smallest opening a parallel gripper
    needs in the best orientation.
    """
    best = math.inf
    for i in range(n + 1):
        el = math.pi / 2 * i / n
        for j in range(2 * n):
            az = math.pi * j / (2 * n)
            d = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
            best = min(best, support(model, d) + support(model, -d))
    return best
