"""Scenes: support surfaces and household objects around the scooter, described in YAML.

A scene file names the scooter's start pose, the surfaces (tables, shelves, counters, floor
areas), optional user mesh models, explicit object placements, random placement rules and
named marker points. `load_scene` turns a file (or a built-in name) into a `Scene`;
`add_scene_to_spec` adds its surfaces and objects to a MuJoCo spec.

Frames and units: world has z up and its origin on the floor; lengths in metres, masses in
kg. Angles in YAML are degrees (`yaw_deg`, about +z, counter-clockwise seen from above); the
`Scene` holds radians. A surface's local frame has its origin at the centre of its footprint
on the floor, x along its depth (`size[0]`) and y along its width (`size[1]`); its front, the
open side of a shelf, faces local -x, so yaw 0 presents it to a scooter looking along +x.

Schema (all keys optional unless marked *):

```yaml
name: kitchen*                    # scene name
description: free text
scooter: {x: 0.0, y: 0.0, yaw_deg: 0.0}   # start pose of the scooter's `base` frame in world
surfaces:
  - name: table*                  # letters, digits, _ and -
    kind: table*                  # table | shelf | counter | floor
    xy: [1.6, -0.15]*             # centre of the footprint in world (m)
    yaw_deg: 0
    size: [0.6, 1.0]*             # depth along local x, width along local y (m)
    height: 0.46                  # top height (m); required for tables and counters
    levels: [0.05, 0.38, 0.69, 1.0]   # shelves only: board top heights, ascending (m)
    rgba: [0.5, 0.4, 0.3, 1]
models:                           # user meshes, usable wherever a library name is
  my_cup: {mesh: cup.obj*, scale: 0.001, mass: 0.2*, friction: 0.6, rgba: [1, 0, 0, 1],
           optical: opaque, collision: hull}       # hull | decompose (needs coacd)
objects:                          # explicit placements
  - {name: can1*, model: soda_can*, on: table, xy: [1.4, -0.2], yaw_deg: 30, level: 2,
     lying: false}                # either xy (world) or at: <marker name>
random:                           # random placement rules
  - {count: 6*, on: table*, models: any, min_gap: 0.02, orientation: upright, seed: 1,
     margin: 0.05, region: [-0.25, 0.15, -0.4, 0.4], level: null}
markers:                          # named points on surfaces
  - {name: loc1*, on: table*, xy: [1.35, 0.0]*, level: null}
```

Objects rest on the top of their surface (or the given shelf level, the top one by default),
1.5 mm above it so they settle. Random rules draw `count` models (without replacement while
they last; `any` is every opaque library object that fits), a yaw, and for `coin_flip` an
upright or lying pose, and place them by rejection sampling so that footprint circles keep
`min_gap` from each other and `margin` from the surface edges (or stay inside `region`, given
in the surface's local frame as [xmin, xmax, ymin, ymax]). Lying is only for an object that
rests on its side (`objects.at_rest`): a banana's curve tips it over, so `lying: true` on a
banana is an error, and a coin flip stands it upright.
"""

from __future__ import annotations

import io
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, Literal

import mujoco
import numpy as np
import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from laserpick.description import dims
from laserpick.robot.sim.objects import (
    GROUP_OPAQUE,
    LIBRARY,
    SURFACE_CONAFFINITY,
    SURFACE_CONTYPE,
    TRANSPARENT_ALPHA,
    MeshAsset,
    ObjectModel,
    OpticalKind,
    Part,
    add_object_body,
    at_rest,
    footprint_half_extents,
    opaque_names,
    quat_mul,
    rest_pose,
    support,
    yaw_quat,
)

#: Where the built-in scene files live.
SCENE_DIR = Path(__file__).parent / "scene_files"
#: Largest scene file accepted (bytes).
MAX_SCENE_BYTES = 1_000_000
#: Largest mesh file accepted (bytes) and most faces in a mesh.
MAX_MESH_BYTES = 20 * 1024 * 1024
MAX_MESH_FACES = 200_000
#: Largest extent of a user mesh after scaling (m): household objects, not furniture.
MAX_MESH_EXTENT = 1.0
#: Most objects in a scene, and per random rule.
MAX_OBJECTS = 300
MAX_RANDOM_COUNT = 100
#: Gap left between an object's lowest point and its surface at placement (m).
REST_CLEARANCE = 0.0015
#: Friction of the surfaces: sliding, torsional, rolling.
SURFACE_FRICTION = (0.8, 0.005, 0.0001)
#: Table top slab thickness (m), leg side (m) and leg inset from the top's corners (m).
TABLE_TOP_THICKNESS = 0.03
TABLE_LEG_SIDE = 0.04
TABLE_LEG_INSET = 0.03
#: Shelf board thickness, side panel thickness and back panel thickness (m).
SHELF_BOARD = 0.02
SHELF_PANEL = 0.018
SHELF_BACK = 0.012
#: Minimum free height between two shelf boards (m).
SHELF_MIN_GAP = 0.05
#: Tries per object before a random rule gives up, and rule restarts.
PLACEMENT_TRIES = 400
PLACEMENT_RESTARTS = 25

SurfaceKind = Literal["table", "shelf", "counter", "floor"]

_DEFAULT_RGBA: dict[str, tuple[float, float, float, float]] = {
    "table": (0.55, 0.4, 0.25, 1.0),
    "shelf": (0.65, 0.5, 0.33, 1.0),
    "counter": (0.82, 0.82, 0.8, 1.0),
    "floor": (0.5, 0.5, 0.5, 1.0),
}
_DEFAULT_MODEL_RGBA = (0.7, 0.7, 0.72, 1.0)


def _scooter_footprint() -> tuple[float, float, float, float]:
    """The scooter's footprint in `base` (xmin, xmax, ymin, ymax, m), arm base included."""
    xmin = -dims.SCOOTER_REAR_OVERHANG
    xmax = max(
        dims.SCOOTER_LENGTH - dims.SCOOTER_REAR_OVERHANG,
        float(dims.ARM_MOUNT_POS[0]) + dims.UR5_LINK_RADII[0],
        float(dims.BASKET_CENTER[0]) + float(dims.BASKET_INNER[0]) / 2 + dims.BASKET_WALL,
    )
    half_w = max(dims.SCOOTER_WIDTH / 2, abs(float(dims.ARM_MOUNT_POS[1])) + 0.075)
    return xmin, xmax, -half_w, half_w


