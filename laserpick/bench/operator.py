"""The referee of the grasping experiments (004 section 8), and how the scripted user drives.

The referee reads the simulator's truth: where each object is, which object a grasp would
close on, whether an object ended up in the basket, and where a person would aim at one. It
also does what the experimenter does by hand (empties the basket, moves a stuck arm home).
None of it is ever shown to the pipeline; the scripted user (`picking.ScriptedOperator`) uses
it only to look at the world the way a person would.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from laserpick.description import dims
from laserpick.pipeline.cloud import fuse
from laserpick.robot.sim.scenes import Surface, scene_config
from laserpick.robot.sim.truth import Captured, SimTruth

#: Hand tremor: the aim's angular noise, standard deviation (rad). About 5 mm at 1 m, a
#: steady hand resting on the scooter's armrest. Ours; 004 does not measure it.
TREMOR_STD = math.radians(0.3)
#: m behind a surface's front edge that the user parks to work at (the isolation table's
#: objects stand 5-45 cm behind its edge at 1.30 m).
PARK_SPOT_DEPTH = 0.25
#: m from the rear axle to the front edge of the surface the user parks at: close to a low
#: surface, for the arm to reach over it; farther from one above the arm's shoulder, which
#: the upper arm must rise past before it can reach forward (at 1.30 m the 73 cm table's
#: edge stands 16 cm before the mount, and no path led from the stowed arm to the ready pose).
PARK_EDGE = 1.30
PARK_EDGE_HIGH = 1.40
#: m from the rear axle to an object on the floor the user parks at: 15 cm ahead of the
#: scooter's front (1.30 m), inside the arm's reach down to the floor. A floor is no
#: obstacle: the user drives onto it, around the objects lying there.
PARK_FLOOR_REACH = 1.45
#: m the scripted user keeps every part of the scooter, arm and held object included, from
#: the furniture when driving between surfaces. The simulated scooter pushes furniture aside
#: and sweeps objects off it; a careful user does neither.
DRIVE_MARGIN = 0.03
#: m, the spacing of the grid of points where the user might stop on the way to turn.
VIA_SPACING = 0.2
#: m the user backs out from a surface before turning, beyond what they were asked: the
#: first that leaves room.
REVERSE_STEPS = (0.0, 0.4, 0.8, 1.2, 1.6)
#: m before the parking spot where the user turns to face it and creeps in: the first that
#: leaves room.
APPROACH_DISTANCES = (0.8, 1.2)
#: rad. A planned turn on the spot this close to half a turn may go either way: planned at
#: the high table as 179.6 deg to the left, it went to the right from where the scooter
#: stood, and link 2 met the table at up to 2,000 N.
TURN_EITHER_WAY = math.radians(20.0)
#: rad. Off its heading by more than this, the user stops and turns on the spot: driving
#: while turning hard swings the front wide.
GO_ALIGNED = math.radians(20.0)


class Referee(SimTruth):
    """The simulator's truth, with what the scripted user reads of it to drive and aim."""

    def outline(self) -> Outline:
        """The scooter's footprint with the arm as it stands now, and what it holds (m,
        `base`): the bounds of the geoms of the scooter's body tree and of a held object."""
        m, d = self.robot.model, self._posed()
        bodies = self.robot.sim.info.object_bodies
        scooter = m.body("scooter").id
        held = {bodies[name] for name in bodies if self.near_hand(name)}
        signs = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T
        corners = []
        for g in range(m.ngeom):
            body = m.geom_bodyid[g]
            if m.body_rootid[body] != scooter and body not in held:
                continue
            local = m.geom_aabb[g, :3] + signs * m.geom_aabb[g, 3:]
            corners.append(local @ d.geom_xmat[g].reshape(3, 3).T + d.geom_xpos[g])
        world = np.vstack(corners)
        base = (self._T_base_world() @ np.c_[world, np.ones(len(world))].T).T
        lo, hi = base[:, :2].min(axis=0), base[:, :2].max(axis=0)
        return Outline((float(lo[0]), float(hi[0])), (float(lo[1]), float(hi[1])))

    def aim_point(self, instance: str) -> np.ndarray | None:
        """Where a person would aim: the middle of the object's visible top (m, `base`), from
        the cameras' view labelled by the simulator; None if no camera sees it."""
        frames, labels = self.robot.capture_with_labels()
        captured = Captured(self.robot, frames, labels)
        return captured.visible_top(fuse(frames), instance)


