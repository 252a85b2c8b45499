"""What an object is made of: its parts (primitive geoms or convex mesh pieces), mass and look.

An object's frame has its origin at the centre of its bottom face and z up when it stands in
its natural upright pose, so an object placed with its origin on a surface rests on it. All
numbers are SI: metres, kilograms; `friction` is the sliding coefficient.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import mujoco
import numpy as np

from laserpick.robot.sim.objects.groups import OPTICAL_GROUP

OpticalKind = Literal["opaque", "transparent", "specular"]
PartKind = Literal["box", "cylinder", "sphere", "capsule", "ellipsoid", "mesh"]

#: The MuJoCo geom type of each part kind, and how many size numbers each takes.
GEOM_TYPE = {
    "box": mujoco.mjtGeom.mjGEOM_BOX,
    "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
    "sphere": mujoco.mjtGeom.mjGEOM_SPHERE,
    "capsule": mujoco.mjtGeom.mjGEOM_CAPSULE,
    "ellipsoid": mujoco.mjtGeom.mjGEOM_ELLIPSOID,
    "mesh": mujoco.mjtGeom.mjGEOM_MESH,
}
SIZE_LEN = {"box": 3, "cylinder": 2, "sphere": 1, "capsule": 2, "ellipsoid": 3, "mesh": 0}


@dataclass(frozen=True, eq=False)
class MeshAsset:
    """A triangle mesh in the object's frame (m): vertices (N, 3) float, faces (M, 3) int.

    MuJoCo collides a mesh geom by its convex hull, so a concave shape should be handed over
    as several convex pieces, one `MeshAsset` each.
    """

    name: str
    vertices: np.ndarray
    faces: np.ndarray

    def __post_init__(self) -> None:
        v = np.asarray(self.vertices, dtype=float).reshape(-1, 3)
        f = np.asarray(self.faces, dtype=np.int64).reshape(-1, 3)
        if len(v) < 4 or len(f) < 4:
            raise ValueError(f"mesh {self.name!r} needs at least 4 vertices and 4 faces")
        if not np.all(np.isfinite(v)):
            raise ValueError(f"mesh {self.name!r} has non-finite vertices")
        if f.min() < 0 or f.max() >= len(v):
            raise ValueError(f"mesh {self.name!r} has face indices out of range")
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "faces", f)

    @property
    def volume(self) -> float:
        """Volume of the mesh's convex hull (m^3), the solid MuJoCo simulates."""
        import trimesh

        return float(trimesh.Trimesh(self.vertices, self.faces, process=False).convex_hull.volume)


@dataclass(frozen=True)
class Part:
    """One primitive geom of an object, in the object's frame (m, wxyz quaternion).

    `size` follows MuJoCo: box half-sizes (x, y, z), cylinder and capsule (radius,
    half-length of the axis along the part's z), sphere (radius,), ellipsoid semi-axes.
    A mesh part names a `MeshAsset` of its object and has an empty size.
    """

    kind: PartKind
    size: tuple[float, ...]
    pos: tuple[float, float, float] = (0.0, 0.0, 0.0)
    quat: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    mesh: str | None = None
    #: Optional colour of this part; the object's colour when None.
    rgba: tuple[float, float, float, float] | None = None

    def __post_init__(self) -> None:
        if self.kind not in GEOM_TYPE:
            raise ValueError(f"unknown part kind {self.kind!r}")
        if self.kind == "mesh":
            if not self.mesh:
                raise ValueError("a mesh part needs a mesh name")
        elif len(self.size) != SIZE_LEN[self.kind] or min(self.size) <= 0:
            raise ValueError(f"bad size {self.size} for a {self.kind}")
        n = math.sqrt(sum(q * q for q in self.quat))
        if not 0.999 < n < 1.001:
            raise ValueError(f"part quaternion {self.quat} is not unit length")


@dataclass(frozen=True, kw_only=True)
class ObjectModel:
    """A household object: its parts, physical properties and look.

    `mass` is the total mass (kg), `friction` the sliding coefficient against other
    surfaces, `height` the upright height (m) with the bottom at z = 0 of the object frame.
    `meshes` holds the mesh assets that mesh parts refer to.
    """

    name: str
    category: str
    parts: tuple[Part, ...]
    mass: float
    friction: float
    rgba: tuple[float, float, float, float]
    optical: OpticalKind = "opaque"
    height: float
    meshes: tuple[MeshAsset, ...] = field(default=())

    def __post_init__(self) -> None:
        if not self.parts:
            raise ValueError(f"object {self.name!r} has no parts")
        if not (self.mass > 0 and math.isfinite(self.mass)):
            raise ValueError(f"object {self.name!r}: mass must be positive, got {self.mass}")
        if not (self.friction > 0 and math.isfinite(self.friction)):
            raise ValueError(f"object {self.name!r}: friction must be positive")
        if self.optical not in OPTICAL_GROUP:
            raise ValueError(f"object {self.name!r}: unknown optical kind {self.optical!r}")
        names = {m.name for m in self.meshes}
        for p in self.parts:
            if p.kind == "mesh" and p.mesh not in names:
                raise ValueError(f"object {self.name!r}: part uses unknown mesh {p.mesh!r}")

    @property
    def group(self) -> int:
        """The geom group of this object's geoms (see `GROUP_OPAQUE` and friends)."""
        return OPTICAL_GROUP[self.optical]

    def mesh_asset(self, name: str) -> MeshAsset:
        """The mesh asset called `name`."""
        for m in self.meshes:
            if m.name == name:
                return m
        raise KeyError(name)
