"""Time parametrization of a joint path within joint speed, joint acceleration and TCP speed
limits (paper 004 section 7.4 leaves this to its planner; we do it explicitly).

A path is a polyline of joint waypoints. Each segment gets the shortest duration that keeps
every joint under `v_max` and the TCP under `tcp_speed` at full speed. Those durations define
a path parameter sigma ("nominal time"); sigma then follows a trapezoidal profile with peak
rate 1 and acceleration `a_max / v_max`, so that along each segment no joint accelerates
faster than `a_max`. The arm starts and stops at rest.
"""

from __future__ import annotations

import math

import numpy as np

from laserpick.types import GripperEvent, Trajectory


def segment_durations(
    q: np.ndarray,
    v_max: float,
    tcp: np.ndarray | None = None,
    tcp_speed: float | None = None,
) -> np.ndarray:
    """Shortest time (s) for each of the K-1 segments at full speed.

    q: (K, 6) joint waypoints (rad). tcp: (K, 3) TCP positions (m) at those waypoints, with
    `tcp_speed` (m/s), to cap the hand's speed near people.
    """
    dq = np.max(np.abs(np.diff(q, axis=0)), axis=1) / v_max
    if tcp is not None and tcp_speed is not None:
        dq = np.maximum(dq, np.linalg.norm(np.diff(tcp, axis=0), axis=1) / tcp_speed)
    return dq


def _trapezoid(length: float, accel: float) -> tuple[float, float]:
    """Cruise rate and total time of a rest-to-rest trapezoid over `length` with peak rate 1."""
    if length <= 0:
        return 0.0, 0.0
    if length >= 1.0 / accel:  # reaches rate 1: ramps take 1/accel each, covering 1/accel
        return 1.0, length + 1.0 / accel
    peak = math.sqrt(length * accel)  # triangle
    return peak, 2.0 * peak / accel


def _sigma_at(t: np.ndarray, length: float, accel: float) -> np.ndarray:
    peak, total = _trapezoid(length, accel)
    t_ramp = peak / accel
    ramp_len = 0.5 * accel * t_ramp**2
    return np.where(
        t < t_ramp,
        0.5 * accel * t**2,
        np.where(
            t < total - t_ramp,
            ramp_len + peak * (t - t_ramp),
            length - 0.5 * accel * np.clip(total - t, 0, None) ** 2,
        ),
    )


def time_parametrize(
    q: np.ndarray,
    *,
    v_max: float,
    a_max: float,
    tcp: np.ndarray | None = None,
    tcp_speed: float | None = None,
    dt: float = 0.01,
    gripper: tuple[tuple[int, str], ...] = (),
) -> Trajectory:
    """A rest-to-rest trajectory along the joint polyline `q` (K, 6), sampled every `dt` s.

    gripper: (waypoint index, "open"|"close") pairs; each event fires when the arm reaches
    that waypoint.
    """
    q = np.asarray(q, dtype=float)
    if q.ndim != 2 or q.shape[1] != 6 or len(q) < 2:
        raise ValueError(f"need at least two (6,) joint waypoints, got shape {q.shape}")
    if not (v_max > 0 and a_max > 0 and dt > 0):
        raise ValueError("v_max, a_max and dt must be positive")
    seg = segment_durations(q, v_max, tcp, tcp_speed)
    knots = np.concatenate([[0.0], np.cumsum(seg)])
    length = float(knots[-1])
    accel = a_max / v_max
    _, total = _trapezoid(length, accel)
    if total == 0.0:
        return Trajectory(times=np.array([0.0]), q=q[:1].copy())
    n = max(2, math.ceil(total / dt) + 1)
    t = np.linspace(0.0, total, n)
    sigma = np.clip(_sigma_at(t, length, accel), 0.0, length)
    path = np.column_stack([np.interp(sigma, knots, q[:, j]) for j in range(6)])
    # The time at which sigma reaches each waypoint, for gripper events.
    events = []
    for index, action in gripper:
        if not 0 <= index < len(q):
            raise ValueError(f"gripper event at waypoint {index}, path has {len(q)}")
        t_event = float(np.interp(knots[index], sigma, t)) if index else 0.0
        events.append(GripperEvent(t_event, action))  # type: ignore[arg-type]
    return Trajectory(times=t, q=path, gripper=tuple(events))
