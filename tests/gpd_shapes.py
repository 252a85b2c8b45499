"""Synthetic point clouds for the grasp detector's tests: shapes sampled on a 3 mm grid with
exact outward normals, a little noise, and a table of points at z = 0. Frames: `base`-like, z
up, metres."""

from __future__ import annotations

import numpy as np

SPACING = 0.003  #: m between object points


def table(half: float = 0.3, spacing: float = 0.004) -> np.ndarray:
    g = np.arange(-half, half, spacing)
    x, y = np.meshgrid(g, g)
    return np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])


def noisy(normals: np.ndarray, seed: int = 7, sigma: float = 0.03) -> np.ndarray:
    """Normals with a little noise, as a sensor's would have (unit length)."""
    n = normals + np.random.default_rng(seed).normal(0, sigma, normals.shape)
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def cylinder(
    r: float = 0.03, height: float = 0.12, centre: tuple[float, float] = (0.0, 0.0)
) -> tuple[np.ndarray, np.ndarray]:
    """A vertical cylinder's side and top (points, outward normals), standing on z = 0."""
    ang = np.linspace(0, 2 * np.pi, int(2 * np.pi * r / SPACING), endpoint=False)
    hh = (np.arange(int(height / SPACING)) + 0.5) * SPACING
    a, z = np.meshgrid(ang, hh)
    side = np.column_stack([r * np.cos(a).ravel(), r * np.sin(a).ravel(), z.ravel()])
    side_n = np.column_stack([np.cos(a).ravel(), np.sin(a).ravel(), np.zeros(a.size)])
    g = np.arange(-r, r, SPACING)
    x, y = np.meshgrid(g, g)
    m = x**2 + y**2 <= r * r
    top = np.column_stack([x[m], y[m], np.full(m.sum(), height)])
    pts = np.vstack([side, top])
    pts[:, :2] += centre
    return pts, np.vstack([side_n, np.tile([0.0, 0.0, 1.0], (len(top), 1))])


def plate(
    origin: np.ndarray, du: np.ndarray, dv: np.ndarray, normal: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """A rectangle origin + s du + t dv (s, t in [0, 1]) of points with one normal."""
    nu = max(1, int(np.linalg.norm(du) / SPACING))
    nv = max(1, int(np.linalg.norm(dv) / SPACING))
    s, t = np.meshgrid((np.arange(nu) + 0.5) / nu, (np.arange(nv) + 0.5) / nv)
    pts = origin + s.ravel()[:, None] * du + t.ravel()[:, None] * dv
    return pts, np.tile(normal, (len(pts), 1))


def box(
    size: tuple[float, float, float], centre: tuple[float, float] = (0.0, 0.0)
) -> tuple[np.ndarray, np.ndarray]:
    """An axis-aligned box's four sides and top (points, outward normals) on z = 0."""
    sx, sy, sz = size
    o = np.array([centre[0] - sx / 2, centre[1] - sy / 2, 0.0])
    X, Y, Z = np.eye(3)
    faces = [
        plate(o + sx * X, sy * Y, sz * Z, X),
        plate(o, sy * Y, sz * Z, -X),
        plate(o + sy * Y, sx * X, sz * Z, Y),
        plate(o, sx * X, sz * Z, -Y),
        plate(o + sz * Z, sx * X, sy * Y, Z),
    ]
    return np.vstack([f[0] for f in faces]), np.vstack([f[1] for f in faces])
