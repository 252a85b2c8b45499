"""Time parametrization of a joint path: smooth, time-optimal and jerk-limited, within the
joint speed, joint acceleration, joint jerk and TCP speed limits.

1. The polyline's corners are blended (`smoothing.corners`): the path is C2. A corner whose
   blend would be too tight to take at STOP_SPEED is not: the arm comes to rest there, and
   each part between such corners is timed alone.
2. TOPP-RA (Pham and Pham 2018, the `toppra` package; `toppra_path`) finds the fastest
   path velocity profile under the joint speed and acceleration limits and the TCP speed
   cap, the arm at rest at both ends. Its path acceleration is constant between grid points
   and jumps at them.
3. The profile is smoothed in time: s_f(t) is the mean of s over [t - tau, t]. Its path
   velocity is (s(t) - s(t - tau)) / tau, its acceleration the mean of TOPP-RA's, so
   continuous, and its jerk the change of TOPP-RA's acceleration over tau, divided by tau:
   tau = a_max / j_max keeps a jump from rest to full acceleration within the jerk limit.
   Along the bends, the path velocity is capped from the start so that the bends' own share
   of the jerk (their curvature and its change, at speed) stays within half the limit.
4. The trajectory is sampled every dt and checked by finite differences, the arm at rest
   before and after: joint speed, acceleration and jerk and the TCP's speed. Where the
   smoothing overshot (it lets the arm round a corner a little faster than TOPP-RA did), the
   path velocity is capped around the samples that were over, and TOPP-RA runs again; where
   only the jerk was over, tau is widened (up to TAU_MAX times) and the profile kept. After
   PASSES tries, what is left over is taken out by slowing the whole part uniformly in time
   (speed scales with 1/k, acceleration with 1/k^2, jerk with 1/k^3), checked again on the
   new samples until they keep every limit.

Units: rad, s, m; TCP positions in `base`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from laserpick.description.kinematics import tcp_pose
from laserpick.pipeline.smoothing import BlendedPath, ClearFn, corners
from laserpick.pipeline.toppra_path import GRID_STEP, INSIDE, FastestProfile, path_grid
from laserpick.transforms import rotation_angles
from laserpick.types import GripperEvent, Trajectory

__all__ = ["Limits", "excess", "straight_times", "time_parametrize"]

#: Checks and corrections of the sampled trajectory before the last, uniform slow-down.
PASSES = 4
#: Corrections aim this far under the limits, so that sampling does not put them back over.
MARGIN = 1.002
#: The lowest path velocity cap (rad of path per s): the arm would barely move.
MIN_CAP = 1e-3
#: A corner whose blend the arm could take no faster than this (rad of path per s) is not
#: blended: the arm stops there (a tight blend would take as long).
STOP_SPEED = 0.05
#: The widest the smoothing gets, in a_max / j_max: a switch from full acceleration to full
#: deceleration needs twice the time of a start from rest.
TAU_MAX = 2.0
#: Uniform slowdowns tried at the end; each takes out what the last left over.
SLOWDOWNS = 8


@dataclass(frozen=True)
class Limits:
    """The motion's limits: joint speed (rad/s), acceleration (rad/s^2) and jerk (rad/s^3),
    each for every joint; the TCP's speed (m/s, None: no cap) and the hand's turning speed
    (rad/s, the TCP frame's angular speed in `base`; None: no cap)."""

    speed: float
    accel: float
    jerk: float
    tcp_speed: float | None = None
    turn_speed: float | None = None

    def __post_init__(self) -> None:
        if not (self.speed > 0 and self.accel > 0 and self.jerk > 0):
            raise ValueError("joint speed, acceleration and jerk limits must be positive")
        if self.tcp_speed is not None and not self.tcp_speed > 0:
            raise ValueError("the TCP speed cap must be positive")
        if self.turn_speed is not None and not self.turn_speed > 0:
            raise ValueError("the hand's turning speed cap must be positive")


def straight_times(a: np.ndarray, b: np.ndarray, limits: Limits, samples: int = 6) -> np.ndarray:
    """(B,) the least time (s) each straight joint move from a (B, 6) to b (B, 6) (rad)
    takes at the speed limits, its accelerations left out: the largest joint's motion at
    the joint speed, the TCP's arc at its cap and the hand's turning at its cap, the
    slowest. The arc and the turns are summed over `samples` configurations along the
    move: a joint move swings the hand along an arc, not a chord."""
    a, b = np.atleast_2d(a), np.atleast_2d(b)
    f = np.linspace(0.0, 1.0, samples)[None, :, None]
    T = tcp_pose((a[:, None, :] + f * (b - a)[:, None, :]).reshape(-1, 6))
    T = T.reshape(len(a), samples, 4, 4)
    times = [np.abs(b - a).max(axis=1) / limits.speed]
    if limits.tcp_speed is not None:
        arc = np.linalg.norm(np.diff(T[:, :, :3, 3], axis=1), axis=2).sum(axis=1)
        times.append(arc / limits.tcp_speed)
    if limits.turn_speed is not None:
        turn = rotation_angles(T[:, :-1, :3, :3], T[:, 1:, :3, :3]).sum(axis=1)
        times.append(turn / limits.turn_speed)
    return np.maximum.reduce(times)


@dataclass(frozen=True)
class _Profile:
    """s(t) at constant path acceleration between grid points, and its running integral."""

    t: np.ndarray  # (N,) time at each grid point
    s: np.ndarray
    sd: np.ndarray
    sdd: np.ndarray  # (N - 1,) constant on each interval
    integral: np.ndarray  # (N,) integral of s from 0 to t

    @classmethod
    def of(cls, s: np.ndarray, sd: np.ndarray) -> _Profile:
        ds = np.diff(s)
        dt = 2.0 * ds / np.maximum(sd[:-1] + sd[1:], 1e-12)
        sdd = (sd[1:] - sd[:-1]) / dt
        t = np.concatenate([[0.0], np.cumsum(dt)])
        piece = s[:-1] * dt + sd[:-1] * dt**2 / 2 + sdd * dt**3 / 6
        return cls(t, s, sd, sdd, np.concatenate([[0.0], np.cumsum(piece)]))

    @property
    def duration(self) -> float:
        return float(self.t[-1])

    def integral_at(self, t: np.ndarray) -> np.ndarray:
        """The integral of s(t) from 0 to t, with s = 0 before the start and the path's
        length after the end."""
        i = np.clip(np.searchsorted(self.t, t, side="right") - 1, 0, len(self.sdd) - 1)
        u = np.clip(t, 0.0, self.duration) - self.t[i]
        inside = self.integral[i] + self.s[i] * u + self.sd[i] * u**2 / 2 + self.sdd[i] * u**3 / 6
        after = self.s[-1] * np.maximum(t - self.duration, 0.0)
        return np.where(t <= 0.0, 0.0, inside + after)

    def smoothed(self, t: np.ndarray, tau: float) -> np.ndarray:
        """s_f(t): the mean of s over [t - tau, t]."""
        return (self.integral_at(t) - self.integral_at(t - tau)) / tau


def _ratios(q: np.ndarray, h: float, limits: Limits) -> dict[str, np.ndarray]:
    """Per sample of q (T, 6) rad, h s apart, the largest ratio to its limit of the joint
    speeds, accelerations and jerks, the TCP's speed and the hand's turning speed that it
    takes part in: by finite differences, the arm at rest before and after."""
    pad = 3
    rest = np.vstack([np.repeat(q[:1], pad, axis=0), q, np.repeat(q[-1:], pad, axis=0)])
    v = np.abs(np.diff(rest, axis=0)).max(axis=1) / h
    a = np.abs(np.diff(rest, 2, axis=0)).max(axis=1) / h**2
    j = np.abs(np.diff(rest, 3, axis=0)).max(axis=1) / h**3
    n = len(q)

    def per_sample(d: np.ndarray) -> np.ndarray:  # difference i takes samples i .. i + k
        k = len(rest) - len(d)
        full = np.max([np.pad(d, (s, k - s)) for s in range(k + 1)], axis=0)
        return full[pad : pad + n]

    out = {
        "speed": per_sample(v) / limits.speed,
        "accel": per_sample(a) / limits.accel,
        "jerk": per_sample(j) / limits.jerk,
        "tcp_speed": np.zeros(n),
        "turn_speed": np.zeros(n),
    }
    if n < 2 or (limits.tcp_speed is None and limits.turn_speed is None):
        return out
    T = tcp_pose(q)
    steps = {}
    if limits.tcp_speed is not None:
        steps["tcp_speed"] = np.linalg.norm(np.diff(T[:, :3, 3], axis=0), axis=1) / limits.tcp_speed
    if limits.turn_speed is not None:
        steps["turn_speed"] = rotation_angles(T[:-1, :3, :3], T[1:, :3, :3]) / limits.turn_speed
    for name, step in steps.items():
        step = step / h
        out[name] = np.maximum(np.append(step, 0.0), np.insert(step, 0, 0.0))
    return out


def excess(q: np.ndarray, h: float, limits: Limits) -> dict[str, float]:
    """How far samples q (T, 6) rad, h s apart, go over each limit: the largest ratio of
    value to limit of joint speed, acceleration, jerk, TCP speed and the hand's turning
    speed, by finite differences,
    the arm at rest before and after (1 is at the limit)."""
    return {name: float(r.max()) for name, r in _ratios(q, h, limits).items()}


def _slowdown(ratios: dict[str, np.ndarray]) -> np.ndarray:
    """Per sample, how many times slower the arm must go there to keep the joint speed,
    acceleration, TCP speed and turning speed limits."""
    speeds = [ratios["speed"], ratios["tcp_speed"], ratios["turn_speed"]]
    return np.maximum.reduce([*speeds, np.sqrt(ratios["accel"])])


def _sampled(
    path: BlendedPath, profile: _Profile, tau: float, slow: float, dt: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times (T,), path positions (T,) and joint angles (T, 6) every dt, of the smoothed
    profile slowed `slow` times (and up to one sample more, to end on a sample)."""
    total = (profile.duration + tau) * slow
    n = max(1, math.ceil(total / dt - 1e-9))
    slow *= n * dt / total  # a whole number of samples dt apart: a little slower, if at all
    t = np.arange(n + 1) * dt
    s = np.clip(profile.smoothed(t / slow, tau), 0.0, path.length)
    s[-1] = path.length
    return t, s, path(s)


def _lower_caps(
    caps: np.ndarray, grid: np.ndarray, t: np.ndarray, s: np.ndarray, slow: np.ndarray, tau: float
) -> np.ndarray:
    """The path velocity caps on the grid, lowered around each sample that needs `slow` > 1
    to the path velocity it had there over `slow`, over the path it covers in tau either
    side: the smoothing averages the profile over that much."""
    sd = np.gradient(s, t)
    caps = caps.copy()
    for k in np.flatnonzero(slow > 1.0):
        reach = sd[k] * tau + GRID_STEP
        near = np.abs(grid - s[k]) <= reach
        caps[near] = np.minimum(caps[near], max(sd[k] / (slow[k] * MARGIN), MIN_CAP))
    return caps


def _bend_caps(path: BlendedPath, grid: np.ndarray, limits: Limits) -> np.ndarray:
    """Path velocity caps (rad/s) that keep the jerk of the path's bends within half the
    limit each: q''' sd^3 (the bend's change) and 3 q'' sd sdd (its curvature while the
    arm speeds up or slows down at up to the acceleration limit)."""
    bend = np.abs(path(grid, 2)).max(axis=1)
    twist = np.abs(path(grid, 3)).max(axis=1)
    with np.errstate(divide="ignore"):
        return np.minimum(
            np.cbrt(limits.jerk / 2 / twist), limits.jerk / 2 / (3 * limits.accel * bend)
        )


def _within_limits(
    path: BlendedPath, limits: Limits, dt: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The smoothed, sampled trajectory (times, s, q) within every limit (module docstring,
    steps 2-4). Over the speed or acceleration limits, the path velocity is capped around
    the samples that were; over the jerk limit, the smoothing is widened, up to TAU_MAX
    times a_max / j_max, then capped too."""
    grid = path_grid(path)
    caps = _bend_caps(path, grid, limits)
    tau = tau_0 = limits.accel / limits.jerk / INSIDE
    fastest = FastestProfile(path, grid, limits)
    profile, profiled = _Profile.of(grid, fastest(caps)), caps
    for _ in range(PASSES):
        # TOPP-RA again only where the caps changed: a jerk over the limit that the wider
        # smoothing takes out leaves them (the first pass of most transits: their jump from
        # full acceleration to cruise), and TOPP-RA is most of the timing's cost.
        if not np.array_equal(caps, profiled):
            profile, profiled = _Profile.of(grid, fastest(caps)), caps
        t, s, q = _sampled(path, profile, tau, 1.0, dt)
        ratios = _ratios(q, t[1] - t[0], limits)
        slow, jerk = _slowdown(ratios), ratios["jerk"]
        if slow.max() <= 1.0 and jerk.max() <= 1.0:
            return t, s, q
        wider = min(tau * max(float(jerk.max()) * MARGIN, 1.0), TAU_MAX * tau_0)
        if wider == tau:
            slow = np.maximum(slow, np.cbrt(jerk))
        caps = _lower_caps(caps, grid, t, s, slow, tau)
        tau = wider
    # Slowed uniformly until the samples keep every limit: sampled at dt again, the slowed
    # profile's finite differences do not scale exactly (a carry's jerk came out 0.3 % over).
    # Each slowdown takes at least one sample more: the samples end on a whole one, so a
    # slowdown short of a sample's time changes none of them (a 2 cm re-grip lift's jerk
    # stayed 0.05 % over through every slowdown, and the pick failed).
    k = 1.0
    for _ in range(SLOWDOWNS):
        ratios = _ratios(q, t[1] - t[0], limits)
        over = max(float(_slowdown(ratios).max()), float(ratios["jerk"].max()) ** (1 / 3))
        if over <= 1.0:
            return t, s, q
        k = max(k * over * MARGIN, (t[-1] + dt) / (profile.duration + tau))
        t, s, q = _sampled(path, profile, tau, k, dt)
    raise RuntimeError(f"no timing within the limits after slowing {k:.2f} times")


def time_parametrize(
    q: np.ndarray,
    *,
    limits: Limits,
    tolerance: float,
    checked_tolerance: float | None = None,
    clear: Sequence[ClearFn | None] | ClearFn | None = None,
    dt: float = 0.01,
    gripper: tuple[tuple[int, str], ...] = (),
) -> Trajectory:
    """A trajectory along the joint polyline q (K, 6) rad from rest to rest, sampled every
    dt s, with its corners blended (`smoothing.corners`: within `tolerance` rad of
    the polyline, or `checked_tolerance` where the leg checks `clear` pass the blend), and
    coming to rest at a corner whose blend would allow less than STOP_SPEED.

    gripper: (waypoint index, "open"|"close") pairs; each event fires when the arm passes
    that waypoint (the middle of its blend).
    """
    q = np.asarray(q, dtype=float)
    if q.ndim != 2 or q.shape[1] != 6 or len(q) < 2:
        raise ValueError(f"need at least two (6,) joint waypoints, got shape {q.shape}")
    if not (dt > 0 and tolerance > 0):
        raise ValueError("dt and the blend tolerance must be positive")
    for index, _ in gripper:
        if not 0 <= index < len(q):
            raise ValueError(f"gripper event at waypoint {index}, path has {len(q)}")
    if np.all(np.abs(q - q[0]) < 1e-9):
        return Trajectory(times=np.array([0.0]), q=q[:1].copy())
    found = corners(q, tolerance, checked_tolerance=checked_tolerance, clear=clear)
    stops = np.flatnonzero(found.blend_speed(limits.accel, limits.jerk) < STOP_SPEED)
    times, samples, passed = [np.zeros(1)], [q[:1]], np.full(len(q), np.nan)
    for path, waypoints in found.paths(stops):
        t, s, part = _within_limits(path, limits, dt)
        start = times[-1][-1]
        at = start + np.interp(path.vertex_s, s, t)
        passed[waypoints] = np.where(np.isnan(passed[waypoints]), at, passed[waypoints])
        times.append(start + t[1:])
        samples.append(part[1:])
    q_out = np.concatenate(samples)
    q_out[-1] = q[-1]
    events = tuple(GripperEvent(float(passed[i]), action) for i, action in gripper)  # type: ignore[arg-type]
    return Trajectory(times=np.concatenate(times), q=q_out, gripper=events)
