"""Adding a scene to a MuJoCo spec: its surfaces as static bodies and its objects as free ones."""

from __future__ import annotations

import mujoco

from laserpick.robot.sim.objects import (
    GROUP_OPAQUE,
    SURFACE_CONAFFINITY,
    SURFACE_CONTYPE,
    add_object_body,
    yaw_quat,
)
from laserpick.robot.sim.scenes.scene import Scene
from laserpick.robot.sim.scenes.surfaces import SHELF_BACK, SHELF_BOARD, SHELF_PANEL, Surface

#: Friction of the surfaces: sliding, torsional, rolling.
SURFACE_FRICTION = (0.8, 0.005, 0.0001)
#: Table top slab thickness (m), leg side (m) and leg inset from the top's corners (m).
TABLE_TOP_THICKNESS = 0.03
TABLE_LEG_SIDE = 0.04
TABLE_LEG_INSET = 0.03

_DEFAULT_RGBA: dict[str, tuple[float, float, float, float]] = {
    "table": (0.55, 0.4, 0.25, 1.0),
    "shelf": (0.65, 0.5, 0.33, 1.0),
    "counter": (0.82, 0.82, 0.8, 1.0),
    "floor": (0.5, 0.5, 0.5, 1.0),
}


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
