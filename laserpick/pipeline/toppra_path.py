"""The fastest path velocity profile along a blended joint path (`smoothing.BlendedPath`):
TOPP-RA (Pham and Pham 2018, the `toppra` package) under the joint speed and acceleration
limits, the TCP's speed cap, the hand's turning cap and caps of the caller's own at the
grid points, the arm at rest at both ends (`timing` smooths and checks what it gives).

Units: rad, s, m; TCP positions in `base`.
"""

from __future__ import annotations

import functools
import itertools
import math
from typing import TYPE_CHECKING

import numpy as np
import toppra
import toppra.algorithm
import toppra.constraint
from toppra.constraint import LinearConstraint

from laserpick.description.kinematics import tcp_pose
from laserpick.pipeline.smoothing import BlendedPath
from laserpick.transforms import rotation_angles

if TYPE_CHECKING:
    from laserpick.pipeline.timing import Limits

__all__ = ["GRID_STEP", "INSIDE", "FastestProfile", "path_grid"]

#: TOPP-RA's grid: at most this far apart (rad of path), and at least this many intervals
#: in every piece of the path (a blend's curvature changes within it).
GRID_STEP = 0.02
GRID_PER_PIECE = 4
#: TOPP-RA and the smoothing aim this much inside the limits, so that a profile at a limit
#: is not taken for one over it by rounding.
INSIDE = 1.0 - 1e-6
#: Step (rad) of the finite difference that gives the TCP's speed along the path.
_EPS = 1e-6
#: The highest path velocity cap (rad of path per s): TOPP-RA's bounds are squared.
LARGE = 1e3


def path_grid(path: BlendedPath) -> np.ndarray:
    """TOPP-RA's grid points (rad of path): every piece of the path split into equal
    intervals."""
    x = path.poly.x
    parts = [
        np.linspace(a, b, max(GRID_PER_PIECE, math.ceil((b - a) / GRID_STEP)) + 1)[:-1]
        for a, b in itertools.pairwise(x)
    ]
    return np.concatenate([*parts, [x[-1]]])


class FastestProfile:
    """TOPP-RA on one path and grid under `limits`, for caps that change from run to run:
    what does not change (the path's derivatives on the grid, the TCP's and the hand's speed
    bounds, the joint constraints) is evaluated once."""

    def __init__(self, path: BlendedPath, grid: np.ndarray, limits: Limits) -> None:
        self.path, self.grid = _Path(path), grid
        self.joints = _joint_constraints(limits.speed, limits.accel)
        self.speed_caps = _speed_caps(path, grid, limits)

    def __call__(self, caps: np.ndarray) -> np.ndarray:
        """The time-optimal path velocities sd (N,) at the grid points, each at most its cap
        (N,) (rad of path per s)."""
        constraints = [*self.joints, _SpeedBound(self.speed_caps, caps)]
        algo = toppra.algorithm.TOPPRA(constraints, self.path, gridpoints=self.grid)
        _, sd, _ = algo.compute_parameterization(0.0, 0.0)
        if sd is None:
            raise RuntimeError("TOPP-RA found no parametrization of the path")
        return np.maximum(sd, 0.0)


class _Path(toppra.interpolator.AbstractGeometricPath):
    """A `BlendedPath` as TOPP-RA reads a path. Its last evaluation of each order is kept:
    every TOPP-RA run on one path asks for the same grid's (`FastestProfile`)."""

    def __init__(self, path: BlendedPath) -> None:
        self._path = path
        self._interval = np.array([0.0, path.length])
        self._kept: dict[int, tuple[bytes, np.ndarray]] = {}

    def __call__(self, path_positions, order: int = 0) -> np.ndarray:
        key = np.asarray(path_positions, float).tobytes()
        kept = self._kept.get(order)
        if kept is None or kept[0] != key:
            kept = self._kept[order] = key, self._path(path_positions, order)
        return kept[1].copy()

    @property
    def dof(self) -> int:
        return 6

    @property
    def path_interval(self) -> np.ndarray:
        return self._interval


def _speed_caps(path: BlendedPath, grid: np.ndarray, limits: Limits) -> np.ndarray:
    """(N,) bounds on sd^2 at the grid points that keep the TCP's speed |dp/ds| sd <=
    tcp_speed and the hand's turning speed |dR/ds| sd <= turn_speed (None: no cap)."""
    bound = np.full(len(grid), np.inf)
    tcp_speed, turn_speed = limits.tcp_speed, limits.turn_speed
    if tcp_speed is None and turn_speed is None:
        return bound
    q, dq = path(grid, 0), path(grid, 1)
    ahead, behind = tcp_pose(q + _EPS * dq), tcp_pose(q - _EPS * dq)
    rates = []  # (limit, its unit per rad of path)
    if tcp_speed is not None:
        step = np.linalg.norm(ahead[:, :3, 3] - behind[:, :3, 3], axis=1)
        rates.append((tcp_speed, step / (2 * _EPS)))
    if turn_speed is not None:
        turn = rotation_angles(behind[:, :3, :3], ahead[:, :3, :3])
        rates.append((turn_speed, turn / (2 * _EPS)))
    for limit, rate in rates:
        # The largest of its neighbours too: the bound holds between grid points.
        edge = np.pad(rate, 1, mode="edge")
        rate = np.maximum.reduce([edge[:-2], rate, edge[2:]])
        cap = limit * INSIDE / np.maximum(rate, 1e-9)
        bound = np.minimum(bound, cap**2)
    return bound


class _SpeedBound(LinearConstraint):
    """Bounds on sd^2 at each grid point: `speed_caps` (N,) (`_speed_caps`) and sd <= caps
    (N,), the grid's own caps."""

    def __init__(self, speed_caps: np.ndarray, caps: np.ndarray) -> None:
        super().__init__()
        self.speed_caps = speed_caps
        self.caps = caps
        self.dof = 6

    def compute_constraint_params(self, path, gridpoints):
        xbound = np.zeros((len(gridpoints), 2))
        xbound[:, 1] = np.minimum(np.minimum(self.caps, LARGE) ** 2, self.speed_caps)
        return None, None, None, None, None, None, xbound


@functools.lru_cache(maxsize=16)
def _joint_constraints(speed: float, accel: float) -> tuple[LinearConstraint, LinearConstraint]:
    """TOPP-RA's joint speed and acceleration constraints (rad/s, rad/s^2, each joint), made
    once: they hold no path, and making them formats their limits to text (6 % of the
    timing's cost)."""
    return (
        toppra.constraint.JointVelocityConstraint(np.full(6, speed * INSIDE)),
        toppra.constraint.JointAccelerationConstraint(np.full(6, accel * INSIDE)),
    )
