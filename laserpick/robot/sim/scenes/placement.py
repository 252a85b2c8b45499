"""Placing objects at rest on surfaces: a pose on a surface level, the check that it fits,
and random placement by rejection sampling."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from laserpick.robot.sim.objects import (
    ObjectModel,
    at_rest,
    footprint_half_extents,
    quat_mul,
    rest_pose,
    support,
    yaw_quat,
)
from laserpick.robot.sim.scenes.errors import Fail
from laserpick.robot.sim.scenes.rectangles import Rect
from laserpick.robot.sim.scenes.scene import Placement
from laserpick.robot.sim.scenes.schema import RandomCfg
from laserpick.robot.sim.scenes.surfaces import Surface

#: Gap left between an object's lowest point and its surface at placement (m).
REST_CLEARANCE = 0.0015
#: Tries per object before a random rule gives up, and rule restarts.
PLACEMENT_TRIES = 400
PLACEMENT_RESTARTS = 25


@dataclass
class Placed:
    """A placement with what overlap tests need: its footprint circle (centre (x, y) and
    radius, m, world) and its oriented footprint rectangle in world."""

    placement: Placement
    center: np.ndarray
    radius: float
    rect: Rect


#: A drawn object before it has a place: model, lying, yaw (rad), footprint radius (m).
Pose = tuple[ObjectModel, bool, float, float]


def rest_on(
    model: ObjectModel, surf: Surface, level: int, xy: np.ndarray, yaw: float, lying: bool
) -> Placed:
    """The object at rest on level `level` of `surf`, its footprint centred on world `xy` (m),
    turned by `yaw` (rad) about +z, upright or `lying`, `REST_CLEARANCE` above the level."""
    rp = rest_pose(model, lying)
    q = quat_mul(yaw_quat(yaw), rp.quat)
    c, s = math.cos(yaw), math.sin(yaw)
    offset = np.array([c * rp.center[0] - s * rp.center[1], s * rp.center[0] + c * rp.center[1]])
    pos = np.array(
        [xy[0] - offset[0], xy[1] - offset[1], surf.levels[level] + rp.z + REST_CLEARANCE]
    )
    # Footprint rectangle: extents along the object's yawed x and y axes.
    half = footprint_half_extents(model, rp)
    placement = Placement("", model, pos, q, surf.name, level, lying)
    return Placed(
        placement, np.asarray(xy, dtype=float), rp.radius, (np.asarray(xy, float), half, yaw)
    )


def check_fits(
    placed: Placed, surf: Surface, level: int, path: str, mname: str, fail: Fail
) -> None:
    """Raise unless the placed object stays inside the surface's usable area and under the
    board above its level; `mname` names its model in the message."""
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
        raise fail(
            f"{path}.xy",
            f"{mname!r} does not fit on {surf.name!r}: it sticks out {out:.3f} m past "
            f"its {side} edge",
        )
    rp = rest_pose(p.model, p.lying)
    if rp.height + REST_CLEARANCE > surf.clearance(level):
        raise fail(
            f"{path}.level",
            f"{mname!r} is {rp.height:.3f} m tall but level {level} of {surf.name!r} has "
            f"{surf.clearance(level):.3f} m of clearance",
        )


def _draw_poses(
    rc: RandomCfg,
    path: str,
    surf: Surface,
    pool: list[ObjectModel],
    bounds: tuple[float, float, float, float],
    rng: np.random.Generator,
    fail: Fail,
) -> list[Pose]:
    """Draw `rc.count` models from `pool`, each with its lying (a coin flip where the rule
    says so) and its yaw; raise if one cannot fit in `bounds` at all."""
    x0, x1, y0, y1 = bounds
    picks = rng.choice(len(pool), size=rc.count, replace=rc.count > len(pool))
    poses = []
    for k in picks:
        heads = rc.orientation == "coin_flip" and rng.random() < 0.5
        model = pool[int(k)]
        # Heads lays it on its side only where it rests so (`at_rest`).
        lying = bool(heads) and at_rest(model, lying=True)
        r = rest_pose(model, lying).radius
        if x1 - x0 < 2 * r or y1 - y0 < 2 * r:
            raise fail(
                path,
                f"{model.name!r} (footprint radius {r:.3f} m) does not fit in the "
                f"placement area of {surf.name!r}",
            )
        poses.append((model, lying, float(rng.uniform(-math.pi, math.pi)), r))
    return poses


def _drop_poses(
    poses: list[Pose],
    min_gap: float,
    surf: Surface,
    level: int,
    bounds: tuple[float, float, float, float],
    rng: np.random.Generator,
    others: list[Placed],
) -> list[Placed] | None:
    """Place each pose at the first of `PLACEMENT_TRIES` uniform draws in `bounds` (the
    surface's local frame) whose footprint circle keeps `min_gap` (m) from those of `others`
    and of the poses placed before it; None where a pose finds no such place."""
    x0, x1, y0, y1 = bounds
    # Footprint circles already on this surface level: centres (n, 2) and radii (n,).
    centres = np.array([o.center for o in others]).reshape(-1, 2)
    radii = np.array([o.radius for o in others])
    placed_now = []
    for model, lying, yaw, r in poses:
        local = np.column_stack(
            [
                rng.uniform(x0 + r, x1 - r, PLACEMENT_TRIES),
                rng.uniform(y0 + r, y1 - r, PLACEMENT_TRIES),
            ]
        )
        world = np.array([surf.to_world(p) for p in local])
        dist = np.linalg.norm(world[:, None, :] - centres[None, :, :], axis=2)
        free = np.all(dist >= radii[None, :] + r + min_gap, axis=1)
        if not free.any():
            return None
        xy = world[int(np.argmax(free))]
        placed = rest_on(model, surf, level, xy, yaw, lying)
        placed.radius = r
        placed_now.append(placed)
        centres = np.vstack([centres, xy])
        radii = np.append(radii, r)
    return placed_now


def scatter(
    rc: RandomCfg,
    path: str,
    surf: Surface,
    level: int,
    pool: list[ObjectModel],
    bounds: tuple[float, float, float, float],
    rng: np.random.Generator,
    placed: list[Placed],
    fail: Fail,
) -> list[Placed]:
    """Place a random rule's objects on level `level` of `surf`, clear of those `placed`
    already: draw the models and poses, then their places, and draw again (up to
    `PLACEMENT_RESTARTS` times) where they do not fit. The placements are still unnamed."""
    x0, x1, y0, y1 = bounds
    # Circles can cover at most pi / sqrt(12) of a region (hexagonal packing).
    capacity = math.pi / math.sqrt(12) * (x1 - x0 + rc.min_gap) * (y1 - y0 + rc.min_gap)
    for _attempt in range(PLACEMENT_RESTARTS):
        poses = _draw_poses(rc, path, surf, pool, bounds, rng, fail)
        if sum(math.pi * (r + rc.min_gap / 2) ** 2 for *_, r in poses) > capacity:
            continue  # these picks cannot fit; draw again
        others = [
            o for o in placed if o.placement.surface == surf.name and o.placement.level == level
        ]
        new = _drop_poses(poses, rc.min_gap, surf, level, bounds, rng, others)
        if new is not None:
            return new
    raise fail(
        path,
        f"could not place {rc.count} objects on {surf.name!r} with min_gap {rc.min_gap} m "
        f"after {PLACEMENT_RESTARTS} tries; use fewer objects, a smaller gap or a larger "
        "region",
    )
