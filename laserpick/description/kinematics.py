"""UR5 kinematics: DH forward kinematics and analytic inverse kinematics, all solutions.

Frames: `ur5` is the DH base frame 0 of the arm; `base` is the scooter frame. The arm's mount
(`dims.ARM_MOUNT_POS`, `dims.ARM_MOUNT_YAW`) relates them. The TCP sits
`dims.GRIPPER_TCP_OFFSET` along the flange's z axis (the approach axis).

The closed-form IK comes from `ur-analytic-ik` (C++, eight solutions per pose). We wrap it to
work in `base`, at the TCP, and to respect our joint limits.
"""

from __future__ import annotations

import math

import numpy as np
import ur_analytic_ik

from laserpick.description import dims
from laserpick.transforms import invert, make_transform, rotz

T_BASE_UR5 = make_transform(rotz(dims.ARM_MOUNT_YAW), dims.ARM_MOUNT_POS)
T_UR5_BASE = invert(T_BASE_UR5)
T_FLANGE_TCP = make_transform(p=np.array([0.0, 0.0, dims.GRIPPER_TCP_OFFSET]))
T_TCP_FLANGE = invert(T_FLANGE_TCP)

_D = np.asarray(dims.UR5_D)
_A = np.asarray(dims.UR5_A)
_ALPHA = np.asarray(dims.UR5_ALPHA)


def dh_fk(q: np.ndarray) -> np.ndarray:
    """Flange pose in `ur5` for joint angles q, batched: q (..., 6) -> (..., 4, 4)."""
    q = np.asarray(q, dtype=float)
    batch = q.shape[:-1]
    T = np.broadcast_to(np.eye(4), (*batch, 4, 4)).copy()
    for i in range(6):
        ct, st = np.cos(q[..., i]), np.sin(q[..., i])
        ca, sa = math.cos(_ALPHA[i]), math.sin(_ALPHA[i])
        A = np.zeros((*batch, 4, 4))
        A[..., 0, 0], A[..., 0, 1], A[..., 0, 2], A[..., 0, 3] = ct, -st * ca, st * sa, _A[i] * ct
        A[..., 1, 0], A[..., 1, 1], A[..., 1, 2], A[..., 1, 3] = st, ct * ca, -ct * sa, _A[i] * st
        A[..., 2, 1], A[..., 2, 2], A[..., 2, 3] = sa, ca, _D[i]
        A[..., 3, 3] = 1.0
        T = T @ A
    return T


def tcp_pose(q: np.ndarray) -> np.ndarray:
    """TCP pose in `base` for joint angles q (..., 6) -> (..., 4, 4)."""
    return T_BASE_UR5 @ dh_fk(q) @ T_FLANGE_TCP


def wrap(q: np.ndarray) -> np.ndarray:
    """Angles (rad) wrapped to [-pi, pi)."""
    return (q + np.pi) % (2 * np.pi) - np.pi


def nearest_turns(q: np.ndarray, q_ref: np.ndarray) -> np.ndarray:
    """The posture of joint angles q (6,) rad with its wrist joints turned by whole turns
    so that the hand turns least on a straight joint move from q_ref (6,) rad, within the
    joint limits. The last two wrists each take the angle nearest q_ref's. The first
    wrist's axis is parallel to the shoulder's and the elbow's, and the three angles' sum
    pitches the hand: it takes the angle that brings that sum nearest q_ref's, or a
    "shorter" first wrist turns the hand over (from a grasp on the floor to a posture over
    the basket, a straight move of 12.6 s against 7.8 s). Shoulder and elbow keep their
    angles, which keep the arm on the side of the scooter it works on; angles that need no
    turn come back exactly."""
    out = np.array(q, dtype=float)
    ref = np.asarray(q_ref, dtype=float)
    gap = ref - out
    gap[3] = ref[1:4].sum() - out[1:4].sum()
    near = out + 2 * math.pi * np.round(gap / (2 * math.pi))
    within = (near >= dims.UR5_Q_MIN - 1e-9) & (near <= dims.UR5_Q_MAX + 1e-9)
    out[3:] = np.where(within, near, out)[3:]
    return out


def ik_flange(T_ur5_flange: np.ndarray) -> np.ndarray:
    """All analytic solutions (k, 6) for a flange pose in `ur5`, angles wrapped to [-pi, pi).

    Returns an empty (0, 6) array when the pose is out of reach.
    """
    sols = ur_analytic_ik.ur5.inverse_kinematics(np.ascontiguousarray(T_ur5_flange, dtype=float))
    if not sols:
        return np.zeros((0, 6))
    Q = wrap(np.array(sols, dtype=float))
    Q = Q[np.all(np.isfinite(Q), axis=1)]
    # Drop duplicates that the closed form returns at singular poses (keep the first).
    if len(Q) > 1:
        same = np.max(np.abs(Q[:, None] - Q[None]), axis=2) < 1e-9
        Q = Q[~np.triu(same, k=1).any(axis=0)]
    return Q


def ik_tcp(T_base_tcp: np.ndarray, q_ref: np.ndarray | None = None) -> np.ndarray:
    """All IK solutions (k, 6) that put the TCP at a pose in `base`, within joint limits.

    With `q_ref`, each solution takes the 2*pi-equivalent angle nearest q_ref (the UR5's
    +-2*pi joints allow two), and solutions are sorted by distance from q_ref.
    """
    Q = ik_flange(T_UR5_BASE @ T_base_tcp @ T_TCP_FLANGE)
    if len(Q) == 0:
        return Q
    if q_ref is not None:
        q_ref = np.asarray(q_ref, dtype=float)
        Q = q_ref + wrap(Q - q_ref)
        Q = Q[np.argsort(np.linalg.norm(Q - q_ref, axis=1))]
    ok = np.all((Q >= dims.UR5_Q_MIN - 1e-9) & (Q <= dims.UR5_Q_MAX + 1e-9), axis=1)
    return Q[ok]