#: The scooter's footprint in `base` (xmin, xmax, ymin, ymax, m); no surface may overlap it.
SCOOTER_FOOTPRINT = _scooter_footprint()


# --- errors ------------------------------------------------------------------------------


class SceneError(ValueError):
    """A scene that cannot be loaded: names the file, the field path and what is wrong.

    `problems` lists (field path, message) pairs; the path looks like `objects[2].on`.
    """

    def __init__(self, file: str, problems: list[tuple[str, str]]) -> None:
        self.file = file
        self.problems = problems
        text = "; ".join(f"{path}: {msg}" if path else msg for path, msg in problems)
        super().__init__(f"{file}: {text}")

    def __reduce__(self) -> tuple[type[SceneError], tuple[str, list[tuple[str, str]]]]:
        return SceneError, (self.file, self.problems)  # crosses process boundaries intact


# --- the YAML schema ---------------------------------------------------------------------

Name = Annotated[str, Field(pattern=r"^[A-Za-z0-9_\-]{1,64}$")]
_NAME_RULE = "must be 1-64 characters: letters, digits, '_' or '-'"
Finite = float
XY = tuple[float, float]
RGBA = tuple[
    Annotated[float, Field(ge=0, le=1)],
    Annotated[float, Field(ge=0, le=1)],
    Annotated[float, Field(ge=0, le=1)],
    Annotated[float, Field(ge=0, le=1)],
]


