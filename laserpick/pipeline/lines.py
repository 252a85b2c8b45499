"""Straight lines of the hand: joint waypoints that move the TCP in a straight line, its
orientation turned evenly on the way (the approach, the lifts, the rises and descents).

Frames: TCP poses in `base` (m); joint angles in rad.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from laserpick.description.kinematics import ik_tcp, tcp_pose
from laserpick.transforms import rotation_angle

__all__ = ["CARTESIAN_JUMP", "TURN_STEP", "cartesian_line"]

#: Largest joint change (rad) between neighbouring waypoints of a Cartesian line: a bigger
#: step means the IK jumped branches (a singularity), so the line is not followed.
CARTESIAN_JUMP = 0.25
#: The most (rad) the hand turns between two waypoints of a line: a hand turned about its
#: TCP, moving nowhere, reached a 30 deg turn in one step, past `CARTESIAN_JUMP`.
TURN_STEP = 0.05


def _line_poses(Ta: np.ndarray, Tb: np.ndarray, fractions: np.ndarray) -> np.ndarray:
    """Poses (n, 4, 4) the `fractions` (n,) of the way from Ta to Tb: linear in position,
    slerp in rotation. All at once: scipy's rotations cost most in their making (one pose
    at a time, 0.8 ms a waypoint, most of a straight line's time)."""
    rots = Rotation.from_matrix(np.stack([Ta[:3, :3], Tb[:3, :3]]))
    T = np.tile(np.eye(4), (len(fractions), 1, 1))
    T[:, :3, :3] = Slerp([0.0, 1.0], rots)(fractions).as_matrix()
    f = fractions[:, None]
    T[:, :3, 3] = (1 - f) * Ta[:3, 3] + f * Tb[:3, 3]
    return T


def cartesian_line(
    q_start: np.ndarray, T_goal: np.ndarray, step: float = 0.01
) -> np.ndarray | None:
    """Joint waypoints (K, 6) moving the TCP in a straight line from where q_start (6,) puts
    it to T_goal, every `step` m and every `TURN_STEP` of its turn; None where IK fails or
    jumps branches on the way."""
    T_start = tcp_pose(q_start)
    dist = float(np.linalg.norm(T_goal[:3, 3] - T_start[:3, 3]))
    turn = rotation_angle(T_start[:3, :3], T_goal[:3, :3])
    n = max(2, math.ceil(dist / step) + 1, math.ceil(turn / TURN_STEP) + 1)
    path = [np.asarray(q_start, float)]
    for T in _line_poses(T_start, T_goal, np.linspace(0.0, 1.0, n)[1:]):
        sols = ik_tcp(T, path[-1])
        if len(sols) == 0 or np.max(np.abs(sols[0] - path[-1])) > CARTESIAN_JUMP:
            return None
        path.append(sols[0])
    return np.array(path)
