"""How an object rests on a level surface: its resting pose upright or lying, its footprint,
and whether it truly rests there (a MuJoCo drop test) rather than only balancing."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import mujoco
import numpy as np

from laserpick.robot.sim.objects.geometry import (
    axis_angle_quat,
    center_of_mass,
    quat_mul,
    support,
)
from laserpick.robot.sim.objects.mjcf import add_object_body
from laserpick.robot.sim.objects.object_model import ObjectModel
from laserpick.transforms import matrix_from_quat


@dataclass(frozen=True)
class RestPose:
    """How an object rests on a horizontal surface, before any yaw.

    `quat` (wxyz) rotates the object frame into the resting pose; `z` (m) lifts its origin so
    the lowest point touches the surface; `center` (x, y) is the centre of the footprint's
    bounding box relative to the origin and `radius` (m) the footprint radius about it;
    `height` is the resting height (m) above the surface.
    """

    quat: np.ndarray
    z: float
    center: np.ndarray
    radius: float
    height: float


_LYING_CANDIDATES = (
    axis_angle_quat((1, 0, 0), math.pi / 2),
    axis_angle_quat((1, 0, 0), -math.pi / 2),
    axis_angle_quat((0, 1, 0), math.pi / 2),
    axis_angle_quat((0, 1, 0), -math.pi / 2),
)


def footprint_half_extents(model: ObjectModel, rest: RestPose) -> np.ndarray:
    """Half extents (m) of the object's footprint rectangle at rest, along its own (unyawed)
    x and y axes: what a scene checks overlaps with."""
    ex = [support(model, d, rest.quat) for d in ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0))]
    return np.array([(ex[0] + ex[1]) / 2, (ex[2] + ex[3]) / 2])


def rest_pose(model: ObjectModel, lying: bool = False) -> RestPose:
    """The object's resting pose upright, or lying on its side.

    Lying picks, of the four quarter turns about the object's x and y axes, the one with the
    lowest centre of mass: a box lies on its broadest face, a can rolls onto its side.
    """
    rp = _rest_pose_cached(model, lying)
    return RestPose(rp.quat.copy(), rp.z, rp.center.copy(), rp.radius, rp.height)


@functools.lru_cache(maxsize=1024)
def _rest_pose_cached(model: ObjectModel, lying: bool) -> RestPose:
    if not lying:
        q = np.array([1.0, 0.0, 0.0, 0.0])
    else:
        com = center_of_mass(model)
        best: tuple[float, int] | None = None
        for i, cand in enumerate(_LYING_CANDIDATES):
            h = float((matrix_from_quat(cand) @ com)[2]) + support(model, (0, 0, -1), cand)
            if best is None or h < best[0] - 1e-4:
                best = (h, i)
        q = _LYING_CANDIDATES[best[1] if best else 0].copy()
    zmin = -support(model, (0, 0, -1), q)
    zmax = support(model, (0, 0, 1), q)
    xlo, xhi = -support(model, (-1, 0, 0), q), support(model, (1, 0, 0), q)
    ylo, yhi = -support(model, (0, -1, 0), q), support(model, (0, 1, 0), q)
    center = np.array([(xlo + xhi) / 2, (ylo + yhi) / 2])
    radius = 0.0
    for k in range(72):
        a = 2 * math.pi * k / 72
        d = np.array([math.cos(a), math.sin(a), 0.0])
        radius = max(radius, support(model, d, q) - float(d[:2] @ center))
    # Sampling 72 directions underestimates a corner by at most 1/cos(2.5 deg) - 1, 0.1 %.
    return RestPose(q, -zmin, center, radius * 1.001, zmax - zmin)


#: Tip (deg) that `at_rest` gives an object about each of four level axes, and how far (deg)
#: from its pose it may settle and still count as having come back.
REST_TIP_DEG = 3.0
REST_BACK_DEG = 3.5
_REST_TIP_AXES = ((1.0, 0.0), (0.0, 1.0), (math.sqrt(0.5), -math.sqrt(0.5)), (-1.0, 0.0))


def at_rest(model: ObjectModel, lying: bool = False) -> bool:
    """Whether the object rests in `rest_pose(model, lying)` rather than only balancing there.

    It is set on a level plane in MuJoCo, tipped `REST_TIP_DEG` about each of four level
    axes in turn, and let go for 2 s; it rests if it comes back to within `REST_BACK_DEG`
    every time. Every library object rests upright. Lying, the quarter turn with the lowest
    centre of mass may only balance: a banana's curve, a mug's handle or a bowl's rim tips
    it over (then a place that sets it down so turns it over too). Cached per model; the
    first call costs 10-30 ms.
    """
    return _at_rest_cached(model, lying)


@functools.lru_cache(maxsize=1024)
def _at_rest_cached(model: ObjectModel, lying: bool) -> bool:
    rp = rest_pose(model, lying)
    up = matrix_from_quat(rp.quat)[2]  # the world's up in the object's frame
    for ax, ay in _REST_TIP_AXES:
        q = quat_mul(axis_angle_quat((ax, ay, 0.0), math.radians(REST_TIP_DEG)), rp.quat)
        spec = mujoco.MjSpec()
        spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
        spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[1.0, 1.0, 0.1])
        add_object_body(spec, "x", model, [0, 0, support(model, (0, 0, -1), q) + 1e-4], q)
        mj = spec.compile()
        data = mujoco.MjData(mj)
        mujoco.mj_step(mj, data, nstep=1000)
        settled = matrix_from_quat(data.qpos[3:7])[2]
        if math.degrees(math.acos(float(np.clip(settled @ up, -1.0, 1.0)))) > REST_BACK_DEG:
            return False
    return True
