"""Corner blends: a joint polyline turned into paths with continuous tangent and curvature,
so that a trajectory along them can be continuous in velocity and acceleration.

Each corner P between legs of directions u1 and u2 is replaced by a quintic Bezier blend from
A = P - d u1 to B = P + d u2 whose control points lie on the two legs (P - d u1, P - 0.6 d u1,
P - 0.2 d u1, P + 0.2 d u2, P + 0.6 d u2, P + d u2): it leaves A along u1 and reaches B along
u2 with zero second derivative at both ends, so the path stays C2, and it lies in the
triangle A P B. Its deviation from the polyline grows in proportion to its reach d; d is
chosen so that the deviation stays within a tolerance (rad, Euclidean in joint space), and a
blend never takes more than its share of a leg (half, or all of a first or last leg).

Where the caller can check configurations for collisions (`clear`), a corner's blend may
deviate up to a larger tolerance, and is halved until every configuration along it, sampled
as densely as `CollisionChecker.segment_ok` samples a leg, is clear; without a check, or
where none of the larger blends is clear, it keeps to the small tolerance. A corner whose
blend stays so tight that the arm would crawl through it is not blended: the arm stops
there (`Corners.paths`), exactly on the polyline.

The path parameter s (rad) is arc length along the straight parts; along a blend it runs
2 d, the blend's speed |dq/ds| is 1 at its ends and dips below 1 where it cuts the corner.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import BPoly

__all__ = ["BlendedPath", "ClearFn", "Corners", "corners"]

#: Configurations (B, 6) rad along a path -> whether every one of them is clear.
ClearFn = Callable[[np.ndarray], bool]

#: The quintic blend's control points, as fractions of d along the incoming (negative) and
#: outgoing (positive) leg.
_CONTROL = np.array([-1.0, -0.6, -0.2, 0.2, 0.6, 1.0])
#: Points at which a blend's deviation and derivatives are measured.
_SAMPLES = 65
#: Largest joint motion (rad) between checked configurations of a blend, as `segment_ok`.
CHECK_STEP = 0.03
#: Halvings of a blend that failed its check before it falls back to the small tolerance.
CHECK_HALVINGS = 3
#: Legs shorter than this (rad) are dropped: repeated waypoints.
_MIN_LEG = 1e-9


@dataclass(frozen=True)
class BlendedPath:
    """A C2 joint path through blended corners.

    poly: Bernstein piecewise quintic, s (rad) -> q (6,) rad, over [0, length].
    vertex_s: (K,) the path position at (or, for a blended corner, nearest) each vertex of
    the polyline it was made from.
    """

    poly: BPoly
    vertex_s: np.ndarray

    @property
    def length(self) -> float:
        return float(self.poly.x[-1])

    @functools.cached_property
    def _orders(self) -> list[BPoly]:
        return [self.poly, *(self.poly.derivative(k) for k in (1, 2, 3))]

    def __call__(self, s: np.ndarray | float, order: int = 0) -> np.ndarray:
        """q (rad) or its order-th derivative (order <= 3) with respect to s at path
        positions s."""
        return self._orders[order](np.clip(s, 0.0, self.length))


def _control_points(p: np.ndarray, u1: np.ndarray, u2: np.ndarray, d: float) -> np.ndarray:
    """(6, 6) control points of the blend at corner p with reach d along each leg."""
    legs = np.where(_CONTROL[:, None] < 0, u1[None, :], u2[None, :])
    return p[None, :] + (_CONTROL * d)[:, None] * legs


def _bernstein(degree: int, tau: np.ndarray) -> np.ndarray:
    """(len(tau), degree + 1) Bernstein basis polynomials of `degree` at tau in [0, 1]."""
    k = np.arange(degree + 1)
    binom = np.array([math.comb(degree, i) for i in k], float)
    return binom * tau[:, None] ** k * (1.0 - tau[:, None]) ** (degree - k)


#: The blend's points and its second and third derivatives (per unit tau) at _SAMPLES
#: points, as matrices on its control points (a quintic: 20 and 60 times the second and
#: third differences of its control points, on the cubic and quadratic bases).
_TAU = np.linspace(0.0, 1.0, _SAMPLES)
_AT, _BEND, _TWIST = _bernstein(5, _TAU), 20.0 * _bernstein(3, _TAU), 60.0 * _bernstein(2, _TAU)


def _unit_blend(u1: np.ndarray, u2: np.ndarray) -> tuple[float, float, float]:
    """For the blend with d = 1 at a corner at the origin (2 rad of path long): its largest
    distance from the legs, and the largest |q''| and |q'''| of any joint along it, per unit
    path."""
    ctrl = _control_points(np.zeros(6), u1, u2, 1.0)
    pts = _AT @ ctrl
    gaps = []
    for u in (-u1, u2):  # each leg as a ray from the corner, of length 1
        along = np.clip(pts @ u, 0.0, 1.0)
        gaps.append(np.linalg.norm(pts - along[:, None] * u[None, :], axis=1))
    bend = np.abs(_BEND @ np.diff(ctrl, 2, axis=0)).max() / 2.0**2  # d/ds = d/dtau / 2
    twist = np.abs(_TWIST @ np.diff(ctrl, 3, axis=0)).max() / 2.0**3
    return float(np.max(np.minimum(*gaps))), float(bend), float(twist)


def _blend_samples(p: np.ndarray, u1: np.ndarray, u2: np.ndarray, d: float) -> np.ndarray:
    """Configurations along the blend, no more than CHECK_STEP apart in any joint: a
    quintic moves no joint faster per unit tau than 5 times its control points' largest
    step in that joint."""
    ctrl = _control_points(p, u1, u2, d)
    rate = 5.0 * float(np.abs(np.diff(ctrl, axis=0)).max())
    n = max(2, math.ceil(rate / CHECK_STEP) + 1)
    return _bernstein(5, np.linspace(0.0, 1.0, n)) @ ctrl


@dataclass(frozen=True)
class Corners:
    """A polyline's corners and their blends.

    q: (K, 6) rad, the polyline less repeated waypoints; index: (M,) each input waypoint's
    row in q. reach: (K,) each blend's d (rad; 0 at the ends). deviation: (K,) how far each
    blend strays from the polyline (rad). bend, twist: (K,) the blend's largest |q''| and
    |q'''| of any joint (per rad of path, and per rad squared).
    """

    q: np.ndarray
    index: np.ndarray
    reach: np.ndarray
    deviation: np.ndarray
    bend: np.ndarray
    twist: np.ndarray

    def blend_speed(self, accel: float, jerk: float) -> np.ndarray:
        """(K,) the path speed (rad/s) each blend allows at most: its curvature at `accel`
        (rad/s^2), and the change of its curvature at `jerk` (rad/s^3); inf where there is
        no corner."""
        with np.errstate(divide="ignore"):
            return np.minimum(np.sqrt(accel / self.bend), np.cbrt(jerk / self.twist))

    def paths(self, stops: np.ndarray) -> list[tuple[BlendedPath, np.ndarray]]:
        """The blended paths between the ends and the vertices in `stops` (indices into q),
        where the arm comes to rest on the polyline; each with the input waypoints it
        covers (indices into the input)."""
        cuts = sorted({0, len(self.q) - 1, *(int(k) for k in stops)})
        out = []
        for a, b in itertools.pairwise(cuts):
            reach = self.reach[a : b + 1].copy()
            reach[0] = reach[-1] = 0.0
            path = _assemble(self.q[a : b + 1], reach)
            mine = np.flatnonzero((self.index >= a) & (self.index <= b))
            vertex_s = path.vertex_s[self.index[mine] - a]
            out.append((BlendedPath(path.poly, vertex_s), mine))
        return out


def _reach(
    p: np.ndarray,
    u1: np.ndarray,
    u2: np.ndarray,
    share: float,
    tolerances: tuple[float, float],
    clear: ClearFn | None,
) -> tuple[float, tuple[float, float, float]]:
    """The blend's reach d (rad) at corner p and its unit measures (`_unit_blend`)."""
    unit = _unit_blend(u1, u2)
    if unit[0] < 1e-12:  # a straight pass: any reach keeps to the line
        return share, unit
    d = min(share, tolerances[0] / unit[0])
    if clear is not None:
        wide = min(share, tolerances[1] / unit[0])
        for _ in range(CHECK_HALVINGS + 1):
            if wide <= d:
                break
            if clear(_blend_samples(p, u1, u2, wide)):
                d = wide
                break
            wide /= 2.0
    return d, unit


