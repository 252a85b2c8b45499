"""How the scripted user drives the scooter: joystick commands held for 0.1 s of robot time,
turning on the spot and driving straight through the points of a planned way
(`route_planning.plan_drive`).

Poses are (x, y, yaw) in `world` (m, rad); commands in m/s and rad/s.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Protocol

import numpy as np

from laserpick.bench.route_planning import APPROACH_DISTANCES, wrap_angle

#: rad. Off its heading by more than this, the user stops and turns on the spot: driving
#: while turning hard swings the front wide.
GO_ALIGNED = math.radians(20.0)


class Driver(Protocol):
    """What the scripted user drives with: where the scooter stands (x, y, yaw in `world`),
    and a drive command (m/s, rad/s) held for 0.1 s of robot time."""

    def base_pose(self) -> np.ndarray: ...

    def drive(self, v: float, w: float) -> None: ...


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
    return bool(np.linalg.norm(p[:2] - goal[:2]) < 0.03 and abs(wrap_angle(p[2] - goal[2])) < 0.035)


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
        err = wrap_angle(yaw - p[2])
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
        err = wrap_angle(math.atan2(d[1], d[0]) - p[2])
        if dist < 0.01 or (dist < 0.05 and abs(err) > math.pi / 2):  # there, or just past
            return 0.0, 0.0, True
        w = float(np.clip(1.5 * err, -0.6, 0.6)) if dist > 0.05 else 0.0
        if abs(err) > GO_ALIGNED:
            return 0.0, w, False
        return min(speed, 0.8 * dist) * math.cos(err), w, False

    _drive_loop(driver, cmd)
