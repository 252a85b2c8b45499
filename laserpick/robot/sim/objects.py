"""The household object library: simple, physically plausible models of everyday objects.

Every object is a rigid body made of a few primitive geoms (or convex mesh pieces for user
meshes). Its frame has its origin at the centre of its bottom face and z up when it stands in
its natural upright pose, so an object placed with its origin on a surface rests on it. All
numbers are SI: metres, kilograms; `friction` is the sliding coefficient.

The categories follow the papers' object sets: the ALS-ranked household objects of EL-E
(000, section 5.2: phone, pill, remote, bottles, cups, utensils, toothbrush, wallet, keys,
glasses case, ...), Jeeves' ten objects (003, section V: soda cans, a chip can, a cleaner
bottle, tea boxes, a vitamin bottle, a stuffed doll) and the UR5 scooter's tabletop set
(004, section 8). Sizes are typical retail sizes; every object fits an 85 mm two-finger
gripper in at least one orientation and weighs at most 1 kg.

Geom groups are a convention shared with the sensor code: surfaces and opaque objects are in
`GROUP_OPAQUE`, the robot in `GROUP_ROBOT`, transparent objects in `GROUP_TRANSPARENT` (the
depth sensors do not see them) and specular objects in `GROUP_SPECULAR`.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

import mujoco
import numpy as np

from laserpick.transforms import matrix_from_quat

OpticalKind = Literal["opaque", "transparent", "specular"]
PartKind = Literal["box", "cylinder", "sphere", "capsule", "ellipsoid", "mesh"]

#: Geom groups shared with the sensor and model code.
GROUP_OPAQUE = 0
GROUP_ROBOT = 1
GROUP_TRANSPARENT = 2
GROUP_SPECULAR = 3

#: Geom group of each optical kind.
OPTICAL_GROUP: dict[str, int] = {
    "opaque": GROUP_OPAQUE,
    "transparent": GROUP_TRANSPARENT,
    "specular": GROUP_SPECULAR,
}
#: Alpha that transparent objects render with in the viewer.
TRANSPARENT_ALPHA = 0.3
#: Torsional and rolling friction of every object geom (m), after the sliding coefficient.
OBJECT_FRICTION_TAIL = (0.005, 0.0005)
#: Contact dimensionality of object geoms: sliding, torsional and rolling friction. Without
#: rolling friction (4) a can laid on its side crept into a roll and off its table within a
#: minute. The pads' contacts take the pads' own (4): they have priority.
OBJECT_CONDIM = 6
#: Collision bitmasks shared with the robot model (two geoms touch if type_a & affinity_b or
#: type_b & affinity_a): surfaces are static (type 1) and touch objects only; objects (type 2)
#: touch the floor and surfaces (1), each other (2), the arm (4) and the scooter (8).
SURFACE_CONTYPE, SURFACE_CONAFFINITY = 1, 2
OBJECT_CONTYPE, OBJECT_CONAFFINITY = 2, 1 | 2 | 4 | 8
#: Widest object the 85 mm gripper takes with some margin (m).
GRIPPABLE_WIDTH = 0.075
#: Heaviest object in the library (kg).
MAX_OBJECT_MASS = 1.0

_GEOM_TYPE = {
    "box": mujoco.mjtGeom.mjGEOM_BOX,
    "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
    "sphere": mujoco.mjtGeom.mjGEOM_SPHERE,
    "capsule": mujoco.mjtGeom.mjGEOM_CAPSULE,
    "ellipsoid": mujoco.mjtGeom.mjGEOM_ELLIPSOID,
    "mesh": mujoco.mjtGeom.mjGEOM_MESH,
}
_SIZE_LEN = {"box": 3, "cylinder": 2, "sphere": 1, "capsule": 2, "ellipsoid": 3, "mesh": 0}


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
        if self.kind not in _GEOM_TYPE:
            raise ValueError(f"unknown part kind {self.kind!r}")
        if self.kind == "mesh":
            if not self.mesh:
                raise ValueError("a mesh part needs a mesh name")
        elif len(self.size) != _SIZE_LEN[self.kind] or min(self.size) <= 0:
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


# --- geometry helpers ---------------------------------------------------------------------


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


# --- MuJoCo -----------------------------------------------------------------------------


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
            type=_GEOM_TYPE[part.kind],
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


# --- the library ------------------------------------------------------------------------

_X_AXIS = tuple(axis_angle_quat((0, 1, 0), math.pi / 2))  # a part's z along the object's x
_Y_AXIS = tuple(axis_angle_quat((1, 0, 0), math.pi / 2))  # a part's z along the object's y


def _box(
    hx: float, hy: float, hz: float, x: float = 0.0, y: float = 0.0, z0: float = 0.0, **kw
) -> Part:
    """A box with half-sizes (hx, hy, hz) whose bottom face is at height z0."""
    return Part("box", (hx, hy, hz), (x, y, z0 + hz), **kw)


def _cyl(r: float, h: float, x: float = 0.0, y: float = 0.0, z0: float = 0.0, **kw) -> Part:
    """An upright cylinder of radius r and full height h whose bottom is at height z0."""
    return Part("cylinder", (r, h / 2), (x, y, z0 + h / 2), **kw)


def _obj(
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


def _bowl() -> list[Part]:
    """A small bowl (13 cm rim, 6 cm tall): a base disc and a ring of 14 tilted wall slabs.

    MuJoCo collides a mesh by its convex hull, which would fill the bowl, so the walls are
    separate thin boxes and the bowl stays hollow for the gripper's fingers.
    """
    parts = [_cyl(0.035, 0.008)]
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


def _stuffed_toy(scale: float) -> list[Part]:
    """A sitting stuffed doll: a flat-bottomed seat, two short legs, torso, arms and head.

    It sits like 003's doll, a balancing pose, but on a flat seat so it stays put; it is
    7.5 cm deep (x) at scale 1, so the gripper can close on it front to back.
    """
    s = scale
    return [
        Part("cylinder", (0.03 * s, 0.015 * s), (0, 0, 0.015 * s)),
        Part("capsule", (0.014 * s, 0.006 * s), (0.024 * s, 0.017 * s, 0.014 * s), _X_AXIS),
        Part("capsule", (0.014 * s, 0.006 * s), (0.024 * s, -0.017 * s, 0.014 * s), _X_AXIS),
        Part("ellipsoid", (0.028 * s, 0.036 * s, 0.045 * s), (0, 0, 0.07 * s)),
        Part("capsule", (0.011 * s, 0.02 * s), (0.005 * s, 0.042 * s, 0.075 * s)),
        Part("capsule", (0.011 * s, 0.02 * s), (0.005 * s, -0.042 * s, 0.075 * s)),
        Part("sphere", (0.034 * s,), (0, 0, 0.14 * s)),
    ]


def _banana() -> list[Part]:
    """A banana lying flat: three capsules along a gentle arc in the xy plane."""
    r, half = 0.018, 0.03
    parts = []
    for k, ang in enumerate((-0.45, 0.0, 0.45)):
        x = (k - 1) * 0.062
        y = 0.012 if k != 1 else 0.0
        q = quat_mul(yaw_quat(ang), np.array(_X_AXIS))
        parts.append(Part("capsule", (r, half), (x, y, r), tuple(float(v) for v in q)))
    return parts


def _mug() -> list[Part]:
    """A small mug: a 7.2 cm body and a D handle of three bars on its +x side."""
    r, h = 0.036, 0.09
    return [
        _cyl(r, h),
        _box(0.011, 0.006, 0.005, x=r + 0.006, z0=0.07),
        _box(0.011, 0.006, 0.005, x=r + 0.006, z0=0.015),
        _box(0.005, 0.006, 0.032, x=r + 0.017, z0=0.018),
    ]


_RED = (0.8, 0.1, 0.1, 1.0)
_WHITE = (0.92, 0.92, 0.9, 1.0)
_BLACK = (0.08, 0.08, 0.08, 1.0)
_STEEL = (0.75, 0.76, 0.78, 1.0)
_CLEAR = (0.7, 0.85, 0.95, TRANSPARENT_ALPHA)


def _build_library() -> dict[str, ObjectModel]:
    objs = [
        # --- drinks and food (004, 003: soda cans, chip can, bottles) ---
        _obj("soda_can", "can", [_cyl(0.033, 0.122)], 0.37, 0.6, _RED),
        _obj("tin_can", "can", [_cyl(0.037, 0.105)], 0.42, 0.5, _STEEL, "specular"),
        _obj(
            "chip_can",
            "can",
            [_cyl(0.0375, 0.23), _cyl(0.0375, 0.01, z0=0.23, rgba=(0.9, 0.6, 0.1, 1))],
            0.2,
            0.6,
            (0.8, 0.05, 0.05, 1),
        ),
        _obj(
            "water_bottle",
            "bottle",
            [
                _cyl(0.032, 0.17),
                _cyl(0.02, 0.02, z0=0.17),
                _cyl(0.014, 0.015, z0=0.19),
                _cyl(0.015, 0.012, z0=0.205, rgba=(0.2, 0.4, 0.9, 1)),
            ],
            0.52,
            0.5,
            _CLEAR,
            "transparent",
        ),
        _obj(
            "juice_bottle",
            "bottle",
            [_cyl(0.034, 0.16), _cyl(0.022, 0.025, z0=0.16), _cyl(0.02, 0.015, z0=0.185)],
            0.55,
            0.6,
            (0.95, 0.55, 0.1, 1),
        ),
        _obj(
            "spray_bottle",
            "bottle",
            [
                _box(0.035, 0.024, 0.085),  # the oval-ish body, like 003's cleaner
                _cyl(0.014, 0.03, z0=0.17),
                _box(0.03, 0.013, 0.018, x=0.012, z0=0.2),  # trigger head
                _box(0.006, 0.008, 0.018, x=0.02, z0=0.165),  # trigger
                _cyl(0.005, 0.01, x=0.045, z0=0.212, quat=_X_AXIS),  # nozzle
            ],
            0.6,
            0.6,
            (0.2, 0.6, 0.9, 1),
        ),
        _obj(
            "pill_bottle",
            "medicine",
            [_cyl(0.021, 0.07, rgba=(0.9, 0.5, 0.1, 1)), _cyl(0.023, 0.016, z0=0.07)],
            0.06,
            0.6,
            _WHITE,
        ),
        _obj(
            "vitamin_bottle",
            "medicine",
            [
                _box(0.018, 0.03, 0.05),
                _cyl(0.03, 0.1, x=0.018),
                _cyl(0.03, 0.1, x=-0.018),
                _cyl(0.022, 0.02, z0=0.1),
            ],
            0.25,
            0.6,
            (0.95, 0.85, 0.3, 1),
        ),
        _obj(
            "pill",
            "medicine",
            [Part("capsule", (0.004, 0.0015), (0, 0, 0.004), _X_AXIS)],
            0.0006,
            0.5,
            _WHITE,
        ),
        _obj("medicine_box", "medicine", [_box(0.05, 0.025, 0.015)], 0.04, 0.6, _WHITE),
        _obj("cereal_box", "box", [_box(0.03, 0.095, 0.125)], 0.3, 0.6, (0.9, 0.75, 0.2, 1)),
        _obj("tea_box", "box", [_box(0.035, 0.065, 0.04)], 0.1, 0.6, (0.2, 0.5, 0.25, 1)),
        _obj("soap_box", "box", [_box(0.045, 0.03, 0.0175)], 0.12, 0.5, (0.6, 0.8, 0.95, 1)),
        _obj("yogurt_cup", "food", [_cyl(0.035, 0.07)], 0.15, 0.6, (0.95, 0.95, 0.85, 1)),
        _obj(
            "spice_jar",
            "food",
            [_cyl(0.022, 0.09, rgba=(0.55, 0.3, 0.1, 1)), _cyl(0.023, 0.015, z0=0.09)],
            0.12,
            0.6,
            _RED,
        ),
        _obj(
            "apple",
            "food",
            [Part("ellipsoid", (0.037, 0.037, 0.033), (0, 0, 0.033))],
            0.18,
            0.7,
            (0.75, 0.1, 0.1, 1),
        ),
        _obj("banana", "food", _banana(), 0.12, 0.7, (0.95, 0.85, 0.2, 1)),
        # --- dishes and utensils ---
        _obj("mug", "dish", _mug(), 0.3, 0.6, (0.2, 0.35, 0.7, 1)),
        _obj("plastic_cup", "dish", [_cyl(0.035, 0.09)], 0.02, 0.5, (0.9, 0.3, 0.5, 1)),
        _obj("glass_cup", "dish", [_cyl(0.035, 0.1)], 0.2, 0.5, _CLEAR, "transparent"),
        _obj("bowl", "dish", _bowl(), 0.25, 0.6, (0.95, 0.95, 0.95, 1)),
        _obj(
            "fork",
            "utensil",
            [_box(0.055, 0.006, 0.0015, x=-0.035), _box(0.025, 0.011, 0.0015, x=0.045)],
            0.04,
            0.4,
            _STEEL,
            "specular",
        ),
        _obj(
            "spoon",
            "utensil",
            [
                _box(0.055, 0.006, 0.0015, x=-0.035),
                Part("ellipsoid", (0.028, 0.018, 0.006), (0.045, 0, 0.006)),
            ],
            0.035,
            0.4,
            _STEEL,
            "specular",
        ),
        # --- personal items (000 section 5.2) ---
        _obj(
            "cordless_phone",
            "phone",
            [_box(0.075, 0.024, 0.014), _box(0.02, 0.022, 0.004, x=0.05, z0=0.028)],
            0.14,
            0.7,
            (0.15, 0.15, 0.18, 1),
        ),
        _obj("cell_phone", "phone", [_box(0.073, 0.0355, 0.004)], 0.17, 0.5, _BLACK),
        _obj("tv_remote", "remote", [_box(0.09, 0.025, 0.011)], 0.12, 0.7, (0.2, 0.2, 0.22, 1)),
        _obj(
            "toothbrush",
            "hygiene",
            [_box(0.07, 0.0065, 0.0075), _box(0.0125, 0.006, 0.0085, x=0.0825)],
            0.02,
            0.6,
            (0.3, 0.7, 0.9, 1),
        ),
        _obj("toothpaste", "hygiene", [_box(0.09, 0.022, 0.015)], 0.12, 0.6, _WHITE),
        _obj("tissue_packet", "hygiene", [_box(0.053, 0.027, 0.0125)], 0.02, 0.8, _WHITE),
        _obj(
            "computer_mouse",
            "electronics",
            [_box(0.05, 0.028, 0.006), Part("ellipsoid", (0.052, 0.03, 0.018), (0, 0, 0.018))],
            0.09,
            0.6,
            (0.3, 0.3, 0.32, 1),
        ),
        _obj(
            "marker",
            "stationery",
            [
                Part("cylinder", (0.009, 0.055), (-0.01, 0, 0.009), _X_AXIS),
                Part("cylinder", (0.009, 0.02), (0.065, 0, 0.009), _X_AXIS, rgba=_BLACK),
            ],
            0.015,
            0.5,
            _WHITE,
        ),
        _obj("glasses_case", "personal", [_box(0.08, 0.032, 0.02)], 0.08, 0.7, (0.4, 0.2, 0.1, 1)),
        _obj("wallet", "personal", [_box(0.055, 0.036, 0.01)], 0.1, 0.8, (0.35, 0.2, 0.1, 1)),
        _obj(
            "keys",
            "personal",
            [_box(0.03, 0.015, 0.006, rgba=_BLACK), _box(0.025, 0.01, 0.0015, x=0.055)],
            0.05,
            0.5,
            _STEEL,
        ),
        # --- toys (003's stuffed doll, 004) ---
        _obj("stuffed_toy", "toy", _stuffed_toy(1.0), 0.15, 0.9, (0.6, 0.45, 0.3, 1)),
        _obj("small_plush", "toy", _stuffed_toy(0.7), 0.06, 0.9, (0.9, 0.6, 0.7, 1)),
        _obj(
            "ball", "toy", [Part("sphere", (0.034,), (0, 0, 0.034))], 0.058, 0.8, (0.8, 0.9, 0.2, 1)
        ),
    ]
    lib = {o.name: o for o in objs}
    if len(lib) != len(objs):
        raise ValueError("duplicate object names in the library")
    return lib


#: The built-in household objects by name.
LIBRARY: dict[str, ObjectModel] = _build_library()


def opaque_names() -> list[str]:
    """Names of the opaque library objects, sorted: the default pool for random placement."""
    return sorted(n for n, o in LIBRARY.items() if o.optical == "opaque")
