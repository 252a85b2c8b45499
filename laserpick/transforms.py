"""Small rigid-transform helpers shared by robot/ and pipeline/ (pure numpy).

Quaternions are (w, x, y, z), MuJoCo's order. Homogeneous transforms are 4x4 float64.
"""

from __future__ import annotations

import math

import numpy as np


def rotx(a: float) -> np.ndarray:
    """Rotation by `a` radians about x."""
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def roty(a: float) -> np.ndarray:
    """Rotation by `a` radians about y."""
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rotz(a: float) -> np.ndarray:
    """Rotation by `a` radians about z."""
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def make_transform(R: np.ndarray | None = None, p: np.ndarray | None = None) -> np.ndarray:
    """A 4x4 transform from a rotation matrix and a translation (identity where omitted)."""
    T = np.eye(4)
    if R is not None:
        T[:3, :3] = R
    if p is not None:
        T[:3, 3] = p
    return T


def invert(T: np.ndarray) -> np.ndarray:
    """Inverse of a rigid 4x4 transform."""
    Ti = np.eye(4)
    R = T[:3, :3]
    Ti[:3, :3] = R.T
    Ti[:3, 3] = -R.T @ T[:3, 3]
    return Ti


def quat_from_matrix(R: np.ndarray) -> np.ndarray:
    """Unit quaternion (w, x, y, z) with w >= 0 for a 3x3 rotation matrix."""
    m = np.asarray(R, dtype=float)
    t = np.trace(m)
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        q = [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        q = [(m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s]
    elif m[1, 1] > m[2, 2]:
        s = math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        q = [(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s]
    else:
        s = math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        q = [(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s]
    qa = np.array(q)
    qa /= np.linalg.norm(qa)
    return qa if qa[0] >= 0 else -qa


def matrix_from_quat(q: np.ndarray) -> np.ndarray:
    """3x3 rotation matrix of a quaternion (w, x, y, z); need not be normalised."""
    w, x, y, z = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def planar_pose(x: float, y: float, yaw: float) -> np.ndarray:
    """4x4 transform of a pose on the floor: position (x, y, 0) and heading `yaw` about z."""
    return make_transform(rotz(yaw), np.array([x, y, 0.0]))


def rotation_angle(Ra: np.ndarray, Rb: np.ndarray) -> float:
    """Angle (rad) of the rotation taking Ra to Rb."""
    c = (np.trace(Ra.T @ Rb) - 1.0) / 2.0
    return float(math.acos(max(-1.0, min(1.0, c))))


def rotation_angles(R0: np.ndarray, R1: np.ndarray) -> np.ndarray:
    """Angles (rad) of the rotations taking R0 to R1 (..., 3, 3), by arctan2: exact near
    no turn and half a turn alike."""
    M = np.swapaxes(R0, -1, -2) @ R1
    skew = M - np.swapaxes(M, -1, -2)
    sin2 = np.linalg.norm(skew[..., [2, 0, 1], [1, 2, 0]], axis=-1)  # 2 sin(angle)
    cos2 = np.trace(M, axis1=-2, axis2=-1) - 1.0  # 2 cos(angle)
    return np.arctan2(sin2, cos2)


def turn_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The rotation (3, 3) taking unit vector `a` onto unit vector `b` the shortest way
    (Rodrigues); half a turn about an axis across `a` where they point opposite ways."""
    axis = np.cross(a, b)
    s, c = float(np.linalg.norm(axis)), float(a @ b)
    if s < 1e-12:
        if c > 0:
            return np.eye(3)
        e = np.eye(3)[int(np.argmin(np.abs(a)))]
        k = e - (e @ a) * a
        k /= np.linalg.norm(k)
        return 2.0 * np.outer(k, k) - np.eye(3)
    k = axis / s
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + s * K + (1.0 - c) * (K @ K)


def pinhole_intrinsics(width: int, height: int, fovy: float) -> np.ndarray:
    """K (3x3, px) of a MuJoCo-style camera with vertical field of view `fovy` (rad).

    OpenCV pixel convention (pixel centres at integers, x right, y down). MuJoCo's optical
    axis passes between the middle pixels, so the principal point is ((W-1)/2, (H-1)/2).
    """
    f = (height / 2.0) / math.tan(fovy / 2.0)
    return np.array([[f, 0.0, (width - 1) / 2.0], [0.0, f, (height - 1) / 2.0], [0.0, 0.0, 1.0]])


def pinhole_project(
    points: np.ndarray, K: np.ndarray, T_world_cam: np.ndarray, near: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pixel coordinates (N, 2) (u, v), depths along the optical axis (N,) (m) and a mask of
    the points in front of the lens (depth > `near`, m) of `points` (N, 3) in the frame
    `T_world_cam` (4x4, OpenCV optical frame: x right, y down, z forward) is given in. The
    pixel coordinates of the points not in front are meaningless. Stacked cameras, K
    (F, 3, 3) and T_world_cam (F, 4, 4), give each of these for each: (F, N, 2), (F, N)."""
    P = np.asarray(points, dtype=float).reshape(-1, 3)
    R, t = T_world_cam[..., :3, :3], T_world_cam[..., None, :3, 3]
    q = (P - t) @ R  # R^T (p - t) per row: the points in the optical frame
    front = q[..., 2] > near
    z = np.where(front, q[..., 2], 1.0)
    K = K[..., None, :, :]  # one camera's intrinsics for all its points
    u = K[..., 0, 0] * q[..., 0] / z + K[..., 0, 2]
    v = K[..., 1, 1] * q[..., 1] / z + K[..., 1, 2]
    uv = np.stack([u, v], axis=-1)
    return uv, q[..., 2], front