def scene_config_backed(name: str, back: float) -> dict:
    """A built-in scene's configuration with the scooter starting `back` m farther back
    along its heading; edit it further, then `parse_scene(yaml.safe_dump(config))`."""
    config = scene_config(name)
    start = config["scooter"]
    yaw = math.radians(start.get("yaw_deg", 0.0))
    start["x"] = start.get("x", 0.0) - back * math.cos(yaw)
    start["y"] = start.get("y", 0.0) - back * math.sin(yaw)
    return config


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


class Driver(Protocol):
    """What the scripted user drives with: where the scooter stands (x, y, yaw in `world`),
    and a drive command (m/s, rad/s) held for 0.1 s of robot time."""

    def base_pose(self) -> np.ndarray: ...

    def drive(self, v: float, w: float) -> None: ...


@dataclass(frozen=True)
class Outline:
    """The scooter's footprint with the arm as it stands: a rectangle in `base` (m), x from
    the rear edge to the front (the arm's reach included), y from right to left."""

    x: tuple[float, float]
    y: tuple[float, float]

    def points(self, step: float = 0.05, filled: bool = False) -> np.ndarray:
        """Points along the rectangle's edges (m, `base` xy), at most `step` apart; filled:
        a grid over the whole rectangle instead."""
        (x0, x1), (y0, y1) = self.x, self.y
        nx, ny = int(np.ceil((x1 - x0) / step)) + 1, int(np.ceil((y1 - y0) / step)) + 1
        xs, ys = np.linspace(x0, x1, nx), np.linspace(y0, y1, ny)
        if filled:
            gx, gy = np.meshgrid(xs, ys)
            return np.c_[gx.ravel(), gy.ravel()]
        return np.vstack(
            [
                np.c_[xs, np.full(nx, y0)],
                np.c_[xs, np.full(nx, y1)],
                np.c_[np.full(ny, x0), ys],
                np.c_[np.full(ny, x1), ys],
            ]
        )


def drive_to(driver: Driver, goal: np.ndarray, *, reverse_first: float = 0.0) -> bool:
    """Drive like a careful user where nothing is in the way: back out `reverse_first` m,
    drive to a point APPROACH_DISTANCES[0] in front of the goal, turn to face the goal and
    creep in. Returns whether the scooter ended within 3 cm and 2 deg of `goal` (x, y, yaw
    in `world`). Among furniture, `plan_drive` finds the way and `follow` drives it."""
    goal = np.asarray(goal, float)
    facing = np.array([math.cos(goal[2]), math.sin(goal[2])])
    return follow(driver, goal, reverse_first, [goal[:2] - APPROACH_DISTANCES[0] * facing])


def follow(
    driver: Driver, goal: np.ndarray, reverse_first: float, waypoints: Sequence[np.ndarray]
) -> bool:
    """Drive a way to `goal` (x, y, yaw in `world`), as `plan_drive` gives it: back out
    `reverse_first` m, drive through the waypoints (m, `world` xy), turn to the goal's
    heading and creep in. Returns whether the scooter ended within 3 cm and 2 deg of it."""
    goal = np.asarray(goal, float)
    if reverse_first > 0:
        start = driver.base_pose()[:2].copy()
        _drive_loop(driver, lambda p: (-0.3, 0.0, np.linalg.norm(p[:2] - start) >= reverse_first))
    for waypoint in waypoints:
        _go_point(driver, waypoint)
    _turn_to(driver, goal[2])
    _go_point(driver, goal[:2], speed=0.2)
    _turn_to(driver, goal[2])
    p = driver.base_pose()
    return bool(np.linalg.norm(p[:2] - goal[:2]) < 0.03 and abs(_wrap(p[2] - goal[2])) < 0.035)


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


def _drive_loop(driver: Driver, command, timeout: float = 60.0) -> None:
    """Drive in 0.1 s steps until command(pose) says done (or `timeout` s of robot time),
    then let go of the stick for the 1 s ramp down."""
    t = 0.0
    while t < timeout:
        v, w, done = command(driver.base_pose())
        if done:
            break
        driver.drive(v, w)
        t += 0.1
    for _ in range(10):
        driver.drive(0.0, 0.0)


def _turn_to(driver: Driver, yaw: float) -> None:
    def cmd(p):
        err = _wrap(yaw - p[2])
        return 0.0, float(np.clip(1.5 * err, -0.6, 0.6)), abs(err) < 0.01

    _drive_loop(driver, cmd)


