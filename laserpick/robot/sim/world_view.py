"""The simulated world as a layer of the 3D view: the floor, the furniture and the objects.

A real robot knows its own body and what its sensors see, not the room; the simulator knows
the room too. `SimWorld` offers it to the console's view (`laserpick.console.WorldLayer`) as
plain data: every MuJoCo body outside the robot that has visible geoms, merged into one
triangle mesh per colour in the body's frame, and the bodies' poses in `world` read from
the simulation's snapshots. It also pauses and resumes the simulation. The robot itself is
drawn from its description (`laserpick.description.visuals`), not from here.

Visible geoms are groups 0..3 (opaque, robot, transparent, specular; see
`laserpick.robot.sim.objects`); sites and markers (group 5) are not drawn. The floor plane
becomes a thin slab `FLOOR_HALF_EXTENT` wide.

Frames and units: poses in `world` (z up), metres; quaternions (w, x, y, z), as both MuJoCo
and viser order them. Reads `Simulation.snapshot()` only, never MjData, from any thread.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import mujoco
import numpy as np
import trimesh

from laserpick.robot.sim.loop import Simulation
from laserpick.robot.sim.objects import (
    GROUP_OPAQUE,
    GROUP_ROBOT,
    GROUP_SPECULAR,
    GROUP_TRANSPARENT,
)

__all__ = ["BodyMesh", "SimWorld", "WorldBody", "body_meshes", "geom_mesh", "geom_rgba"]

log = logging.getLogger(__name__)

#: Geom groups a person should see: opaque, robot, transparent, specular.
VISIBLE_GROUPS = frozenset({GROUP_OPAQUE, GROUP_ROBOT, GROUP_TRANSPARENT, GROUP_SPECULAR})
#: Half extent (m) of the drawn floor; MuJoCo planes are infinite or 30 m, far more than needed.
FLOOR_HALF_EXTENT = 6.0
#: Floor slab thickness (m); its top face is the plane.
FLOOR_THICKNESS = 0.02
#: MuJoCo's default geom rgba; a geom with this colour and a material takes the material's.
_DEFAULT_RGBA = (0.5, 0.5, 0.5, 1.0)

RGBA = tuple[float, float, float, float]


@dataclass(frozen=True)
class BodyMesh:
    """The geoms of one colour of a body: vertices (V, 3) float32 m in the body's frame,
    faces (F, 3) uint32, RGBA in [0, 1]."""

    rgba: RGBA
    vertices: np.ndarray
    faces: np.ndarray


@dataclass(frozen=True)
class WorldBody:
    """A body of the simulated world. `moving`: it can move (a free object), so its pose is
    followed; `ground`: the world body, which holds the floor."""

    name: str
    moving: bool
    ground: bool
    meshes: tuple[BodyMesh, ...]


def geom_mesh(model: mujoco.MjModel, g: int) -> trimesh.Trimesh | None:
    """The triangle mesh of geom `g` in its own frame (m), or None for unsupported types.

    Planes become a slab whose top face is the plane (see `FLOOR_HALF_EXTENT`); heightfields
    are skipped. Sharp edges are split (`smooth_shaded`) so that the browser's computed vertex
    normals shade boxes flat and cylinders smooth.
    """
    kind = int(model.geom_type[g])
    size = np.asarray(model.geom_size[g], dtype=float)
    G = mujoco.mjtGeom
    if kind == G.mjGEOM_PLANE:
        hx = size[0] if size[0] > 0 else FLOOR_HALF_EXTENT
        hy = size[1] if size[1] > 0 else FLOOR_HALF_EXTENT
        hx, hy = min(hx, FLOOR_HALF_EXTENT), min(hy, FLOOR_HALF_EXTENT)
        mesh = trimesh.creation.box(extents=[2 * hx, 2 * hy, FLOOR_THICKNESS])
        mesh.apply_translation([0.0, 0.0, -FLOOR_THICKNESS / 2])
        return mesh
    if kind == G.mjGEOM_BOX:
        return trimesh.creation.box(extents=2 * size).smooth_shaded
    if kind == G.mjGEOM_SPHERE:
        return trimesh.creation.icosphere(subdivisions=2, radius=size[0])
    if kind == G.mjGEOM_ELLIPSOID:
        mesh = trimesh.creation.icosphere(subdivisions=2, radius=1.0)
        mesh.apply_scale(size)
        return mesh
    if kind == G.mjGEOM_CAPSULE:
        return trimesh.creation.capsule(height=2 * size[1], radius=size[0], count=[16, 16])
    if kind == G.mjGEOM_CYLINDER:
        mesh = trimesh.creation.cylinder(radius=size[0], height=2 * size[1], sections=24)
        return mesh.smooth_shaded
    if kind == G.mjGEOM_MESH:
        mid = int(model.geom_dataid[g])
        v0, nv = int(model.mesh_vertadr[mid]), int(model.mesh_vertnum[mid])
        f0, nf = int(model.mesh_faceadr[mid]), int(model.mesh_facenum[mid])
        verts = np.array(model.mesh_vert[v0 : v0 + nv], dtype=float)
        faces = np.array(model.mesh_face[f0 : f0 + nf], dtype=np.int64)
        return trimesh.Trimesh(verts, faces, process=False).smooth_shaded
    log.warning("world view: geom %d has type %d, which is not drawn", g, kind)
    return None


def geom_rgba(model: mujoco.MjModel, g: int) -> RGBA:
    """The colour a geom is drawn in: its rgba, or its material's when it has the default."""
    rgba = tuple(float(c) for c in model.geom_rgba[g])
    mat = int(model.geom_matid[g])
    if mat >= 0 and np.allclose(rgba, _DEFAULT_RGBA):
        rgba = tuple(float(c) for c in model.mat_rgba[mat])
    return rgba  # type: ignore[return-value]


