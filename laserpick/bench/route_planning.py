"""Where the scripted user can drive: the scooter's outline, what it must keep off, and a
planned way between two parking poses that keeps the whole scooter clear of the furniture.

Poses are (x, y, yaw) in `world` (m, rad); outlines are rectangles in `base` (m).
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Collection, Sequence
from dataclasses import dataclass

import numpy as np

from laserpick.robot.sim.scenes import Surface

#: m the scripted user keeps every part of the scooter, arm and held object included, from
#: the furniture when driving between surfaces. The simulated scooter pushes furniture aside
#: and sweeps objects off it; a careful user does neither.
DRIVE_MARGIN = 0.03
#: m, the spacing of the grid of points where the user might stop on the way to turn.
VIA_SPACING = 0.2
#: m the user backs out from a surface before turning, beyond what they were asked: the
#: first that leaves room.
REVERSE_STEPS = (0.0, 0.4, 0.8, 1.2, 1.6)
#: m, the longest move between two grid points of a way with several stops, and the cost
#: (m per rad) of turning on the spot at a stop: a way that turns less is the better.
HOP = 0.45
TURN_COST = 0.3
#: m before the parking spot where the user turns to face it and creeps in: the first that
#: leaves room.
APPROACH_DISTANCES = (0.8, 1.2)
#: rad. A planned turn on the spot this close to half a turn may go either way: the scooter
#: arrives a few degrees off the heading planned and turns the short way from there, which
#: can swing the arm through a table the other way round would miss.
TURN_EITHER_WAY = math.radians(20.0)


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


@dataclass(frozen=True)
class Footprint:
    """A rectangle on the floor the scooter must keep off: `name`, centre `xy` (m, `world`),
    `yaw` (rad) and `size` (m, along and across). A surface is one too."""

    name: str
    xy: tuple[float, float]
    yaw: float
    size: tuple[float, float]


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
    gap = float(clearance(furniture, base_points_at(poses, outline.points())).min(initial=np.inf))
    if small:
        inside = base_points_at(poses, outline.points(filled=True))
        gap = min(gap, float(clearance(small, inside).min()))
    return gap


def clearance(surfaces: Sequence[Surface | Footprint], xy: np.ndarray) -> np.ndarray:
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


def base_points_at(poses: np.ndarray, local: np.ndarray) -> np.ndarray:
    """The `base` points `local` (M x 2) at each of the poses (K x 3: x, y, yaw in `world`),
    as one (K * M) x 2 array in `world`."""
    c, si = np.cos(poses[:, 2])[:, None], np.sin(poses[:, 2])[:, None]
    x = poses[:, :1] + c * local[:, 0] - si * local[:, 1]
    y = poses[:, 1:2] + si * local[:, 0] + c * local[:, 1]
    return np.c_[x.ravel(), y.ravel()]


def straight_poses(a: np.ndarray, b: np.ndarray, yaw: float, step: float = 0.05) -> np.ndarray:
    """Poses (K x 3) along the straight line from a to b (m, `world` xy) at heading yaw."""
    n = max(2, int(np.linalg.norm(b - a) / step) + 1)
    t = np.linspace(0.0, 1.0, n)[:, None]
    return np.c_[a + t * (b - a), np.full(n, yaw)]


def turn_poses(
    xy: np.ndarray, yaw0: float, yaw1: float, step: float = math.radians(5)
) -> np.ndarray:
    """Poses (K x 3) of a turn on the spot at xy from yaw0 to yaw1, the short way round; a
    turn within TURN_EITHER_WAY of half a turn, all the way round: the scooter arrives a few
    degrees off the heading planned, and turns the short way from where it is."""
    turn = wrap_angle(yaw1 - yaw0)
    if abs(turn) > math.pi - TURN_EITHER_WAY:
        turn = 2 * math.pi
    n = max(2, int(abs(turn) / step) + 1)
    return np.c_[np.tile(xy, (n, 1)), yaw0 + np.linspace(0.0, turn, n)]


def _heading(a: np.ndarray, b: np.ndarray) -> float:
    return math.atan2(b[1] - a[1], b[0] - a[0])


def wrap_angle(a: float) -> float:
    """The angle `a` (rad) wrapped into [-pi, pi)."""
    return (a + math.pi) % (2 * math.pi) - math.pi


def _via_points(surfaces: Sequence[Surface | Footprint], outline: Outline) -> np.ndarray:
    """The points (N x 2, m, `world` xy) of a VIA_SPACING grid over the surfaces and 1 m
    about them where the user might stop on the way to turn."""
    lo = np.min([s.xy for s in surfaces], axis=0) - 1.0
    hi = np.max([s.xy for s in surfaces], axis=0) + 1.0
    grid = np.mgrid[lo[0] : hi[0] : VIA_SPACING, lo[1] : hi[1] : VIA_SPACING].reshape(2, -1).T
    # The sweeps decide; this only drops points where the scooter could not even stand.
    return grid[clearance(surfaces, grid) >= 0.5 * (outline.y[1] - outline.y[0])]


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
        return np.vstack([turn_poses(xy, yaw, h), straight_poses(xy, to, h)]), h

    def arrive_clear(approach: np.ndarray, yaw: float) -> bool:
        """At the approach, heading yaw: turn to the goal's heading and creep in."""
        arrive = np.vstack(
            [turn_poses(approach, yaw, goal[2]), straight_poses(approach, goal[:2], goal[2])]
        )
        return clear(arrive, at_goal)

    # Where the creep in is blocked whatever way leads to it, no way is worth searching.
    approaches = [goal[:2] - d * facing for d in APPROACH_DISTANCES]
    approaches = [a for a in approaches if clear(straight_poses(a, goal[:2], goal[2]), at_goal)]
    if not approaches:
        return None
    vias = _via_points(surfaces, outline)
    for back in sorted({reverse_first + r for r in REVERSE_STEPS}):
        out = start[:2] - back * np.array([math.cos(start[2]), math.sin(start[2])])
        if back > 0 and not clear(straight_poses(start[:2], out, start[2]), at_start):
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
    # No way with one stop: a way with several, once backed out as far as asked.
    back = max(reverse_first, 0.0)
    out = start[:2] - back * np.array([math.cos(start[2]), math.sin(start[2])])
    if back > 0 and not clear(straight_poses(start[:2], out, start[2]), at_start):
        return None
    leaving = at_start if back == 0 else frozenset()
    for approach in approaches:
        stops = _stops(np.r_[out, start[2]], approach, vias, go, clear, leaving, arrive_clear)
        if stops is not None:
            return back, stops
    return None


