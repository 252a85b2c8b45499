"""EL-E's overhead grasp (paper 000, sections 4.4.1-4.4.3), for our parallel gripper.

The target's points are projected onto a 1 cm 2D occupancy grid, as seen by a virtual
camera looking straight down. If the object's extent across its axis of least variance fits
between the fingers, the grasp is at the 2D centroid with the fingers closing across the axis
of most variance. Otherwise it is at a raised point near the robot: the point nearest the arm
among those within 5 mm of the object's highest point, with the fingers closing along the
line from the centroid to that point. Before any of it is used, the volume the hand sweeps
on its way down must be free of other points.

Frames: `base` (x forward, y left, z up). The grasp pose's columns are the hand axis, the
closing axis and the approach axis (straight down).
"""

from __future__ import annotations

import numpy as np

from laserpick.description.dims import GRIPPER_HAND
from laserpick.types import Failure, Grasp

GRID_CELL = 0.01  #: m, EL-E's 2D occupancy grid resolution (000 section 4.4.1)
RAISED_BAND = 0.005  #: m, "less than 5 mm below the point of maximum height" (000 4.4.2)
GRASP_DEPTH = 0.02  #: m the pads reach below the top of the object (our choice)
FLOOR_GAP = 0.003  #: m the fingertips stay above the support surface
#: m above the support's fitted height within which its own points lie: depth noise at the
#: scooter's 1-2 m ranges scatters them by several mm, and they are not obstacles. Ours.
SUPPORT_BAND = 0.01


def occupancy_pca(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Centroid (2,), unit axes of most and least variance (2,) of the occupied 1 cm cells."""
    cells = np.unique(np.floor(points[:, :2] / GRID_CELL).astype(np.int64), axis=0)
    centres = (cells + 0.5) * GRID_CELL
    centroid = centres.mean(axis=0)
    cov = np.cov((centres - centroid).T) if len(centres) > 1 else np.eye(2) * 1e-6
    _, v = np.linalg.eigh(cov)
    return centroid, v[:, 1], v[:, 0]


def _extent(points_xy: np.ndarray, axis: np.ndarray) -> float:
    d = points_xy @ axis
    return float(d.max() - d.min()) + GRID_CELL  # cells have width


def _pose(position: np.ndarray, closing_xy: np.ndarray) -> np.ndarray:
    closing = np.array([closing_xy[0], closing_xy[1], 0.0])
    closing /= np.linalg.norm(closing)
    approach = np.array([0.0, 0.0, -1.0])
    T = np.eye(4)
    T[:3, :3] = np.column_stack([np.cross(closing, approach), closing, approach])
    T[:3, 3] = position
    return T


def overhead_grasp(
    target: np.ndarray,
    scene: np.ndarray,
    surface_height: float,
    arm_xy: np.ndarray,
) -> Grasp | Failure:
    """A top-down grasp of `target` (M, 3), checked against the `scene` cloud (N, 3).

    surface_height: z (m) of the support surface. arm_xy: the arm's base in `base` (m), for
    "the point nearest the robot". The scene cloud may include the target's own points.
    """
    if len(target) < 3:
        return Failure("detect_grasp", "I see too little of the object for an overhead grasp.")
    centroid, _, minor = occupancy_pca(target)
    top = float(target[:, 2].max())
    across = _extent(target[:, :2], minor)
    if across <= GRIPPER_HAND.width_max - 2 * GRID_CELL:
        closing = minor
        xy = centroid
        width = across
    else:
        raised = target[target[:, 2] >= top - RAISED_BAND]
        nearest = raised[np.argmin(np.linalg.norm(raised[:, :2] - arm_xy, axis=1))]
        xy = nearest[:2]
        closing = xy - centroid
        if np.linalg.norm(closing) < 1e-6:
            closing = minor
        width = min(
            GRIPPER_HAND.width_max, _extent(target[:, :2], closing / np.linalg.norm(closing))
        )
    # The TCP is pad_depth / 2 above the fingertips, which stop FLOOR_GAP above the support.
    z = max(surface_height + FLOOR_GAP + GRIPPER_HAND.pad_depth / 2, top - GRASP_DEPTH)
    pose = _pose(np.array([xy[0], xy[1], z]), closing)
    # The support itself is below the fingertips: its points (and their noise) do not block.
    above = scene[scene[:, 2] > surface_height + SUPPORT_BAND]
    blocked = sweep_collisions(pose, above, target)
    if blocked:
        return Failure(
            "detect_grasp", f"An overhead grasp would hit {blocked} points on the way down."
        )
    return Grasp(pose=pose, width=min(width, GRIPPER_HAND.width_max))


def sweep_collisions(pose: np.ndarray, scene: np.ndarray, target: np.ndarray) -> int:
    """How many non-target scene points lie in the volume the fingers sweep coming straight
    down onto `pose` (000 section 4.4.3): two finger slabs just outside the opening, from
    the grasp height up to 0.3 m above it."""
    R, p = pose[:3, :3], pose[:3, 3]
    local = (scene - p) @ R  # hand axis, closing axis, approach (down) components
    half_open = GRIPPER_HAND.width_max / 2
    finger = 0.012  #: m, finger thickness across the closing axis plus margin
    in_slab = (np.abs(local[:, 1]) > half_open - 0.002) & (np.abs(local[:, 1]) < half_open + finger)
    in_band = np.abs(local[:, 0]) < 0.015  # the pads' width along the hand axis, with margin
    in_height = (local[:, 2] < 0.011) & (local[:, 2] > -0.3)  # fingertips up to 30 cm above
    hits = in_slab & in_band & in_height
    if not hits.any():
        return 0
    # Points of the target itself do not block: the fingers close onto them.
    hit_pts = scene[hits]
    if len(target):
        d = np.min(np.linalg.norm(hit_pts[:, None, :] - target[None, ::4, :], axis=2), axis=1)
        hit_pts = hit_pts[d > 0.005]
    return len(hit_pts)
