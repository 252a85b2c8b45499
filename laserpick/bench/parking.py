"""Where the scripted user parks to work at a surface or at an object on a floor, and how
they get there: the parking pose, what they drive around, and the headings and offsets
they try on a floor until one parks clear and a way leads there.

Poses are (x, y, yaw) in `world` (m, rad); a surface's local frame has x back from its
middle and y across.
"""

from __future__ import annotations

import itertools
import logging
import math
from collections.abc import Sequence

import numpy as np

from laserpick.bench.driving import follow
from laserpick.bench.picking import ScriptedOperator
from laserpick.bench.referee import Referee
from laserpick.bench.route_planning import Footprint, Outline, parked_clear, plan_drive
from laserpick.description import dims
from laserpick.robot.sim.scenes import Scene, Surface

log = logging.getLogger(__name__)

#: m above the floor within which an object's lowest point lies on it.
FLOOR_LYING = 0.05
#: m behind a surface's front edge that the user parks to work at (the isolation table's
#: objects stand 5-45 cm behind its edge at 1.30 m).
PARK_SPOT_DEPTH = 0.25
#: m from the rear axle to the front edge of the surface the user parks at: close to a low
#: surface, for the arm to reach over it; farther from one above the arm's shoulder, which
#: the upper arm must rise past before it can reach forward (at 1.30 m a 73 cm table's
#: edge stands 16 cm before the mount, and no path leads from the stowed arm to the ready
#: pose).
PARK_EDGE = 1.30
PARK_EDGE_HIGH = 1.40
#: m from the rear axle to an object on the floor the user parks at: 15 cm ahead of the
#: scooter's front (1.30 m), inside the arm's reach down to the floor. A floor is no
#: obstacle: the user drives onto it, around the objects lying there.
PARK_FLOOR_REACH = 1.45
#: What an attempt says when the user found no way to park in front of its object: trying
#: again would drive the same way.
NO_PARKING = "the user could not park in front of it"
#: Headings (rad, from the floor's +x) the user tries, in order, to park at an object on a
#: floor: the other objects lying there, and the furniture beside it, may block a side. In
#: 15 deg steps: in 45 deg steps an object 40 cm from a counter and 36 cm from another
#: object has no heading the user can park at and drive to.
FLOOR_TURNS = tuple(math.radians(a) for a in sorted(range(-165, 195, 15), key=abs))
#: m across (to the arm's left) the user lets an object on a floor lie from straight before
#: the arm, in the order tried, where no heading parks with it straight before the arm: an
#: object between a counter and two others may have a clear way in only 10-20 cm to a
#: side.
FLOOR_ACROSS = (0.0, 0.1, -0.1, 0.2, -0.2)
#: (back, across) m the user shifts the spot they meant to park at before a surface, in the
#: order tried, where it is not clear or no way leads there: a person parks as near it as
#: the room allows. With the arm standing by beside the scooter (10 cm wider on the right
#: than stowed), the spot 20 cm across asked for a second try at the 108 cm table was not.
SURFACE_SHIFTS = ((0.0, 0.0), (0.0, -0.1), (0.0, 0.1), (0.1, 0.0), (0.1, -0.1), (0.1, 0.1))


def parking_pose(
    surface: Surface,
    local_y: float = 0.0,
    level: float | None = None,
    local_x: float | None = None,
    turn: float = 0.0,
    back: float = 0.0,
    across: float = 0.0,
) -> np.ndarray:
    """Where the user parks to work on `surface` at height `level` (m; default its lowest
    level): facing it, its front edge PARK_EDGE ahead of the rear axle (PARK_EDGE_HIGH when
    the level is above the arm's shoulder) and the spot `local_y` (m, the surface's frame)
    in front of the arm. On a floor, with the spot's `local_x` (m) given, the spot itself
    PARK_FLOOR_REACH ahead instead, the scooter facing the floor's +x turned by `turn`
    (rad): a floor may be driven onto from any side. `back` (m): that much farther back;
    `across` (m): the spot that much to the left of straight before the arm. Returns
    (x, y, yaw) in `world` (m, rad)."""
    level = surface.levels[0] if level is None else level
    edge = PARK_EDGE_HIGH if level > dims.ARM_MOUNT_POS[2] + dims.UR5_D[0] else PARK_EDGE
    c, s = math.cos(surface.yaw), math.sin(surface.yaw)
    ahead = edge + PARK_SPOT_DEPTH + back
    spot_local = np.array([-surface.size[0] / 2 + PARK_SPOT_DEPTH, local_y])
    yaw = surface.yaw  # the front faces the surface's local -x: face its +x
    if surface.kind == "floor" and local_x is not None:
        ahead, spot_local = PARK_FLOOR_REACH + back, np.array([local_x, local_y])
        yaw += turn
    spot = np.asarray(surface.xy) + np.array(
        [c * spot_local[0] - s * spot_local[1], s * spot_local[0] + c * spot_local[1]]
    )
    c, s = math.cos(yaw), math.sin(yaw)
    reach = np.array([ahead, dims.ARM_MOUNT_POS[1] + across])
    origin = spot - np.array([c * reach[0] - s * reach[1], s * reach[0] + c * reach[1]])
    return np.array([origin[0], origin[1], yaw])