def _go_point(driver: Driver, xy: np.ndarray, speed: float = 0.5) -> None:
    def heading(p):
        d = xy - p[:2]
        return math.atan2(d[1], d[0])

    if np.linalg.norm(xy - driver.base_pose()[:2]) > 0.02:
        _turn_to(driver, heading(driver.base_pose()))

    def cmd(p):
        d = xy - p[:2]
        dist = float(np.linalg.norm(d))
        err = _wrap(math.atan2(d[1], d[0]) - p[2])
        if dist < 0.01 or (dist < 0.05 and abs(err) > math.pi / 2):  # there, or just past
            return 0.0, 0.0, True
        w = float(np.clip(1.5 * err, -0.6, 0.6)) if dist > 0.05 else 0.0
        if abs(err) > GO_ALIGNED:
            return 0.0, w, False
        return min(speed, 0.8 * dist) * math.cos(err), w, False

    _drive_loop(driver, cmd)


@dataclass(frozen=True)
class Footprint:
    """A rectangle on the floor the scooter must keep off: `name`, centre `xy` (m, `world`),
    `yaw` (rad) and `size` (m, along and across). A surface is one too."""

    name: str
    xy: tuple[float, float]
    yaw: float
    size: tuple[float, float]


def obstacles(
    surfaces: Sequence[Surface], referee: Referee, keep_off: Sequence[str]
) -> list[Surface | Footprint]:
    """What the user drives around: every surface but a floor (they drive onto that), and
    the objects `keep_off` where they lie on the floor, each as its bounding rectangle."""
    out: list[Surface | Footprint] = [s for s in surfaces if s.kind != "floor"]
    for name in keep_off:
        world = referee.object_points(name, frame="world")
        if world[:, 2].min() > 0.05:  # not on the floor
            continue
        lo, hi = world[:, :2].min(axis=0), world[:, :2].max(axis=0)
        out.append(Footprint(name, tuple((lo + hi) / 2), 0.0, tuple(hi - lo)))
    return out


def parked_clear(pose: np.ndarray, around: Sequence[Surface | Footprint], outline: Outline) -> bool:
    """Whether the scooter with `outline`, standing at `pose` (x, y, yaw in `world`), keeps
    DRIVE_MARGIN from everything `around`: where it parks on a floor, nothing is to be in
    reach of its front but the object."""
    return _gap(pose[None], around, outline) >= DRIVE_MARGIN


def _gap(poses: np.ndarray, around: Sequence[Surface | Footprint], outline: Outline) -> float:
    """The least distance (m) from the scooter with `outline`, at any of the poses (K x 3:
    x, y, yaw in `world`), to anything `around`. Furniture meets the outline's edges first;
    an object on the floor (a Footprint) can be smaller and lie wholly inside it, so it is
    measured from points over the whole outline."""
    furniture = [a for a in around if not isinstance(a, Footprint)]
    small = [a for a in around if isinstance(a, Footprint)]
    gap = float(_clearance(furniture, _at(poses, outline.points())).min(initial=np.inf))
    if small:
        inside = _at(poses, outline.points(filled=True))
        gap = min(gap, float(_clearance(small, inside).min()))
    return gap


def _clearance(surfaces: Sequence[Surface | Footprint], xy: np.ndarray) -> np.ndarray:
    """Distance (m) from each of the points `xy` (N x 2, `world`) to the nearest of the
    surfaces' footprints; inf without surfaces."""
    out = np.full(len(xy), np.inf)
    for s in surfaces:
        c, si = math.cos(s.yaw), math.sin(s.yaw)
        d = xy - np.asarray(s.xy)
        local = np.c_[c * d[:, 0] + si * d[:, 1], -si * d[:, 0] + c * d[:, 1]]
        outside = np.maximum(np.abs(local) - np.asarray(s.size) / 2, 0.0)
        out = np.minimum(out, np.linalg.norm(outside, axis=1))
    return out


def _at(poses: np.ndarray, local: np.ndarray) -> np.ndarray:
    """The `base` points `local` (M x 2) at each of the poses (K x 3: x, y, yaw in `world`),
    as one (K * M) x 2 array in `world`."""
    c, si = np.cos(poses[:, 2])[:, None], np.sin(poses[:, 2])[:, None]
    x = poses[:, :1] + c * local[:, 0] - si * local[:, 1]
    y = poses[:, 1:2] + si * local[:, 0] + c * local[:, 1]
    return np.c_[x.ravel(), y.ravel()]


def _leg(a: np.ndarray, b: np.ndarray, yaw: float, step: float = 0.05) -> np.ndarray:
    """Poses (K x 3) along the straight line from a to b (m, `world` xy) at heading yaw."""
    n = max(2, int(np.linalg.norm(b - a) / step) + 1)
    t = np.linspace(0.0, 1.0, n)[:, None]
    return np.c_[a + t * (b - a), np.full(n, yaw)]


