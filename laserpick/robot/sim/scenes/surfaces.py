"""Support surfaces: tables, shelves, counters and floor areas, built from their config and
checked clear of the scooter and of each other."""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from laserpick.description import dims
from laserpick.robot.sim.scenes.errors import Fail
from laserpick.robot.sim.scenes.rectangles import Rect, rects_overlap
from laserpick.robot.sim.scenes.schema import SurfaceCfg, SurfaceKind

#: Shelf board thickness, side panel thickness and back panel thickness (m).
SHELF_BOARD = 0.02
SHELF_PANEL = 0.018
SHELF_BACK = 0.012
#: Minimum free height between two shelf boards (m).
SHELF_MIN_GAP = 0.05


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


def _levels(sc: SurfaceCfg, path: str, fail: Fail) -> tuple[float, tuple[float, ...]]:
    """The surface's top height (m) and the heights objects rest on, checked for its kind."""
    levels: tuple[float, ...]
    if sc.kind == "floor":
        if sc.height not in (None, 0.0):
            raise fail(f"{path}.height", "a floor area lies at height 0")
        if sc.levels is not None:
            raise fail(f"{path}.levels", "only shelves have levels")
        height, levels = 0.0, (0.0,)
    elif sc.kind == "shelf":
        if not sc.levels:
            raise fail(f"{path}.levels", "a shelf needs its board heights (levels)")
        levels = tuple(sc.levels)
        if levels[0] < SHELF_BOARD:
            raise fail(f"{path}.levels[0]", f"must be at least {SHELF_BOARD} m")
        for k in range(1, len(levels)):
            if levels[k] - levels[k - 1] < SHELF_BOARD + SHELF_MIN_GAP:
                raise fail(
                    f"{path}.levels[{k}]",
                    f"levels must ascend with at least {SHELF_MIN_GAP} m between boards",
                )
        height = levels[-1]
        if sc.height is not None and abs(sc.height - height) > 1e-9:
            raise fail(f"{path}.height", "a shelf's height is its top level; omit it or match it")
        d, w = sc.size
        if d < SHELF_BACK + 0.05 or w < 2 * SHELF_PANEL + 0.05:
            raise fail(f"{path}.size", "too small for a shelf")
    else:
        if sc.height is None:
            raise fail(f"{path}.height", f"a {sc.kind} needs a height")
        if sc.height <= 0:
            raise fail(f"{path}.height", f"a {sc.kind} must be higher than 0 m")
        if sc.levels is not None:
            raise fail(f"{path}.levels", "only shelves have levels")
        height, levels = sc.height, (sc.height,)
    return height, levels


def surface_from_cfg(sc: SurfaceCfg, path: str, fail: Fail) -> Surface:
    """The surface a scene file's `surfaces[i]` entry (at `path`) describes, checked."""
    height, levels = _levels(sc, path, fail)
    return Surface(
        name=sc.name,
        kind=sc.kind,
        xy=(sc.xy[0], sc.xy[1]),
        yaw=math.radians(sc.yaw_deg),
        size=(sc.size[0], sc.size[1]),
        height=height,
        levels=levels,
        rgba=sc.rgba,
    )


def _footprint(s: Surface) -> Rect:
    return (np.array(s.xy), np.array(s.size) / 2, s.yaw)


def check_surface_clear(
    surf: Surface,
    scooter_pose: tuple[float, float, float],
    others: Iterable[Surface],
    path: str,
    fail: Fail,
) -> None:
    """Raise unless `surf` keeps off the scooter at its start pose (x, y m; yaw rad) and off
    every other surface; floor areas may overlap anything."""
    if surf.kind == "floor":
        return
    x, y, yaw = scooter_pose
    x0, x1, y0, y1 = SCOOTER_FOOTPRINT
    c, s = math.cos(yaw), math.sin(yaw)
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    scooter = (
        np.array([x + c * cx - s * cy, y + s * cx + c * cy]),
        np.array([(x1 - x0) / 2, (y1 - y0) / 2]),
        yaw,
    )
    if rects_overlap(_footprint(surf), scooter):
        raise fail(path, f"surface {surf.name!r} overlaps the scooter at its start pose")
    for other in others:
        if other.kind != "floor" and rects_overlap(_footprint(surf), _footprint(other)):
            raise fail(path, f"surface {surf.name!r} overlaps surface {other.name!r}")