def _geom_transform(model: mujoco.MjModel, g: int) -> np.ndarray:
    """4x4 pose of geom `g` in its body's frame."""
    T = np.eye(4)
    R = np.zeros(9)
    mujoco.mju_quat2Mat(R, model.geom_quat[g])
    T[:3, :3] = R.reshape(3, 3)
    T[:3, 3] = model.geom_pos[g]
    return T


def body_meshes(model: mujoco.MjModel, body: int) -> tuple[BodyMesh, ...]:
    """The visible geoms of `body` merged into one mesh per rgba, in the body's frame."""
    by_colour: dict[tuple[float, ...], list[trimesh.Trimesh]] = {}
    for g in range(model.ngeom):
        if int(model.geom_bodyid[g]) != body or int(model.geom_group[g]) not in VISIBLE_GROUPS:
            continue
        rgba = geom_rgba(model, g)
        if rgba[3] <= 0.0:
            continue
        mesh = geom_mesh(model, g)
        if mesh is None:
            continue
        mesh.apply_transform(_geom_transform(model, g))
        by_colour.setdefault(tuple(round(c, 4) for c in rgba), []).append(mesh)
    out = []
    for rgba, parts in by_colour.items():
        merged = parts[0] if len(parts) == 1 else trimesh.util.concatenate(parts)
        vertices = np.asarray(merged.vertices, dtype=np.float32)
        faces = np.asarray(merged.faces, dtype=np.uint32)
        out.append(BodyMesh(rgba, vertices, faces))  # type: ignore[arg-type]
    return tuple(out)


def _is_moving(model: mujoco.MjModel, body: int) -> bool:
    """True if the body can move in `world`: it is not welded to the world body, or is mocap."""
    return int(model.body_weldid[body]) != 0 or int(model.body_mocapid[body]) >= 0


class SimWorld:
    """The world of a `Simulation` but the robot, for the console's view (`WorldLayer`)."""

    def __init__(self, sim: Simulation) -> None:
        self.sim = sim
        model = sim.model
        robot = sim.info.scooter_body
        ids, bodies = [], []
        for b in range(model.nbody):
            meshes = body_meshes(model, b) if int(model.body_rootid[b]) != robot else ()
            if meshes:
                name = model.body(b).name or f"body{b}"
                ids.append(b)
                bodies.append(WorldBody(name, _is_moving(model, b), b == 0, meshes))
        self._ids = np.array(ids, dtype=np.int64)
        self._bodies = tuple(bodies)

    def bodies(self) -> tuple[WorldBody, ...]:
        """The bodies to draw: outside the robot, with something visible."""
        return self._bodies

    def poses(self) -> tuple[np.ndarray, np.ndarray]:
        """Positions (N, 3) m and orientations (N, 4) (w, x, y, z) in `world` of `bodies()`,
        in their order, from the latest snapshot."""
        snap = self.sim.snapshot()
        return snap.xpos[self._ids], snap.xquat[self._ids]

    @property
    def paused(self) -> bool:
        return self.sim.paused

    def pause(self) -> None:
        self.sim.pause()

    def resume(self) -> None:
        self.sim.resume()