def _turn(xy: np.ndarray, yaw0: float, yaw1: float, step: float = math.radians(5)) -> np.ndarray:
    """Poses (K x 3) of a turn on the spot at xy from yaw0 to yaw1, the short way round; a
    turn within TURN_EITHER_WAY of half a turn, all the way round: the scooter arrives a few
    degrees off the heading planned, and turns the short way from where it is."""
    turn = _wrap(yaw1 - yaw0)
    if abs(turn) > math.pi - TURN_EITHER_WAY:
        turn = 2 * math.pi
    n = max(2, int(abs(turn) / step) + 1)
    return np.c_[np.tile(xy, (n, 1)), yaw0 + np.linspace(0.0, turn, n)]


def _heading(a: np.ndarray, b: np.ndarray) -> float:
    return math.atan2(b[1] - a[1], b[0] - a[0])


def plan_drive(
    start: np.ndarray,
    goal: np.ndarray,
    surfaces: Sequence[Surface | Footprint],
    outline: Outline,
    reverse_first: float = 0.0,
    parked_at: Collection[str] = (),
) -> tuple[float, list[np.ndarray]] | None:
    """A way from `start` to park at `goal` (x, y, yaw in `world`) that keeps the whole
    scooter DRIVE_MARGIN from every surface, driven as `follow` drives: back out, turn on
    the spot toward the next point and drive there, ..., turn to the goal's heading before
    it and creep in. Returns (how far to back out (m), the points to drive through (m,
    `world` xy), the last one APPROACH_DISTANCES before the goal), or None.

    Tried in order: backing out `reverse_first` plus each of REVERSE_STEPS; each approach
    distance; straight, then through one point of a VIA_SPACING grid, nearest first. The
    moves that leave the start may touch what the scooter touches there: it is parked at
    it. Creeping in to the goal may touch only what is named in `parked_at`, what the user
    parks to work at (a table the arm reaches over, an object on the floor before the
    arm); anything else within DRIVE_MARGIN of the goal makes it no place to park."""
    start, goal = np.asarray(start, float), np.asarray(goal, float)

    def clear(poses: np.ndarray, exempt: frozenset[str] = frozenset()) -> bool:
        others = [s for s in surfaces if s.name not in exempt]
        return _gap(poses, others, outline) >= DRIVE_MARGIN

    def touching(pose: np.ndarray) -> frozenset[str]:
        return frozenset(s.name for s in surfaces if _gap(pose[None], [s], outline) < DRIVE_MARGIN)

    at_start, at_goal = touching(start), frozenset(parked_at)
    facing = np.array([math.cos(goal[2]), math.sin(goal[2])])

    def go(xy: np.ndarray, yaw: float, to: np.ndarray) -> tuple[np.ndarray, float]:
        """The poses of turning at xy from yaw toward `to` and driving there, and the heading."""
        h = _heading(xy, to)
        return np.vstack([_turn(xy, yaw, h), _leg(xy, to, h)]), h

    def arrive_clear(approach: np.ndarray, yaw: float) -> bool:
        """At the approach, heading yaw: turn to the goal's heading and creep in."""
        arrive = np.vstack([_turn(approach, yaw, goal[2]), _leg(approach, goal[:2], goal[2])])
        return clear(arrive, at_goal)

    # Where the creep in is blocked whatever way leads to it, no way is worth searching.
    approaches = [goal[:2] - d * facing for d in APPROACH_DISTANCES]
    approaches = [a for a in approaches if clear(_leg(a, goal[:2], goal[2]), at_goal)]
    if not approaches:
        return None
    lo = np.min([s.xy for s in surfaces], axis=0) - 1.0
    hi = np.max([s.xy for s in surfaces], axis=0) + 1.0
    grid = np.mgrid[lo[0] : hi[0] : VIA_SPACING, lo[1] : hi[1] : VIA_SPACING].reshape(2, -1).T
    # The sweeps decide; this only drops points where the scooter could not even stand.
    vias = grid[_clearance(surfaces, grid) >= 0.5 * (outline.y[1] - outline.y[0])]
    for back in sorted({reverse_first + r for r in REVERSE_STEPS}):
        out = start[:2] - back * np.array([math.cos(start[2]), math.sin(start[2])])
        if back > 0 and not clear(_leg(start[:2], out, start[2]), at_start):
            continue
        leaving = at_start if back == 0 else frozenset()
        for approach in approaches:
            moves, h = go(out, start[2], approach)
            if clear(moves, leaving) and arrive_clear(approach, h):
                return back, [approach]
            length = np.linalg.norm(vias - out, axis=1) + np.linalg.norm(vias - approach, axis=1)
            for via in vias[np.argsort(length)]:
                leave, h = go(out, start[2], via)
                if not clear(leave, leaving):
                    continue
                moves, h = go(via, h, approach)
                if clear(moves) and arrive_clear(approach, h):
                    return back, [via, approach]
    return None