def _both(a: ClearFn | None, b: ClearFn | None) -> ClearFn | None:
    """The check a blend between legs checked by a and b must pass: both (None if either
    leg has no check); b is asked only where a passes every configuration."""
    if a is None or b is None:
        return None
    if a is b:
        return a

    return lambda Q: a(Q) and b(Q)


def corners(
    q: np.ndarray,
    tolerance: float,
    *,
    checked_tolerance: float | None = None,
    clear: Sequence[ClearFn | None] | ClearFn | None = None,
) -> Corners:
    """The corners of the joint polyline q (K, 6) rad and their blends.

    tolerance: how far (rad) an unchecked blend may stray from the polyline.
    checked_tolerance: how far a blend may stray where `clear` passes it.
    clear: a check for every leg (one for all, or one per leg, None where there is none); a
    blend must pass the checks of both its legs.
    """
    q = np.asarray(q, float)
    keep = np.concatenate([[True], np.linalg.norm(np.diff(q, axis=0), axis=1) > _MIN_LEG])
    index = np.cumsum(keep) - 1
    legs = list(clear) if isinstance(clear, Sequence) else [clear] * (len(q) - 1)
    checks = [legs[i - 1] for i in np.flatnonzero(keep)[1:]]
    q = q[keep]
    n = len(q) - 1
    if n < 1:
        raise ValueError("a path needs two distinct waypoints")
    delta = np.diff(q, axis=0)
    length = np.linalg.norm(delta, axis=1)
    u = delta / length[:, None]
    share = length * np.where((np.arange(n) == 0) | (np.arange(n) == n - 1), 1.0, 0.5)
    tolerances = (tolerance, checked_tolerance or tolerance)
    out = np.zeros((4, n + 1))  # reach, deviation, bend, twist
    for k in range(1, n):
        check = _both(checks[k - 1], checks[k])
        d, (dev, bend, twist) = _reach(
            q[k], u[k - 1], u[k], min(share[k - 1], share[k]), tolerances, check
        )
        out[:, k] = d, dev * d, bend / d if d > 0 else 0.0, twist / d**2 if d > 0 else 0.0
    return Corners(q, index, *out)


