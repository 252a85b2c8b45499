"""Adding an object to a MuJoCo spec: a free body with one geom per part, and its mesh assets."""

from __future__ import annotations

from collections.abc import Sequence

import mujoco
import numpy as np

from laserpick.robot.sim.objects.geometry import part_volume
from laserpick.robot.sim.objects.groups import (
    OBJECT_CONAFFINITY,
    OBJECT_CONTYPE,
    TRANSPARENT_ALPHA,
)
from laserpick.robot.sim.objects.object_model import GEOM_TYPE, MeshAsset, ObjectModel

#: Torsional and rolling friction of every object geom (m), after the sliding coefficient.
OBJECT_FRICTION_TAIL = (0.005, 0.0005)
#: Contact dimensionality of object geoms: sliding, torsional and rolling friction. Without
#: rolling friction (4) a can laid on its side rolls off its table within a minute. The pads'
#: contacts take the pads' own (4): they have priority.
OBJECT_CONDIM = 6


def _mesh_asset_name(model: ObjectModel, mesh: str) -> str:
    return f"mesh/{model.name}/{mesh}"


def _ensure_mesh(spec: mujoco.MjSpec, model: ObjectModel, mesh: MeshAsset) -> str:
    """Add a mesh asset to `spec` once per model and return its asset name."""
    name = _mesh_asset_name(model, mesh.name)
    existing = spec.mesh(name)
    if existing is not None:
        if len(existing.uservert) != mesh.vertices.size:
            raise ValueError(f"a different mesh named {name!r} is already in the spec")
        return name
    spec.add_mesh(
        name=name,
        uservert=mesh.vertices.ravel().tolist(),
        userface=mesh.faces.ravel().tolist(),
        inertia=mujoco.mjtMeshInertia.mjMESH_INERTIA_CONVEX,
    )
    return name


def add_object_body(
    spec: mujoco.MjSpec,
    instance: str,
    model: ObjectModel,
    pos: Sequence[float],
    quat: Sequence[float],
) -> mujoco.MjsBody:
    """Add one free object to `spec.worldbody` and return its body.

    The body is `obj/<instance>` at `pos` (m, world) with orientation `quat` (wxyz, world),
    with a free joint `obj/<instance>` and geoms `obj/<instance>/<k>`, one per part. The total
    mass is split over the parts by volume, so the body weighs exactly `model.mass`.
    """
    name = f"obj/{instance}"
    body = spec.worldbody.add_body(
        name=name, pos=[float(x) for x in pos], quat=[float(x) for x in quat]
    )
    body.add_freejoint(name=name)
    vols = np.array([part_volume(p, model) for p in model.parts])
    masses = model.mass * vols / vols.sum()
    rgba = list(model.rgba)
    if model.optical == "transparent":
        rgba[3] = min(rgba[3], TRANSPARENT_ALPHA)
    for k, (part, mass) in enumerate(zip(model.parts, masses, strict=True)):
        prgba = list(part.rgba) if part.rgba is not None else rgba
        if model.optical == "transparent":
            prgba[3] = min(prgba[3], TRANSPARENT_ALPHA)
        geom = body.add_geom(
            name=f"{name}/{k}",
            type=GEOM_TYPE[part.kind],
            pos=list(part.pos),
            quat=list(part.quat),
            mass=float(mass),
            friction=[model.friction, *OBJECT_FRICTION_TAIL],
            condim=OBJECT_CONDIM,
            group=model.group,
            rgba=prgba,
            contype=OBJECT_CONTYPE,
            conaffinity=OBJECT_CONAFFINITY,
        )
        if part.kind == "mesh":
            geom.meshname = _ensure_mesh(spec, model, model.mesh_asset(part.mesh or ""))
        else:
            size = list(part.size) + [0.0] * (3 - len(part.size))
            geom.size = size
    return body