def obstacles(
    surfaces: Sequence[Surface], referee: Referee, keep_off: Sequence[str]
) -> list[Surface | Footprint]:
    """What the user drives around: every surface but a floor (they drive onto that), and
    the objects `keep_off` where they lie on the floor, each as its bounding rectangle."""
    out: list[Surface | Footprint] = [s for s in surfaces if s.kind != "floor"]
    for name in keep_off:
        world = referee.object_points(name, frame="world")
        if world[:, 2].min() > FLOOR_LYING:  # not on the floor
            continue
        lo, hi = world[:, :2].min(axis=0), world[:, :2].max(axis=0)
        out.append(Footprint(name, tuple((lo + hi) / 2), 0.0, tuple(hi - lo)))
    return out


def _scene_obstacles(op: ScriptedOperator, scene: Scene) -> list[Surface | Footprint]:
    """What the user drives around: the furniture, and the objects lying on the floor."""
    return obstacles(scene.surfaces, op.referee, op.referee.instances())


def go_to_object(
    op: ScriptedOperator, scene: Scene, instance: str, back: float = 0.0, across: float = 0.0
) -> bool:
    """Drive from wherever the scooter is to park in front of the object's surface, the
    object before the arm (on the floor: before the object itself), `back` m farther back
    than at first and `across` m to the arm's left. Returns whether it parked."""
    placement = scene.placement(instance)
    surface = scene.surface(placement.surface)
    level = surface.levels[placement.level]
    x, y = (float(v) for v in surface.to_local(op.referee.world_position(instance)[:2]))
    works_at = instance if surface.kind == "floor" else surface.name
    return park(op, scene, surface, x, y, level, works_at, back=back, across=across)


def park(
    op: ScriptedOperator,
    scene: Scene,
    surface: Surface,
    local_x: float,
    local_y: float,
    level: float,
    works_at: str | None,
    outline: Outline | None = None,
    back: float = 0.0,
    across: float = 0.0,
) -> bool:
    """Drive to work at the spot (local x, y: m in the surface's frame; level: its height),
    `back` m farther back than at first and `across` m to the arm's left, and say whether
    the user parked there. Parked, the scooter may reach over only `works_at`: the surface,
    or the object on a floor it picks (None: a free spot on a floor). A floor may be driven
    onto from any side. The user tries the spots `spots_near` gives in turn, until one parks
    clear of everything else and a way leads there. Where none does and something that fell
    lies on the floor (`fallen`), the user asks for it to be picked up and tries once more."""
    spots = spots_near(surface, local_x, local_y, level, back, across)
    outline = outline or op.referee.outline()
    parked_at = () if works_at is None else (works_at,)
    for cleared in (False, True):
        if cleared:  # as a person would ask: someone picks up what fell, and they try again
            down = fallen(scene, op.referee)
            if not down:
                return False
            for name in down:
                op.referee.take_out(name)
            log.info("the floor cleared of %s, which kept the user from parking", down)
        around = _scene_obstacles(op, scene)
        others = [a for a in around if a.name not in parked_at]
        for goal in spots:
            if np.linalg.norm(op.base_pose()[:2] - goal[:2]) < 0.03:
                return True
            if not parked_clear(goal, others, outline):
                continue
            plan = plan_drive(op.base_pose(), goal, around, outline, 0.6, parked_at)
            if plan is not None:
                return follow(op, goal, *plan)
    return False


def spots_near(
    surface: Surface,
    local_x: float,
    local_y: float,
    level: float,
    back: float = 0.0,
    across: float = 0.0,
) -> list[np.ndarray]:
    """The parking poses (x, y, yaw in `world`) the user tries, in order, to work at the spot
    (local x, y: m in the surface's frame; level: its height), `back` m farther back and
    `across` m to the arm's left (`parking_pose`): on a floor, each of FLOOR_TURNS with the
    spot straight before the arm, then a little to a side (FLOOR_ACROSS); before a surface,
    the spot asked, then near it (SURFACE_SHIFTS)."""
    if surface.kind == "floor":
        shifts = [(0.0, a, turn) for a, turn in itertools.product(FLOOR_ACROSS, FLOOR_TURNS)]
    else:
        shifts = [(b, a, 0.0) for b, a in SURFACE_SHIFTS]
    return [
        parking_pose(
            surface, local_y, level, local_x=local_x, turn=turn, back=back + b, across=across + a
        )
        for b, a, turn in shifts
    ]


def fallen(scene: Scene, referee: Referee) -> list[str]:
    """The objects lying on the floor outside every floor area, where nobody puts anything
    down: dropped on the way or beside the basket. Where the scooter cannot park for them,
    someone picks them up; left there, a mug that missed the basket at a table kept the user
    from parking at that table for its other two objects."""
    areas = [s for s in scene.surfaces if s.kind == "floor"]
    out = []
    for name in referee.instances():
        if referee.taken_out(name):
            continue
        world = referee.object_points(name, frame="world")
        if len(world) == 0 or world[:, 2].min() > FLOOR_LYING:
            continue
        xy = world[:, :2].mean(axis=0)
        if not any(_within(area, xy) for area in areas):
            out.append(name)
    return out


def _within(surface: Surface, xy: np.ndarray) -> bool:
    """Whether world (x, y) (m) lies over the surface's footprint."""
    x0, x1, y0, y1 = surface.area()
    lx, ly = surface.to_local(xy)
    return bool(x0 <= lx <= x1 and y0 <= ly <= y1)