class _Cfg(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class ScooterCfg(_Cfg):
    """Start pose of the scooter's `base` frame in world: x, y (m) and yaw (degrees)."""

    x: float = 0.0
    y: float = 0.0
    yaw_deg: float = 0.0


class SurfaceCfg(_Cfg):
    """A support surface; see the module docstring for the frame conventions."""

    name: Name
    kind: SurfaceKind
    xy: XY
    yaw_deg: float = 0.0
    size: tuple[Annotated[float, Field(gt=0, le=20)], Annotated[float, Field(gt=0, le=20)]]
    height: Annotated[float, Field(ge=0, le=3)] | None = None
    levels: list[Annotated[float, Field(gt=0, le=3)]] | None = Field(default=None, max_length=12)
    rgba: RGBA | None = None


class ModelCfg(_Cfg):
    """A user object model from a mesh file (OBJ or STL) relative to the scene file."""

    mesh: str = Field(min_length=1, max_length=512)
    scale: Any = 1.0
    mass: Annotated[float, Field(gt=0, le=50)]
    friction: Annotated[float, Field(gt=0, le=5)] = 0.6
    rgba: RGBA | None = None
    optical: OpticalKind = "opaque"
    collision: Literal["hull", "decompose"] = "hull"
    category: str = Field(default="user", max_length=64)

    @field_validator("scale")
    @classmethod
    def _check_scale(cls, v: Any) -> tuple[float, float, float]:
        vals = [v] * 3 if isinstance(v, int | float) and not isinstance(v, bool) else v
        if not isinstance(vals, list | tuple) or len(vals) != 3:
            raise ValueError("must be a number or a list of three numbers [sx, sy, sz]")
        out = []
        for x in vals:
            if isinstance(x, bool) or not isinstance(x, int | float):
                raise ValueError(f"scale factors must be numbers, got {x!r}")
            if not (math.isfinite(x) and x > 0):
                raise ValueError(f"scale factors must be positive and finite, got {x!r}")
            out.append(float(x))
        return (out[0], out[1], out[2])


class ObjectCfg(_Cfg):
    """An explicit placement: instance `name` of `model` on surface `on`."""

    name: Name
    model: Name
    on: Name | None = None
    xy: XY | None = None
    at: Name | None = None
    yaw_deg: float = 0.0
    level: Annotated[int, Field(ge=0)] | None = None
    lying: bool = False


class RandomCfg(_Cfg):
    """A random placement rule: `count` objects drawn from `models` on surface `on`."""

    count: Annotated[int, Field(ge=1, le=MAX_RANDOM_COUNT)]
    on: Name
    models: Any = "any"
    min_gap: Annotated[float, Field(ge=0, le=1)] = 0.02
    orientation: Literal["upright", "coin_flip"] = "upright"
    seed: Annotated[int, Field(ge=0)] = 0
    margin: Annotated[float, Field(ge=0, le=1)] = 0.05
    region: tuple[float, float, float, float] | None = None
    level: Annotated[int, Field(ge=0)] | None = None

    @field_validator("models")
    @classmethod
    def _check_models(cls, v: Any) -> str | list[str]:
        if v == "any":
            return v
        if not isinstance(v, list) or not v or not all(isinstance(x, str) for x in v):
            raise ValueError("must be 'any' or a non-empty list of model names")
        return v


class MarkerCfg(_Cfg):
    """A named point on a surface, at world `xy`, on its top (or its shelf `level`)."""

    name: Name
    on: Name
    xy: XY
    level: Annotated[int, Field(ge=0)] | None = None


class SceneCfg(_Cfg):
    """The whole scene file."""

    name: str = Field(min_length=1, max_length=100)
    description: str = Field(default="", max_length=5000)
    scooter: ScooterCfg = ScooterCfg()
    surfaces: list[SurfaceCfg] = Field(default_factory=list, max_length=50)
    models: dict[Name, ModelCfg] = Field(default_factory=dict, max_length=20)
    objects: list[ObjectCfg] = Field(default_factory=list, max_length=MAX_OBJECTS)
    random: list[RandomCfg] = Field(default_factory=list, max_length=20)
    markers: list[MarkerCfg] = Field(default_factory=list, max_length=100)


_SECTION_MODELS: dict[str, type[BaseModel]] = {
    "scooter": ScooterCfg,
    "surfaces": SurfaceCfg,
    "models": ModelCfg,
    "objects": ObjectCfg,
    "random": RandomCfg,
    "markers": MarkerCfg,
}


def _loc_path(loc: tuple[Any, ...]) -> str:
    """('objects', 2, 'on') -> 'objects[2].on'."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        elif part == "[key]":
            out += " (key)"
        else:
            out += f".{part}" if out else str(part)
    return out or "(top level)"


def _pydantic_problems(err: ValidationError) -> list[tuple[str, str]]:
    """Turn a ValidationError into (field path, readable message) pairs."""
    problems = []
    for e in err.errors():
        loc = tuple(e["loc"])
        msg = e["msg"]
        if e["type"] == "extra_forbidden":
            section = loc[0] if len(loc) > 1 else None
            cls = _SECTION_MODELS.get(section, SceneCfg) if isinstance(section, str) else SceneCfg
            allowed = ", ".join(cls.model_fields)
            msg = f"unknown field {loc[-1]!r} (allowed: {allowed})"
        elif e["type"] == "missing":
            msg = "required field is missing"
        elif e["type"] == "string_pattern_mismatch":
            msg = f"{e['input']!r} {_NAME_RULE}"
        elif e["type"] == "finite_number":
            msg = f"must be a finite number, got {e['input']!r}"
        elif msg.startswith("Value error, "):
            msg = msg[len("Value error, ") :]
        elif "input" in e and not isinstance(e["input"], dict | list):
            msg = f"{msg}, got {e['input']!r}"
        problems.append((_loc_path(loc), msg))
    return problems


# --- the loaded scene --------------------------------------------------------------------


@dataclass(frozen=True)
class Surface:
    """A static support surface in world.

    `xy` is the footprint centre (m, world), `yaw` its rotation about +z (rad), `size` the
    (depth, width) of the footprint along its local (x, y) (m), `height` its top (m) and
    `levels` the heights of the surfaces objects rest on: every shelf board top, or
    (height,) for tables and counters, (0.0,) for floor areas.
    """

    name: str
    kind: SurfaceKind
    xy: tuple[float, float]
    yaw: float
    size: tuple[float, float]
    height: float
    levels: tuple[float, ...]
    rgba: tuple[float, float, float, float] | None = None

    def to_local(self, xy: np.ndarray) -> np.ndarray:
        """World (x, y) -> the surface's local (x, y) (m)."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        d = np.asarray(xy, dtype=float)[:2] - np.asarray(self.xy)
        return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])

    def to_world(self, local: np.ndarray) -> np.ndarray:
        """The surface's local (x, y) -> world (x, y) (m)."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        lx, ly = float(local[0]), float(local[1])
        return np.array([self.xy[0] + c * lx - s * ly, self.xy[1] + s * lx + c * ly])

    def area(self) -> tuple[float, float, float, float]:
        """Usable area of each level in the local frame: (xmin, xmax, ymin, ymax) (m).

        For a shelf it is inside the side panels and in front of the back panel.
        """
        d, w = self.size
        if self.kind == "shelf":
            return (-d / 2, d / 2 - SHELF_BACK, -w / 2 + SHELF_PANEL, w / 2 - SHELF_PANEL)
        return (-d / 2, d / 2, -w / 2, w / 2)

    def clearance(self, level: int) -> float:
        """Free height above level `level` (m): up to the next board, unlimited at the top."""
        if level + 1 < len(self.levels):
            return self.levels[level + 1] - SHELF_BOARD - self.levels[level]
        return math.inf

    def contains(self, xy: np.ndarray, margin: float = 0.0) -> bool:
        """Whether world point `xy` lies on the usable area, `margin` (m) inside its edges."""
        lx, ly = self.to_local(xy)
        x0, x1, y0, y1 = self.area()
        return x0 + margin <= lx <= x1 - margin and y0 + margin <= ly <= y1 - margin


@dataclass(frozen=True)
class Placement:
    """An object instance and its initial pose in world: `pos` (3,) m, `quat` (4,) wxyz.

    `pos` is the object frame's origin (the centre of its upright bottom face); `surface`
    and `level` say what it rests on; `lying` whether it was laid on its side.
    """

    instance: str
    model: ObjectModel
    pos: np.ndarray
    quat: np.ndarray
    surface: str
    level: int = 0
    lying: bool = False


@dataclass(frozen=True)
class Scene:
    """A loaded scene: the scooter's start pose (x, y m; yaw rad), surfaces, objects, markers.

    `markers` maps names to world points (3,) (m) on their surface's top.
    """

    name: str
    description: str
    scooter_pose: tuple[float, float, float]
    surfaces: tuple[Surface, ...]
    placements: tuple[Placement, ...]
    source: Path | None
    markers: dict[str, np.ndarray] = field(default_factory=dict)

    def surface(self, name: str) -> Surface:
        """The surface called `name`."""
        for s in self.surfaces:
            if s.name == name:
                return s
        raise KeyError(name)

    def placement(self, instance: str) -> Placement:
        """The placement of object instance `instance`."""
        for p in self.placements:
            if p.instance == instance:
                return p
        raise KeyError(instance)


# --- building ----------------------------------------------------------------------------


@dataclass
class _Placed:
    """Bookkeeping for overlap tests: footprint circle and oriented rectangle in world."""

    placement: Placement
    center: np.ndarray  # footprint centre (x, y), world
    radius: float
    rect: tuple[np.ndarray, np.ndarray, float]  # centre, half extents, angle (rad)


def _rect_corners(center: np.ndarray, half: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    axes = np.array([[c, s], [-s, c]])
    signs = np.array([[1, 1], [1, -1], [-1, -1], [-1, 1]])
    return center + (signs * half) @ axes


def _rects_overlap(
    a: tuple[np.ndarray, np.ndarray, float],
    b: tuple[np.ndarray, np.ndarray, float],
    tol: float = 1e-4,
) -> bool:
    """Separating-axis test of two oriented rectangles (centre, half extents, angle)."""
    ca, cb = _rect_corners(*a), _rect_corners(*b)
    for ang in (a[2], b[2]):
        for axis in (
            np.array([math.cos(ang), math.sin(ang)]),
            np.array([-math.sin(ang), math.cos(ang)]),
        ):
            pa, pb = ca @ axis, cb @ axis
            if pa.max() <= pb.min() + tol or pb.max() <= pa.min() + tol:
                return False
    return True


class _Builder:
    """Turns a validated `SceneCfg` into a `Scene`, raising `SceneError` on the first problem."""

    def __init__(self, cfg: SceneCfg, file: str, base_dir: Path | None, seed: int | None):
        self.cfg = cfg
        self.file = file
        self.base_dir = base_dir
        self.seed = seed
        self.surfaces: dict[str, Surface] = {}
        self.models: dict[str, ObjectModel] = {}
        self.markers: dict[str, np.ndarray] = {}
        self.placed: list[_Placed] = []
        self.names: set[str] = set()
        self._marker_surface: dict[str, tuple[str, int]] = {}

    def fail(self, path: str, msg: str) -> SceneError:
        return SceneError(self.file, [(path, msg)])

    # surfaces
    def build_surfaces(self) -> None:
        for i, sc in enumerate(self.cfg.surfaces):
            path = f"surfaces[{i}]"
            if sc.name in self.surfaces:
                raise self.fail(f"{path}.name", f"duplicate surface name {sc.name!r}")
            levels: tuple[float, ...]
            if sc.kind == "floor":
                if sc.height not in (None, 0.0):
                    raise self.fail(f"{path}.height", "a floor area lies at height 0")
                if sc.levels is not None:
                    raise self.fail(f"{path}.levels", "only shelves have levels")
                height, levels = 0.0, (0.0,)
            elif sc.kind == "shelf":
                if not sc.levels:
                    raise self.fail(f"{path}.levels", "a shelf needs its board heights (levels)")
                levels = tuple(sc.levels)
                if levels[0] < SHELF_BOARD:
                    raise self.fail(f"{path}.levels[0]", f"must be at least {SHELF_BOARD} m")
                for k in range(1, len(levels)):
                    if levels[k] - levels[k - 1] < SHELF_BOARD + SHELF_MIN_GAP:
                        raise self.fail(
                            f"{path}.levels[{k}]",
                            f"levels must ascend with at least {SHELF_MIN_GAP} m between boards",
                        )
                height = levels[-1]
                if sc.height is not None and abs(sc.height - height) > 1e-9:
                    raise self.fail(
                        f"{path}.height", "a shelf's height is its top level; omit it or match it"
                    )
                d, w = sc.size
                if d < SHELF_BACK + 0.05 or w < 2 * SHELF_PANEL + 0.05:
                    raise self.fail(f"{path}.size", "too small for a shelf")
            else:
                if sc.height is None:
                    raise self.fail(f"{path}.height", f"a {sc.kind} needs a height")
                if sc.height <= 0:
                    raise self.fail(f"{path}.height", f"a {sc.kind} must be higher than 0 m")
                if sc.levels is not None:
                    raise self.fail(f"{path}.levels", "only shelves have levels")
                height, levels = sc.height, (sc.height,)
            surf = Surface(
                name=sc.name,
                kind=sc.kind,
                xy=(sc.xy[0], sc.xy[1]),
                yaw=math.radians(sc.yaw_deg),
                size=(sc.size[0], sc.size[1]),
                height=height,
                levels=levels,
                rgba=sc.rgba,
            )
            self._check_surface_clear(path, surf)
            self.surfaces[sc.name] = surf

    def _surface_rect(self, s: Surface) -> tuple[np.ndarray, np.ndarray, float]:
        return (np.array(s.xy), np.array(s.size) / 2, s.yaw)

    def _check_surface_clear(self, path: str, surf: Surface) -> None:
        if surf.kind == "floor":
            return
        x, y, yaw = self.scooter_pose
        x0, x1, y0, y1 = SCOOTER_FOOTPRINT
        c, s = math.cos(yaw), math.sin(yaw)
        cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
        scooter = (
            np.array([x + c * cx - s * cy, y + s * cx + c * cy]),
            np.array([(x1 - x0) / 2, (y1 - y0) / 2]),
            yaw,
        )
        if _rects_overlap(self._surface_rect(surf), scooter):
            raise self.fail(path, f"surface {surf.name!r} overlaps the scooter at its start pose")
        for other in self.surfaces.values():
            if other.kind != "floor" and _rects_overlap(
                self._surface_rect(surf), self._surface_rect(other)
            ):
                raise self.fail(path, f"surface {surf.name!r} overlaps surface {other.name!r}")

    @property
    def scooter_pose(self) -> tuple[float, float, float]:
        sc = self.cfg.scooter
        return (sc.x, sc.y, math.radians(sc.yaw_deg))

    # models
    def build_models(self) -> None:
        for name, mc in self.cfg.models.items():
            path = f"models.{name}"
            if name in LIBRARY:
                raise self.fail(path, f"{name!r} is a library object; pick another name")
            self.models[name] = _mesh_model(name, mc, self.base_dir, self.fail, path)

    def model(self, name: str, path: str) -> ObjectModel:
        if name in self.models:
            return self.models[name]
        if name in LIBRARY:
            return LIBRARY[name]
        raise self.fail(path, f"unknown model {name!r}; not in the library or this scene's models")

    def surface(self, name: str | None, path: str) -> Surface:
        if name is None:
            raise self.fail(path, "required field is missing")
        if name not in self.surfaces:
            known = ", ".join(self.surfaces) or "none"
            raise self.fail(path, f"unknown surface {name!r} (surfaces: {known})")
        return self.surfaces[name]

    def level(self, surf: Surface, level: int | None, path: str) -> int:
        if level is None:
            return len(surf.levels) - 1
        if surf.kind != "shelf" and level != 0:
            raise self.fail(path, f"{surf.name!r} is a {surf.kind}; only shelves have levels")
        if level >= len(surf.levels):
            raise self.fail(path, f"{surf.name!r} has levels 0..{len(surf.levels) - 1}")
        return level

    # markers
    def build_markers(self) -> None:
        for i, mc in enumerate(self.cfg.markers):
            path = f"markers[{i}]"
            if mc.name in self.markers:
                raise self.fail(f"{path}.name", f"duplicate marker name {mc.name!r}")
            surf = self.surface(mc.on, f"{path}.on")
            lvl = self.level(surf, mc.level, f"{path}.level")
            if not surf.contains(np.array(mc.xy)):
                raise self.fail(f"{path}.xy", f"{list(mc.xy)} is not on surface {surf.name!r}")
            self.markers[mc.name] = np.array([mc.xy[0], mc.xy[1], surf.levels[lvl]])
            self._marker_surface[mc.name] = (surf.name, lvl)

    # placements
    def _pose(
        self, model: ObjectModel, surf: Surface, level: int, xy: np.ndarray, yaw: float, lying: bool
    ) -> _Placed:
        rp = rest_pose(model, lying)
        q = quat_mul(yaw_quat(yaw), rp.quat)
        c, s = math.cos(yaw), math.sin(yaw)
        offset = np.array(
            [c * rp.center[0] - s * rp.center[1], s * rp.center[0] + c * rp.center[1]]
        )
        pos = np.array(
            [xy[0] - offset[0], xy[1] - offset[1], surf.levels[level] + rp.z + REST_CLEARANCE]
        )
        # Footprint rectangle: extents along the object's yawed x and y axes.
        half = footprint_half_extents(model, rp)
        placement = Placement("", model, pos, q, surf.name, level, lying)
        return _Placed(
            placement, np.asarray(xy, dtype=float), rp.radius, (np.asarray(xy, float), half, yaw)
        )

    def _name(self, base: str) -> str:
        n = 1
        while f"{base}_{n}" in self.names:
            n += 1
        return f"{base}_{n}"

    def _commit(self, placed: _Placed, instance: str) -> None:
        p = placed.placement
        placed.placement = Placement(instance, p.model, p.pos, p.quat, p.surface, p.level, p.lying)
        self.placed.append(placed)
        self.names.add(instance)

    def build_objects(self) -> None:
        # Reserve the explicit names first so generated names never take one.
        for i, oc in enumerate(self.cfg.objects):
            if oc.name in self.names:
                raise self.fail(f"objects[{i}].name", f"duplicate object name {oc.name!r}")
            self.names.add(oc.name)
        for i, oc in enumerate(self.cfg.objects):
            path = f"objects[{i}]"
            model = self.model(oc.model, f"{path}.model")
            if (oc.xy is None) == (oc.at is None):
                raise self.fail(path, "give exactly one of xy (world) or at (a marker name)")
            level_in = oc.level
            if oc.at is not None:
                if oc.at not in self.markers:
                    raise self.fail(f"{path}.at", f"unknown marker {oc.at!r}")
                m_surf, m_level = self._marker_surface[oc.at]
                if oc.on is not None and oc.on != m_surf:
                    raise self.fail(f"{path}.on", f"marker {oc.at!r} is on {m_surf!r}")
                surf = self.surfaces[m_surf]
                level_in = m_level if level_in is None else level_in
                xy = self.markers[oc.at][:2]
            else:
                surf = self.surface(oc.on, f"{path}.on")
                xy = np.array(oc.xy, dtype=float)
            level = self.level(surf, level_in, f"{path}.level")
            if oc.lying and not at_rest(model, lying=True):
                raise self.fail(
                    f"{path}.lying",
                    f"{oc.model!r} does not rest on its side: laid so, it tips over at a touch;"
                    " stand it upright",
                )
            placed = self._pose(model, surf, level, xy, math.radians(oc.yaw_deg), oc.lying)
            self._check_fits(placed, surf, level, path, oc.model)
            for other in self.placed:
                op = other.placement
                if (
                    op.surface == surf.name
                    and op.level == level
                    and _rects_overlap(placed.rect, other.rect)
                ):
                    raise self.fail(path, f"{oc.name!r} overlaps {op.instance!r}")
            self._commit(placed, oc.name)

    def _check_fits(
        self, placed: _Placed, surf: Surface, level: int, path: str, mname: str
    ) -> None:
        p = placed.placement
        x0, x1, y0, y1 = surf.area()
        c, s = math.cos(surf.yaw), math.sin(surf.yaw)
        ex, ey = np.array([c, s, 0.0]), np.array([-s, c, 0.0])
        local = surf.to_local(p.pos[:2])
        sticks = {
            "front (-x)": x0 - (local[0] - support(p.model, -ex, p.quat)),
            "back (+x)": (local[0] + support(p.model, ex, p.quat)) - x1,
            "right (-y)": y0 - (local[1] - support(p.model, -ey, p.quat)),
            "left (+y)": (local[1] + support(p.model, ey, p.quat)) - y1,
        }
        side, out = max(sticks.items(), key=lambda kv: kv[1])
        if out > 1e-6:
            raise self.fail(
                f"{path}.xy",
                f"{mname!r} does not fit on {surf.name!r}: it sticks out {out:.3f} m past "
                f"its {side} edge",
            )
        rp = rest_pose(p.model, p.lying)
        if rp.height + REST_CLEARANCE > surf.clearance(level):
            raise self.fail(
                f"{path}.level",
                f"{mname!r} is {rp.height:.3f} m tall but level {level} of {surf.name!r} has "
                f"{surf.clearance(level):.3f} m of clearance",
            )

    def build_random(self) -> None:
        for i, rc in enumerate(self.cfg.random):
            path = f"random[{i}]"
            surf = self.surface(rc.on, f"{path}.on")
            level = self.level(surf, rc.level, f"{path}.level")
            clearance = surf.clearance(level)

            def fits(m: ObjectModel, rc: RandomCfg = rc, clearance: float = clearance) -> bool:
                h = rest_pose(m).height
                if rc.orientation == "coin_flip":
                    h = max(h, rest_pose(m, True).height)
                return h + REST_CLEARANCE <= clearance

            if rc.models == "any":
                pool = [LIBRARY[n] for n in opaque_names() if fits(LIBRARY[n])]
            else:
                pool = []
                for k, n in enumerate(rc.models):
                    m = self.model(n, f"{path}.models[{k}]")
                    if not fits(m):
                        raise self.fail(
                            f"{path}.models[{k}]",
                            f"{n!r} is too tall for level {level} of {surf.name!r}",
                        )
                    pool.append(m)
            if len(self.placed) + rc.count > MAX_OBJECTS:
                raise self.fail(f"{path}.count", f"a scene holds at most {MAX_OBJECTS} objects")
            # Allowed centres, local frame: the usable area less the margin, within the region.
            x0, x1, y0, y1 = surf.area()
            x0, x1, y0, y1 = x0 + rc.margin, x1 - rc.margin, y0 + rc.margin, y1 - rc.margin
            if rc.region is not None:
                rx0, rx1, ry0, ry1 = rc.region
                if rx0 >= rx1 or ry0 >= ry1:
                    raise self.fail(f"{path}.region", "must be [xmin, xmax, ymin, ymax]")
                x0, x1, y0, y1 = max(x0, rx0), min(x1, rx1), max(y0, ry0), min(y1, ry1)
                if x0 >= x1 or y0 >= y1:
                    raise self.fail(
                        f"{path}.region", f"lies outside the usable area of {surf.name!r}"
                    )
            base_seed = rc.seed if self.seed is None else self.seed
            rng = np.random.default_rng([base_seed, i])
            self._place_random(rc, path, surf, level, pool, (x0, x1, y0, y1), rng)

    def _place_random(
        self,
        rc: RandomCfg,
        path: str,
        surf: Surface,
        level: int,
        pool: list[ObjectModel],
        bounds: tuple[float, float, float, float],
        rng: np.random.Generator,
    ) -> None:
        x0, x1, y0, y1 = bounds
        start = len(self.placed)
        # Circles can cover at most pi / sqrt(12) of a region (hexagonal packing).
        capacity = math.pi / math.sqrt(12) * (x1 - x0 + rc.min_gap) * (y1 - y0 + rc.min_gap)
        for _attempt in range(PLACEMENT_RESTARTS):
            del self.placed[start:]
            picks = rng.choice(len(pool), size=rc.count, replace=rc.count > len(pool))
            poses = []
            for k in picks:
                heads = rc.orientation == "coin_flip" and rng.random() < 0.5
                model = pool[int(k)]
                # Heads lays it on its side only where it rests so (`at_rest`).
                lying = bool(heads) and at_rest(model, lying=True)
                r = rest_pose(model, lying).radius
                if x1 - x0 < 2 * r or y1 - y0 < 2 * r:
                    raise self.fail(
                        path,
                        f"{model.name!r} (footprint radius {r:.3f} m) does not fit in the "
                        f"placement area of {surf.name!r}",
                    )
                poses.append((model, lying, float(rng.uniform(-math.pi, math.pi)), r))
            if sum(math.pi * (r + rc.min_gap / 2) ** 2 for *_, r in poses) > capacity:
                continue  # these picks cannot fit; draw again
            # Footprint circles already on this surface level: centres (n, 2) and radii (n,).
            others = [
                o
                for o in self.placed
                if o.placement.surface == surf.name and o.placement.level == level
            ]
            centres = np.array([o.center for o in others]).reshape(-1, 2)
            radii = np.array([o.radius for o in others])
            for model, lying, yaw, r in poses:
                local = np.column_stack(
                    [
                        rng.uniform(x0 + r, x1 - r, PLACEMENT_TRIES),
                        rng.uniform(y0 + r, y1 - r, PLACEMENT_TRIES),
                    ]
                )
                world = np.array([surf.to_world(p) for p in local])
                dist = np.linalg.norm(world[:, None, :] - centres[None, :, :], axis=2)
                free = np.all(dist >= radii[None, :] + r + rc.min_gap, axis=1)
                if not free.any():
                    break
                xy = world[int(np.argmax(free))]
                placed = self._pose(model, surf, level, xy, yaw, lying)
                placed.radius = r
                self.placed.append(placed)
                centres = np.vstack([centres, xy])
                radii = np.append(radii, r)
            else:
                for placed in self.placed[start:]:
                    instance = self._name(placed.placement.model.name)
                    self.names.add(instance)
                    p = placed.placement
                    placed.placement = Placement(
                        instance, p.model, p.pos, p.quat, p.surface, p.level, p.lying
                    )
                return
        del self.placed[start:]
        raise self.fail(
            path,
            f"could not place {rc.count} objects on {surf.name!r} with min_gap {rc.min_gap} m "
            f"after {PLACEMENT_RESTARTS} tries; use fewer objects, a smaller gap or a larger "
            "region",
        )

    def build(self, source: Path | None) -> Scene:
        self.build_surfaces()
        self.build_models()
        self.build_markers()
        self.build_objects()
        self.build_random()
        return Scene(
            name=self.cfg.name,
            description=self.cfg.description,
            scooter_pose=self.scooter_pose,
            surfaces=tuple(self.surfaces.values()),
            placements=tuple(p.placement for p in self.placed),
            source=source,
            markers=dict(self.markers),
        )


# --- user meshes -------------------------------------------------------------------------


def _mesh_model(
    name: str, mc: ModelCfg, base_dir: Path | None, fail: Any, path: str
) -> ObjectModel:
    """Load a user mesh model: checks the path, size and content, then builds collision parts.

    The mesh is scaled, centred in xy on its bounding box and lifted so its lowest point is at
    z = 0. `collision: hull` uses its convex hull (what MuJoCo would collide anyway);
    `decompose` splits it into convex pieces with coacd so concave shapes stay concave.
    """
    import trimesh

    if base_dir is None:
        raise fail(f"{path}.mesh", "mesh models need the scene file's directory (base_dir)")
    rel = Path(mc.mesh)
    if ".." in rel.parts:
        raise fail(f"{path}.mesh", f"{mc.mesh!r} must not contain '..'")
    base = base_dir.resolve()
    full = (rel if rel.is_absolute() else base / rel).resolve()
    if not full.is_relative_to(base):
        raise fail(f"{path}.mesh", f"{mc.mesh!r} lies outside the scene file's directory")
    if full.suffix.lower() not in (".obj", ".stl"):
        raise fail(f"{path}.mesh", f"{mc.mesh!r}: only OBJ and STL meshes are supported")
    if not full.is_file():
        raise fail(f"{path}.mesh", f"mesh file {mc.mesh!r} not found")
    nbytes = full.stat().st_size
    if nbytes > MAX_MESH_BYTES:
        raise fail(
            f"{path}.mesh",
            f"{mc.mesh!r} is {nbytes / 1e6:.1f} MB; the limit is {MAX_MESH_BYTES / 1e6:.0f} MB",
        )
    try:
        # Load from bytes, with no resolver: an OBJ's mtllib or textures are never opened.
        mesh = trimesh.load(
            io.BytesIO(full.read_bytes()),
            file_type=full.suffix.lower()[1:],
            force="mesh",
            process=True,
        )
    except Exception as exc:  # trimesh raises many kinds of errors on bad files
        raise fail(f"{path}.mesh", f"cannot read {mc.mesh!r}: {exc}") from None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise fail(f"{path}.mesh", f"{mc.mesh!r} holds no triangles")
    if len(mesh.faces) > MAX_MESH_FACES:
        raise fail(
            f"{path}.mesh",
            f"{mc.mesh!r} has {len(mesh.faces)} faces; the limit is {MAX_MESH_FACES}",
        )
    if not np.all(np.isfinite(mesh.vertices)):
        raise fail(f"{path}.mesh", f"{mc.mesh!r} has non-finite vertices")
    verts = np.asarray(mesh.vertices, dtype=float) * np.asarray(mc.scale)
    lo, hi = verts.min(axis=0), verts.max(axis=0)
    ext = hi - lo
    if ext.max() > MAX_MESH_EXTENT:
        raise fail(
            f"{path}.scale",
            f"the scaled mesh is {ext.max():.2f} m across; objects must stay "
            f"under {MAX_MESH_EXTENT} m (is the scale right? mm files need scale 0.001)",
        )
    if ext.min() < 1e-3:
        raise fail(f"{path}.mesh", f"{mc.mesh!r} is flat (under 1 mm thick); it needs a volume")
    verts = verts - np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]])
    mesh = trimesh.Trimesh(verts, np.asarray(mesh.faces), process=True)

    pieces: list[tuple[np.ndarray, np.ndarray]]
    if mc.collision == "hull":
        hull = mesh.convex_hull
        pieces = [(np.asarray(hull.vertices), np.asarray(hull.faces))]
    else:
        try:
            import coacd  # type: ignore[import-not-found]
        except ImportError:
            raise fail(
                f"{path}.collision",
                "'decompose' needs the coacd package (pip install coacd); use 'hull' instead",
            ) from None
        try:
            coacd.set_log_level("error")
            parts = coacd.run_coacd(coacd.Mesh(mesh.vertices, mesh.faces))
        except Exception as exc:
            raise fail(f"{path}.collision", f"convex decomposition failed: {exc}") from None
        pieces = []
        for v, f in parts:
            piece = trimesh.Trimesh(np.asarray(v), np.asarray(f)).convex_hull
            if piece.volume > 1e-9:
                pieces.append((np.asarray(piece.vertices), np.asarray(piece.faces)))
        if not pieces:
            raise fail(f"{path}.collision", "convex decomposition produced no pieces")
    meshes = tuple(MeshAsset(f"part{k}", v, f) for k, (v, f) in enumerate(pieces))
    parts_ = tuple(Part("mesh", (), mesh=m.name) for m in meshes)
    rgba = mc.rgba
    if rgba is None:
        rgba = _DEFAULT_MODEL_RGBA
        if mc.optical == "transparent":
            rgba = (*_DEFAULT_MODEL_RGBA[:3], TRANSPARENT_ALPHA)
    return ObjectModel(
        name=name,
        category=mc.category,
        parts=parts_,
        mass=mc.mass,
        friction=mc.friction,
        rgba=rgba,
        optical=mc.optical,
        height=float(verts[:, 2].max()),
        meshes=meshes,
    )


# --- YAML ----------------------------------------------------------------------------------


class _SceneLoader(yaml.SafeLoader):
    """PyYAML's safe loader with YAML 1.2 booleans: only true/false, so `on:` stays a key.

    YAML 1.1 reads on/off/yes/no as booleans, which would turn the `on` field into `True`.
    """


_SceneLoader.yaml_implicit_resolvers = {
    ch: [(tag, rx) for tag, rx in resolvers if tag != "tag:yaml.org,2002:bool"]
    for ch, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
_SceneLoader.add_implicit_resolver(
    "tag:yaml.org,2002:bool",
    re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"),
    list("tTfF"),
)


# --- public API ----------------------------------------------------------------------------


def builtin_scene_names() -> list[str]:
    """Names of the scenes that ship with laserpick, sorted."""
    return sorted(p.stem for p in SCENE_DIR.glob("*.yaml"))


def scene_config(name: str) -> dict[str, Any]:
    """A built-in scene's file as plain data (YAML 1.2 booleans, as `parse_scene` reads it),
    to edit and pass back through `parse_scene(yaml.safe_dump(config))`."""
    data = yaml.load((SCENE_DIR / f"{name}.yaml").read_text(), Loader=_SceneLoader)
    assert isinstance(data, dict)
    return data


def parse_scene(
    text: str,
    source: Path | None = None,
    base_dir: Path | None = None,
    seed: int | None = None,
) -> Scene:
    """Parse scene YAML text (PyYAML's safe loader, YAML 1.2 booleans) into a `Scene`.

    `source` names the file in errors and in `Scene.source`; `base_dir` is where mesh paths
    are resolved (the source's directory by default; uploads without one cannot use meshes);
    `seed` (>= 0) overrides the seeds of the random rules. Raises `SceneError`.
    """
    file = str(source) if source is not None else "<scene>"
    if base_dir is None and source is not None:
        base_dir = Path(source).parent
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int) or seed < 0):
        raise SceneError(file, [("seed", f"must be a non-negative integer, got {seed!r}")])
    if len(text.encode("utf-8", errors="replace")) > MAX_SCENE_BYTES:
        raise SceneError(file, [("", f"scene file is larger than {MAX_SCENE_BYTES} bytes")])
    try:
        data = yaml.load(text, Loader=_SceneLoader)  # a SafeLoader: plain data only
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc)
        raise SceneError(file, [(where, f"YAML syntax error: {problem}")]) from None
    if not isinstance(data, dict):
        got = "an empty file" if data is None else type(data).__name__
        raise SceneError(file, [("(top level)", f"expected a mapping of scene fields, got {got}")])
    try:
        cfg = SceneCfg.model_validate(data)
    except ValidationError as exc:
        raise SceneError(file, _pydantic_problems(exc)) from None
    try:
        return _Builder(cfg, file, base_dir, seed).build(source)
    except SceneError:
        raise
    except (ValueError, TypeError, OverflowError) as exc:  # a guard against odd inputs
        raise SceneError(file, [("", f"invalid scene: {exc}")]) from None


def load_scene(name_or_path: str | Path, seed: int | None = None) -> Scene:
    """Load a built-in scene by name (see `builtin_scene_names`) or a scene YAML file.

    `seed` overrides the random rules' seeds. Raises `SceneError` for missing or bad files.
    """
    name = str(name_or_path)
    if isinstance(name_or_path, str) and re.fullmatch(r"[A-Za-z0-9_\-]+", name):
        path = SCENE_DIR / f"{name}.yaml"
        if not path.is_file():
            known = ", ".join(builtin_scene_names())
            raise SceneError(name, [("", f"no built-in scene {name!r} (built-in: {known})")])
    else:
        path = Path(name_or_path)
    if not path.is_file():
        raise SceneError(str(path), [("", "scene file not found")])
    if path.stat().st_size > MAX_SCENE_BYTES:
        raise SceneError(str(path), [("", f"scene file is larger than {MAX_SCENE_BYTES} bytes")])
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError(str(path), [("", f"cannot read the file: {exc}")]) from None
    return parse_scene(text, source=path, base_dir=path.parent, seed=seed)


def _add_box(
    body: mujoco.MjsBody,
    name: str,
    half: tuple[float, float, float],
    pos: tuple[float, float, float],
    rgba: tuple[float, ...],
) -> None:
    body.add_geom(
        name=name,
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=list(half),
        pos=list(pos),
        rgba=list(rgba),
        friction=list(SURFACE_FRICTION),
        group=GROUP_OPAQUE,
        contype=SURFACE_CONTYPE,
        conaffinity=SURFACE_CONAFFINITY,
    )


def add_surface(spec: mujoco.MjSpec, surf: Surface) -> mujoco.MjsBody:
    """Add one surface as a static body `surface/<name>` with geoms `surface/<name>/<part>`.

    Tables are a 3 cm top slab on four legs, counters a solid block, shelves a board per
    level between two side panels with a back panel; floor areas add an empty body only
    (the ground plane belongs to the robot model).
    """
    name = f"surface/{surf.name}"
    body = spec.worldbody.add_body(
        name=name, pos=[surf.xy[0], surf.xy[1], 0.0], quat=list(yaw_quat(surf.yaw))
    )
    rgba = surf.rgba or _DEFAULT_RGBA[surf.kind]
    d, w = surf.size
    if surf.kind == "table":
        t = min(TABLE_TOP_THICKNESS, surf.height)
        _add_box(body, f"{name}/top", (d / 2, w / 2, t / 2), (0, 0, surf.height - t / 2), rgba)
        leg_h = surf.height - t
        if leg_h > 0.005:
            lx = max(d / 2 - TABLE_LEG_INSET - TABLE_LEG_SIDE / 2, 0.0)
            ly = max(w / 2 - TABLE_LEG_INSET - TABLE_LEG_SIDE / 2, 0.0)
            half = (TABLE_LEG_SIDE / 2, TABLE_LEG_SIDE / 2, leg_h / 2)
            for k, (sx, sy) in enumerate(((1, 1), (1, -1), (-1, -1), (-1, 1))):
                _add_box(body, f"{name}/leg{k}", half, (sx * lx, sy * ly, leg_h / 2), rgba)
    elif surf.kind == "counter":
        _add_box(
            body, f"{name}/block", (d / 2, w / 2, surf.height / 2), (0, 0, surf.height / 2), rgba
        )
    elif surf.kind == "shelf":
        top = surf.levels[-1]
        inner_w = w / 2 - SHELF_PANEL
        for side, sy in (("left", 1), ("right", -1)):
            _add_box(
                body,
                f"{name}/side_{side}",
                (d / 2, SHELF_PANEL / 2, top / 2),
                (0, sy * (w / 2 - SHELF_PANEL / 2), top / 2),
                rgba,
            )
        _add_box(
            body,
            f"{name}/back",
            (SHELF_BACK / 2, inner_w, top / 2),
            (d / 2 - SHELF_BACK / 2, 0, top / 2),
            rgba,
        )
        for k, level in enumerate(surf.levels):
            _add_box(
                body,
                f"{name}/board{k}",
                ((d - SHELF_BACK) / 2, inner_w, SHELF_BOARD / 2),
                (-SHELF_BACK / 2, 0, level - SHELF_BOARD / 2),
                rgba,
            )
    return body


def add_scene_to_spec(spec: mujoco.MjSpec, scene: Scene) -> None:
    """Add the scene's surfaces (static bodies) and objects (free bodies) to `spec`.

    The ground plane and the scooter are not added here: the robot model owns them.
    """
    for surf in scene.surfaces:
        add_surface(spec, surf)
    for p in scene.placements:
        add_object_body(spec, p.instance, p.model, p.pos, p.quat)
