"""GPD's samples and their local frames (ten Pas et al. 2017): which target points seed
candidates, the surface normal and curvature axis at each, and the hand rotations tried
about that axis. Frames: `base` axes (x forward, y left, z up), metres, radians.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from laserpick.settings import GraspSettings


def sample_indices(n_points: int, n_samples: int, rng: np.random.Generator) -> np.ndarray:
    """Indices of up to `n_samples` distinct target points, drawn uniformly (sorted)."""
    if n_points <= n_samples:
        return np.arange(n_points)
    return np.sort(rng.choice(n_points, size=n_samples, replace=False))


def local_frames(
    target: np.ndarray,
    normals: np.ndarray,
    idx: np.ndarray,
    s: GraspSettings,
    tree: cKDTree | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Surface normal and curvature axis (each (S, 3), unit) at the target points `idx`.

    The normal is the mean of the neighbours' normals within gpd_nn_radius (kept pointing the
    way they were given: outward, toward the sensors). The curvature axis is the direction of
    least normal variation: the eigenvector of sum(n n^T) with the smallest eigenvalue (GPD),
    made orthogonal to the normal. `tree`: a KD-tree of `target`, if one is at hand.
    """
    tree = tree if tree is not None else cKDTree(target)
    k = min(s.gpd_frame_neighbours, len(target))
    _, nb = tree.query(target[idx], k=k, distance_upper_bound=s.gpd_nn_radius)
    nb = np.asarray(nb).reshape(len(idx), k)
    padded = np.vstack([normals.astype(np.float64), np.zeros((1, 3))])  # index M: no neighbour
    n = padded[nb]  # (S, k, 3), zero rows for missing neighbours
    normal = n.sum(axis=1)
    own = normals[idx].astype(np.float64)
    weak = np.linalg.norm(normal, axis=1) < 1e-6  # opposing normals cancel: keep the sample's
    normal[weak] = own[weak]
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    _, vecs = np.linalg.eigh(np.einsum("ski,skj->sij", n, n))
    axis = vecs[:, :, 0]  # smallest eigenvalue first
    axis -= normal * np.sum(axis * normal, axis=1, keepdims=True)
    bad = np.linalg.norm(axis, axis=1) < 1e-3  # eigenvector along the normal: any tangent does
    if bad.any():
        alt = np.where(np.abs(normal[bad, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]])
        axis[bad] = np.cross(normal[bad], alt)
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    return normal, axis


def tilted_frames(
    normal: np.ndarray, axis: np.ndarray, tilts: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Each frame (normal, curvature axis; (S, 3) each) turned about its closing axis,
    normal x axis, by each of `tilts` (T,) rad: (T * S, 3) each, tilt-major. The hand's
    approach at rotation 0 then leans from -normal toward the curvature axis, as GPD 2 tries
    hand axes other than the curvature axis."""
    c, s = np.cos(tilts)[:, None, None], np.sin(tilts)[:, None, None]
    return (c * normal + s * axis).reshape(-1, 3), (c * axis - s * normal).reshape(-1, 3)


def orientation_angles(n: int) -> np.ndarray:
    """Hand rotations (rad) about the curvature axis, -90 deg to +90 deg inclusive.

    GPD drops +90 deg as a duplicate of -90 deg, but the two approach from opposite sides of
    the sample (from above and from below a side face), so both are kept.
    """
    return np.linspace(-np.pi / 2, np.pi / 2, n) if n > 1 else np.zeros(1)
