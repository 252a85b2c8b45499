"""Oriented rectangles in the plane (centre, half extents, angle): the overlap test that keeps
surfaces and objects apart."""

from __future__ import annotations

import math

import numpy as np

#: An oriented rectangle: centre (x, y), half extents along its own axes (m), angle (rad).
Rect = tuple[np.ndarray, np.ndarray, float]


def _corners(center: np.ndarray, half: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    axes = np.array([[c, s], [-s, c]])
    signs = np.array([[1, 1], [1, -1], [-1, -1], [-1, 1]])
    return center + (signs * half) @ axes


def rects_overlap(a: Rect, b: Rect, tol: float = 1e-4) -> bool:
    """Separating-axis test of two oriented rectangles (centre, half extents, angle)."""
    ca, cb = _corners(*a), _corners(*b)
    for ang in (a[2], b[2]):
        for axis in (
            np.array([math.cos(ang), math.sin(ang)]),
            np.array([-math.sin(ang), math.cos(ang)]),
        ):
            pa, pb = ca @ axis, cb @ axis
            if pa.max() <= pb.min() + tol or pb.max() <= pa.min() + tol:
                return False
    return True
