"""Where the scripted user sets a held object down: a free spot on a surface, room about it
for what they hold, and the marks they aim there (moved on where the dot lands on something
in front, or where the robot refused a mark and said which way to move it).

Points are in `world` unless a name or docstring says `base` (m).
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from laserpick.behaviours import MARK_MOVES
from laserpick.bench.parking import PARK_SPOT_DEPTH
from laserpick.bench.picking import ScriptedOperator
from laserpick.robot.sim.scenes import Surface

#: m the user leaves between the footprint of what they set down and anything else on the
#: surface: the fingers' room about it, and a few cm for the object's middle going down only
#: about over the mark (the robot centres what it saw of the object).
PLACE_ROOM = 0.07
#: Where the dot of a place mark lands on something in front of the spot (an object between
#: the seat and it), the user moves the aim by these (m, the surface's x back and y across)
#: until the dot lies within `picking.DOT_ON_SPOT` of where they aim, as a person who
#: watches the dot does: a mark on the side of a box in front of the spot is refused ("not
#: on a flat surface").
AIM_SHIFTS = ((0.0, 0.0), (0.0, 0.05), (0.0, -0.05), (0.0, 0.10), (0.0, -0.10), (0.05, 0.0))
#: m the user moves a place mark the way the robot said when it refused it (`aim_as_told`):
#: a level hand's wrist comes down up to 22 cm to the side of the object.
MARK_STEP = 0.15
#: Where the line 25 cm behind a surface's front edge has no free spot, the user sets
#: things down elsewhere on the top, nearest that line: these many random spots are
#: weighed, SPOT_EDGE_ROOM (m) or more from the front and back edges and the object's
#: footprint clear of them. Every place goes to that line first, so by a trial's last tasks
#: it can be full while the top has room behind it.
SPOT_TRIES = 400
SPOT_EDGE_ROOM = 0.12


def free_spot(
    op: ScriptedOperator, surface: Surface, room: float, held: str | None
) -> tuple[float, np.ndarray] | None:
    """A spot on the top of `surface`, `room` m from every point of the objects there but
    `held`: (local y, world xyz). First on the line 25 cm behind its front edge (half its
    depth if that is less), where the user parks to work; where that line is full, the
    free spot nearest it, its footprint (and SPOT_EDGE_ROOM) clear of the front and back
    edges. A shelf's top, not its lower boards: under a board the cameras see no dot and no
    surface. None when the surface has no such spot."""
    half_w = surface.size[1] / 2 - 0.15
    level = surface.levels[-1]
    front = -surface.size[0] / 2
    line = min(PARK_SPOT_DEPTH, surface.size[0] / 2)
    others = _standing(op, level, held)

    def spot(depth: float, ly: float) -> np.ndarray | None:
        xy = surface.to_world(np.array([front + depth, ly]))
        return np.array([xy[0], xy[1], level]) if _free(others, xy, room) else None

    for _ in range(100):
        ly = float(op.rng.uniform(-half_w, half_w)) if half_w > 0 else 0.0
        if (at := spot(line, ly)) is not None:
            return ly, at
    # Off the line, the edges are near: the whole footprint must stay on the top.
    edge = max(SPOT_EDGE_ROOM, room - PLACE_ROOM + 0.03)
    deepest = surface.size[0] - edge
    if deepest < edge:
        return None
    depths = op.rng.uniform(edge, deepest, SPOT_TRIES)
    across = op.rng.uniform(-half_w, half_w, SPOT_TRIES) if half_w > 0 else np.zeros(SPOT_TRIES)
    for k in np.argsort(np.abs(depths - line), kind="stable"):
        if (at := spot(float(depths[k]), float(across[k]))) is not None:
            return float(across[k]), at
    return None


def room_for(op: ScriptedOperator, instance: str) -> float:
    """How far (m) the user keeps a spot from everything else to set `instance` down there:
    the reach of its footprint as it stands now (its points' farthest, level, from their
    middle), plus PLACE_ROOM. A fixed distance from the other objects' middles, whatever is
    held, sets a long object down onto its neighbour's rim."""
    pts = op.referee.object_points(instance, frame="world")[:, :2]
    middle = (pts.min(axis=0) + pts.max(axis=0)) / 2
    return float(np.linalg.norm(pts - middle, axis=1).max()) + PLACE_ROOM


def _standing(op: ScriptedOperator, level: float, but: str | None) -> np.ndarray:
    """Where the objects other than `but` that stand at about height `level` (m) reach: their
    points' level positions (n, 2; m, `world`)."""
    ref = op.referee
    pts = [
        p[:, :2]
        for n, p in ref.all_object_points(frame="world").items()
        if n != but and abs(ref.world_position(n)[2] - level) < 0.1
    ]
    return np.vstack(pts) if pts else np.zeros((0, 2))


def _free(others: np.ndarray, xy: np.ndarray, room: float) -> bool:
    """Whether the spot `xy` (m, `world`) lies `room` m from every point of `others` (n, 2)."""
    return len(others) == 0 or float(np.min(np.linalg.norm(others - xy, axis=1))) > room


def _on_top(surface: Surface, local: np.ndarray) -> bool:
    """Whether the spot at `local` (m, the surface's own x back and y across from its middle)
    lies on `surface`'s top, 5 cm or more inside its edges."""
    half = np.asarray(surface.size[:2]) / 2
    return not np.any(np.abs(local) > half - 0.05)


def aims_in_sight(
    op: ScriptedOperator, surface: Surface, spot: np.ndarray, room: float, held: str | None
) -> Iterator[np.ndarray]:
    """Where the user marks, in turn, to put something at `spot` (m, `world`, on `surface`'s
    top; `base` out): each aim of AIM_SHIFTS that is free (`room` m from the objects there
    but `held`), on the surface and lit by the dot (the spot itself first, where the dot
    lands on it), then the last of them (the spot, where none is) for as long as asked. A
    person moves the mark on when the dot lands on something in front of the spot, and when
    the robot refuses to place there."""
    local = surface.to_local(spot[:2])
    others = _standing(op, spot[2], held)
    last = None
    for dx, dy in AIM_SHIFTS:
        moved = local + (dx, dy)
        xy = surface.to_world(moved)
        if not _on_top(surface, moved) or not _free(others, xy, room):
            continue
        target = op.referee.to_base(np.array([xy[0], xy[1], spot[2]]))
        op.aim(target, watched=True)
        if op.dot_near(target):
            last = target
            yield target
    last = op.referee.to_base(spot) if last is None else last
    while True:
        yield last


def aim_as_told(
    op: ScriptedOperator,
    surface: Surface,
    aim: np.ndarray,
    refusal: str,
    room: float,
    held: str | None,
) -> np.ndarray | None:
    """Where the user marks next when the robot refused the mark `aim` (m, `base`) and said
    which way to move it (`behaviours.MARK_MOVES`): MARK_STEP m that way, if that spot is
    on `surface`'s top, free (`room` m from the objects there but `held`) and lit by the
    dot; else None, and the user goes on as before (`aims_in_sight`)."""
    move = next((v for k, v in MARK_MOVES.items() if refusal.rstrip(".").endswith(k)), None)
    if move is None:
        return None
    target = aim + MARK_STEP * np.array([*move, 0.0])
    xy = op.referee.to_world(target)[:2]
    if not _on_top(surface, surface.to_local(xy)):
        return None
    if not _free(_standing(op, float(op.referee.to_world(aim)[2]), held), xy, room):
        return None
    op.aim(target, watched=True)
    return target if op.dot_near(target) else None
