"""Building a `Scene` from a validated scene config: surfaces, models, markers, explicit
objects and random rules, raising `SceneError` on the first problem."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from laserpick.robot.sim.objects import LIBRARY, ObjectModel, at_rest, opaque_names, rest_pose
from laserpick.robot.sim.scenes.errors import SceneError
from laserpick.robot.sim.scenes.meshes import mesh_model
from laserpick.robot.sim.scenes.placement import (
    REST_CLEARANCE,
    Placed,
    check_fits,
    rest_on,
    scatter,
)
from laserpick.robot.sim.scenes.rectangles import rects_overlap
from laserpick.robot.sim.scenes.scene import Placement, Scene
from laserpick.robot.sim.scenes.schema import MAX_OBJECTS, ObjectCfg, RandomCfg, SceneCfg
from laserpick.robot.sim.scenes.surfaces import Surface, check_surface_clear, surface_from_cfg


class SceneBuilder:
    """Turns a validated `SceneCfg` into a `Scene`, raising `SceneError` on the first problem.

    `file` names the scene in errors, `base_dir` is where mesh paths are resolved, and `seed`
    (when not None) overrides the random rules' seeds.
    """

    def __init__(self, cfg: SceneCfg, file: str, base_dir: Path | None, seed: int | None):
        self.cfg = cfg
        self.file = file
        self.base_dir = base_dir
        self.seed = seed
        self.surfaces: dict[str, Surface] = {}
        self.models: dict[str, ObjectModel] = {}
        self.markers: dict[str, np.ndarray] = {}
        self.placed: list[Placed] = []
        self.names: set[str] = set()
        self._marker_surface: dict[str, tuple[str, int]] = {}

    def fail(self, path: str, msg: str) -> SceneError:
        """The error for field `path` of this scene file."""
        return SceneError(self.file, [(path, msg)])

    def build(self, source: Path | None) -> Scene:
        """The scene, with `source` as its `Scene.source`."""
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

    @property
    def scooter_pose(self) -> tuple[float, float, float]:
        """The scooter's start pose in world: x, y (m), yaw (rad)."""
        sc = self.cfg.scooter
        return (sc.x, sc.y, math.radians(sc.yaw_deg))

    # --- surfaces, models and markers ------------------------------------------------------

    def build_surfaces(self) -> None:
        for i, sc in enumerate(self.cfg.surfaces):
            path = f"surfaces[{i}]"
            if sc.name in self.surfaces:
                raise self.fail(f"{path}.name", f"duplicate surface name {sc.name!r}")
            surf = surface_from_cfg(sc, path, self.fail)
            check_surface_clear(surf, self.scooter_pose, self.surfaces.values(), path, self.fail)
            self.surfaces[sc.name] = surf

    def build_models(self) -> None:
        for name, mc in self.cfg.models.items():
            path = f"models.{name}"
            if name in LIBRARY:
                raise self.fail(path, f"{name!r} is a library object; pick another name")
            self.models[name] = mesh_model(name, mc, self.base_dir, self.fail, path)

    def model(self, name: str, path: str) -> ObjectModel:
        """The scene's own model `name`, or the library's."""
        if name in self.models:
            return self.models[name]
        if name in LIBRARY:
            return LIBRARY[name]
        raise self.fail(path, f"unknown model {name!r}; not in the library or this scene's models")

    def surface(self, name: str | None, path: str) -> Surface:
        """The surface called `name`."""
        if name is None:
            raise self.fail(path, "required field is missing")
        if name not in self.surfaces:
            known = ", ".join(self.surfaces) or "none"
            raise self.fail(path, f"unknown surface {name!r} (surfaces: {known})")
        return self.surfaces[name]

    def level(self, surf: Surface, level: int | None, path: str) -> int:
        """The level index `level` of `surf`, checked; its top level when None."""
        if level is None:
            return len(surf.levels) - 1
        if surf.kind != "shelf" and level != 0:
            raise self.fail(path, f"{surf.name!r} is a {surf.kind}; only shelves have levels")
        if level >= len(surf.levels):
            raise self.fail(path, f"{surf.name!r} has levels 0..{len(surf.levels) - 1}")
        return level

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

    # --- objects -----------------------------------------------------------------------------

    def _name(self, base: str) -> str:
        """The first `<base>_<n>` no object has taken."""
        n = 1
        while f"{base}_{n}" in self.names:
            n += 1
        return f"{base}_{n}"

    def _commit(self, placed: Placed, instance: str) -> None:
        p = placed.placement
        placed.placement = Placement(instance, p.model, p.pos, p.quat, p.surface, p.level, p.lying)
        self.placed.append(placed)
        self.names.add(instance)

    def _where(self, oc: ObjectCfg, path: str) -> tuple[Surface, int, np.ndarray]:
        """The surface, level and world (x, y) (m) an explicit object names: its marker's,
        or its own `on` and `xy`."""
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
        return surf, self.level(surf, level_in, f"{path}.level"), xy

    def build_objects(self) -> None:
        # Reserve the explicit names first so generated names never take one.
        for i, oc in enumerate(self.cfg.objects):
            if oc.name in self.names:
                raise self.fail(f"objects[{i}].name", f"duplicate object name {oc.name!r}")
            self.names.add(oc.name)
        for i, oc in enumerate(self.cfg.objects):
            path = f"objects[{i}]"
            model = self.model(oc.model, f"{path}.model")
            surf, level, xy = self._where(oc, path)
            if oc.lying and not at_rest(model, lying=True):
                raise self.fail(
                    f"{path}.lying",
                    f"{oc.model!r} does not rest on its side: laid so, it tips over at a touch;"
                    " stand it upright",
                )
            placed = rest_on(model, surf, level, xy, math.radians(oc.yaw_deg), oc.lying)
            check_fits(placed, surf, level, path, oc.model, self.fail)
            for other in self.placed:
                op = other.placement
                if (
                    op.surface == surf.name
                    and op.level == level
                    and rects_overlap(placed.rect, other.rect)
                ):
                    raise self.fail(path, f"{oc.name!r} overlaps {op.instance!r}")
            self._commit(placed, oc.name)

    # --- random rules ------------------------------------------------------------------------

    def _pool(self, rc: RandomCfg, path: str, surf: Surface, level: int) -> list[ObjectModel]:
        """The models a random rule draws from, each short enough for the level's clearance."""
        clearance = surf.clearance(level)

        def fits(m: ObjectModel) -> bool:
            h = rest_pose(m).height
            if rc.orientation == "coin_flip":
                h = max(h, rest_pose(m, True).height)
            return h + REST_CLEARANCE <= clearance

        if rc.models == "any":
            return [LIBRARY[n] for n in opaque_names() if fits(LIBRARY[n])]
        pool = []
        for k, n in enumerate(rc.models):
            m = self.model(n, f"{path}.models[{k}]")
            if not fits(m):
                raise self.fail(
                    f"{path}.models[{k}]",
                    f"{n!r} is too tall for level {level} of {surf.name!r}",
                )
            pool.append(m)
        return pool

    def _bounds(self, rc: RandomCfg, path: str, surf: Surface) -> tuple[float, float, float, float]:
        """Allowed centres, local frame: the usable area less the margin, within the region."""
        x0, x1, y0, y1 = surf.area()
        x0, x1, y0, y1 = x0 + rc.margin, x1 - rc.margin, y0 + rc.margin, y1 - rc.margin
        if rc.region is not None:
            rx0, rx1, ry0, ry1 = rc.region
            if rx0 >= rx1 or ry0 >= ry1:
                raise self.fail(f"{path}.region", "must be [xmin, xmax, ymin, ymax]")
            x0, x1, y0, y1 = max(x0, rx0), min(x1, rx1), max(y0, ry0), min(y1, ry1)
            if x0 >= x1 or y0 >= y1:
                raise self.fail(f"{path}.region", f"lies outside the usable area of {surf.name!r}")
        return x0, x1, y0, y1

    def build_random(self) -> None:
        for i, rc in enumerate(self.cfg.random):
            path = f"random[{i}]"
            surf = self.surface(rc.on, f"{path}.on")
            level = self.level(surf, rc.level, f"{path}.level")
            pool = self._pool(rc, path, surf, level)
            if len(self.placed) + rc.count > MAX_OBJECTS:
                raise self.fail(f"{path}.count", f"a scene holds at most {MAX_OBJECTS} objects")
            bounds = self._bounds(rc, path, surf)
            base_seed = rc.seed if self.seed is None else self.seed
            rng = np.random.default_rng([base_seed, i])
            new = scatter(rc, path, surf, level, pool, bounds, rng, self.placed, self.fail)
            for placed in new:
                self._commit(placed, self._name(placed.placement.model.name))
