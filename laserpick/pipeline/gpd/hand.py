"""The hand GPD tests, as boxes (`HandGeometry`): grown by the side clearance, the regions
around a sample it can reach, and the TCP poses of its candidates. Frames: `base` (m); a hand
frame has the hand axis (x), the closing axis (y) and the approach (z).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from laserpick.description.dims import HandGeometry
from laserpick.settings import GraspSettings


def cleared_hand(hand: HandGeometry, side_clearance: float) -> HandGeometry:
    """The hand the detector tests: `hand` grown by `side_clearance` (m) on every side but
    the fingertips and the palm's front (gpd_clearance keeps those off the first contact).
    Its fingers' inner faces close in by the clearance, so a grasp's width is at most the
    stroke less twice the clearance; its outer faces, the fingers' edges along the hand axis
    and the palm's sides move out by it. The pads (the contacts) keep their size."""
    m = side_clearance
    if m == 0:
        return hand
    return replace(
        hand,
        width_max=hand.width_max - 2 * m,
        finger_thickness=hand.finger_thickness + 2 * m,
        finger_width=max(hand.finger_width, hand.pad_width) + 2 * m,
        palm_width=hand.palm_width + 2 * m,
        palm_depth=hand.palm_depth + 2 * m,
    )


def hand_regions(hand: HandGeometry, s: GraspSettings) -> list[tuple[float, float, float]]:
    """Where scene points can touch a candidate hand, around its sample, as slab_pairs
    regions (half slab along the hand axis, radius in the rotation plane, largest u), m.

    Fingers: closing up to the outer face at the edge placement, approach from the roots of
    the starting hand to the deepest tips (finger_length: the sample itself stops the palm
    there). Palm: closing up to its side at the edge placement, approach back to its rear at
    the start; it stays on the sample's outer side (u below its half-width plus offset).
    """
    grid_half = hand.width_max / 2 - hand.width_max / s.gpd_finger_placements / 2  # largest |c_k|
    c_finger = grid_half + hand.width_max / 2 + hand.pad_thickness + hand.finger_thickness
    a_finger = max(hand.finger_length, hand.finger_length - s.gpd_init_bite)
    c_palm = grid_half + hand.palm_width / 2
    a_palm = hand.finger_length + hand.palm_length - s.gpd_init_bite
    finger_slab = max(hand.finger_width, hand.pad_width) / 2
    return [
        (finger_slab, math.hypot(c_finger, a_finger), np.inf),
        (hand.palm_depth / 2, math.hypot(c_palm, a_palm), c_palm),
    ]


def grasp_poses(
    samples: np.ndarray,
    normal: np.ndarray,
    axis: np.ndarray,
    angles: np.ndarray,
    frames: np.ndarray,
    offset: np.ndarray,
    tip: np.ndarray,
    hand: HandGeometry,
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
        + (tip[:, None].astype(np.float64) - hand.pad_depth / 2) * approach
    )
    return poses
