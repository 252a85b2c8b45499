"""The hand GPD tests, as boxes: grown by the side clearance, the regions around a sample
it can reach, and the TCP poses of its candidates. Frames: `base` (m); a hand frame has the
hand axis (x), the closing axis (y) and the approach (z).
"""

from __future__ import annotations

import math

import numpy as np

from laserpick.settings import GraspSettings


def cleared_hand(s: GraspSettings) -> GraspSettings:
    """The hand the detector tests: `s`'s grown by side_clearance on every side but the
    fingertips and the palm's front (gpd_clearance keeps those off the first contact). Its
    fingers' inner faces close in by the clearance, so a grasp's width is at most the stroke
    less twice the clearance; its outer faces, the fingers' edges along the hand axis and
    the palm's sides move out by it. The pads (the contacts) keep their size."""
    m = s.side_clearance
    if m == 0:
        return s
    return s.model_copy(
        update={
            "width_max": s.width_max - 2 * m,
            "finger_thickness": s.finger_thickness + 2 * m,
            "finger_width": max(s.finger_width, s.pad_width) + 2 * m,
            "palm_width": s.palm_width + 2 * m,
            "palm_depth": s.palm_depth + 2 * m,
        }
    )


def hand_regions(s: GraspSettings) -> list[tuple[float, float, float]]:
    """Where scene points can touch a candidate hand, around its sample, as slab_pairs
    regions (half slab along the hand axis, radius in the rotation plane, largest u), m.

    Fingers: closing up to the outer face at the edge placement, approach from the roots of
    the starting hand to the deepest tips (finger_length: the sample itself stops the palm
    there). Palm: closing up to its side at the edge placement, approach back to its rear at
    the start; it stays on the sample's outer side (u below its half-width plus offset).
    """
    grid_half = s.width_max / 2 - s.width_max / s.gpd_finger_placements / 2  # largest |c_k|
    c_finger = grid_half + s.width_max / 2 + s.pad_thickness + s.finger_thickness
    a_finger = max(s.finger_length, s.finger_length - s.gpd_init_bite)
    c_palm = grid_half + s.palm_width / 2
    a_palm = s.finger_length + s.palm_length - s.gpd_init_bite
    finger_slab = max(s.finger_width, s.pad_width) / 2
    return [
        (finger_slab, math.hypot(c_finger, a_finger), np.inf),
        (s.palm_depth / 2, math.hypot(c_palm, a_palm), c_palm),
    ]


def grasp_poses(
    samples: np.ndarray,
    normal: np.ndarray,
    axis: np.ndarray,
    angles: np.ndarray,
    frames: np.ndarray,
    offset: np.ndarray,
    tip: np.ndarray,
    s: GraspSettings,
) -> np.ndarray:
    """(G, 4, 4) TCP poses of candidate `frames` (sample * O + orientation), with the hand
    `offset` (m) along the closing axis and fingertips `tip` (m) along the approach from the
    sample; the TCP is pad_depth / 2 behind the tips, between the pads' centres."""
    i, o = np.divmod(frames, len(angles))
    theta = angles[o][:, None]
    x = axis[i]
    e1 = -normal[i]
    e2 = np.cross(x, e1)
    approach = np.cos(theta) * e1 + np.sin(theta) * e2
    closing = np.cross(approach, x)
    poses = np.tile(np.eye(4), (len(frames), 1, 1))
    poses[:, :3, 0], poses[:, :3, 1], poses[:, :3, 2] = x, closing, approach
    poses[:, :3, 3] = (
        samples[i]
        + offset[:, None].astype(np.float64) * closing
        + (tip[:, None].astype(np.float64) - s.pad_depth / 2) * approach
    )
    return poses