def _stops(
    start: np.ndarray,
    approach: np.ndarray,
    vias: np.ndarray,
    go,
    clear,
    at_start: frozenset[str],
    arrive_clear,
) -> list[np.ndarray] | None:
    """The points (m, `world` xy) of a way from `start` (x, y, yaw) through several of the
    `vias` to `approach`, each move a turn on the spot and a straight drive that `clear`
    passes, or None: the shortest by Dijkstra over moves of at most HOP between grid points
    (the heading at a point is the one the shortest way there arrives with), less the stops
    the scooter can drive straight past (`_skipped`)."""
    nodes = np.vstack([start[:2], vias])
    near = [np.flatnonzero(np.linalg.norm(nodes - p, axis=1) <= HOP) for p in nodes]
    best = {0: 0.0}
    heading, parent = {0: float(start[2])}, {0: -1}
    frontier, done = [(0.0, 0)], set()
    while frontier:
        cost, u = heapq.heappop(frontier)
        if u in done:
            continue
        done.add(u)
        exempt = at_start if u == 0 else frozenset()
        last, h = go(nodes[u], heading[u], approach)
        if u > 0 and clear(last) and arrive_clear(approach, h):
            way = _chain(parent, u, nodes) + [approach]
            return _skipped(way, start, go, clear, at_start, arrive_clear)
        for v in near[u]:
            if v in done or v == u:
                continue
            moves, h = go(nodes[u], heading[u], nodes[v])
            step = (
                cost
                + float(np.linalg.norm(nodes[v] - nodes[u]))
                + TURN_COST * abs(wrap_angle(h - heading[u]))
            )
            if step < best.get(v, np.inf) and clear(moves, exempt):
                best[v], heading[v], parent[v] = step, h, u
                heapq.heappush(frontier, (step, v))
    return None


def _chain(parent: dict[int, int], u: int, nodes: np.ndarray) -> list[np.ndarray]:
    """The points from the first after the start to node u, by `parent`."""
    out = []
    while u > 0:
        out.append(nodes[u])
        u = parent[u]
    return out[::-1]


def _skipped(points, start, go, clear, at_start, arrive_clear) -> list[np.ndarray]:
    """`points` less the stops the way can drive past: from each stop kept, straight on to
    the farthest later point whose move is clear. Where a move the search found clear, or
    the creep in after the last, is not from the heading a skipped stop leaves, the way is
    kept as it was found."""
    kept, here, h, exempt = [], start[:2], float(start[2]), at_start
    k = 0
    while k < len(points):
        for j in range(len(points) - 1, k - 1, -1):
            moves, h_next = go(here, h, points[j])
            if clear(moves, exempt):
                break
        else:
            return list(points)
        kept.append(points[j])
        here, h, exempt, k = points[j], h_next, frozenset(), j + 1
    return kept if arrive_clear(points[-1], h) else list(points)
