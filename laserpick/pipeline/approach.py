"""Jeeves' centroid approach (paper 003 section IV): drive the base until the target's
centroid sits at the arm's grasping spot, with a gain-scheduled bearing controller.

dX, dY: the target centroid minus the grasping spot, in `base` (m; x forward, y left).
D = sqrt(dX^2 + dY^2) and theta = atan2(dY, dX). The laws are v = Kv * D and w = Kw * theta,
where Kw is large beyond 20 cm, small between 20 and 7 cm, and zero inside 7 cm, because the
bearing of a point a few centimetres away is mostly noise (003 section IV). The paper gives the
distances but not the gains; ours are in `ApproachSettings`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from laserpick.settings import ApproachSettings, get_settings


@dataclass(frozen=True)
class DriveCommand:
    """Base velocity (m/s forward, rad/s left turn) and whether the approach is done."""

    v: float
    w: float
    done: bool


def bearing_gain(distance: float, s: ApproachSettings) -> float:
    """The scheduled Kw (1/s) at `distance` (m)."""
    if distance > s.far_distance:
        return s.kw_far
    if distance > s.near_distance:
        return s.kw_mid
    return 0.0


def centroid_approach(
    centroid_base: np.ndarray, settings: ApproachSettings | None = None
) -> DriveCommand:
    """One control step toward bringing `centroid_base` (m, in `base`) to the grasping spot."""
    s = settings or get_settings().approach
    dx = float(centroid_base[0]) - s.grasp_spot[0]
    dy = float(centroid_base[1]) - s.grasp_spot[1]
    distance = math.hypot(dx, dy)
    near = distance <= s.near_distance
    # Inside the near zone the bearing is not corrected (Kw = 0), so a sideways error there
    # stays: the approach ends once the target is no longer ahead or behind, and the arm
    # takes up the rest.
    if distance <= s.tolerance or (near and abs(dx) <= s.tolerance):
        return DriveCommand(0.0, 0.0, True)
    # A target behind the spot means backing up: drive along the line, sign by dX.
    theta = math.atan2(dy, dx) if dx >= 0 else math.atan2(-dy, -dx)
    v = math.copysign(min(s.kv * (abs(dx) if near else distance), s.v_max), dx)
    w = float(np.clip(bearing_gain(distance, s) * theta, -s.w_max, s.w_max))
    return DriveCommand(v, w, False)
