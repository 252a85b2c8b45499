"""The scene file's structure: pydantic models of each section, and readable validation errors.

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

The package docstring gives the frames and how objects are placed.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from laserpick.robot.sim.objects import OpticalKind

#: Most objects in a scene, and per random rule.
MAX_OBJECTS = 300
MAX_RANDOM_COUNT = 100

SurfaceKind = Literal["table", "shelf", "counter", "floor"]

Name = Annotated[str, Field(pattern=r"^[A-Za-z0-9_\-]{1,64}$")]
_NAME_RULE = "must be 1-64 characters: letters, digits, '_' or '-'"
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


def pydantic_problems(err: ValidationError) -> list[tuple[str, str]]:
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
