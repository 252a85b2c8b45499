"""The loaded scene: the scooter's start pose, surfaces, object placements and markers, in world."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from laserpick.robot.sim.objects import ObjectModel
from laserpick.robot.sim.scenes.surfaces import Surface


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