def _assemble(q: np.ndarray, reach: np.ndarray) -> BlendedPath:
    """The path of straight pieces and blends along the polyline q (K, 6), each piece a
    quintic in Bernstein form; vertex_s for every vertex of q."""
    delta = np.diff(q, axis=0)
    length = np.linalg.norm(delta, axis=1)
    u = delta / length[:, None]
    pieces: list[np.ndarray] = []
    widths: list[float] = []
    vertex_s = np.zeros(len(q))
    s = 0.0
    line = np.linspace(0.0, 1.0, 6)[:, None]
    for k in range(len(q) - 1):
        if k > 0 and reach[k] > 0:
            pieces.append(_control_points(q[k], u[k - 1], u[k], reach[k]))
            widths.append(2.0 * reach[k])
            vertex_s[k] = s + reach[k]
            s += 2.0 * reach[k]
        elif k > 0:
            vertex_s[k] = s
        straight = length[k] - reach[k] - reach[k + 1]
        if straight > 1e-12:
            a = q[k] + reach[k] * u[k]
            pieces.append(a[None, :] + line * (straight * u[k])[None, :])
            widths.append(straight)
            s += straight
    vertex_s[-1] = s
    x = np.concatenate([[0.0], np.cumsum(widths)])
    return BlendedPath(BPoly(np.stack(pieces, axis=1), x), vertex_s)
