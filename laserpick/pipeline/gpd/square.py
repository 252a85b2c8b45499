"""The last pass: hands whose pads meet the object's faces at a slant about the approach,
turned square to them. Ours, beyond GPD. Frames: a hand frame's (h, c, a) axes, metres,
radians.

GPD's hand axis is the sample's curvature axis, which on a flat face is noise: a box's top
gives hands turned any way about the approach, and the antipodal test passes those whose
closing axis lies within the friction cone of the faces' normals. Such pads meet a box's
sides on two diagonal edges, and the box turns slowly about them. Held in the simulation
for a minute, a TV remote turned 0.6 degrees with the pads square to it, 4 with them 6
degrees off it and 7 with them 9 degrees off; a tissue packet 2.6, 8 and 8
(`bench/slanted_pads_hold.py`).
"""

from __future__ import annotations

import math

import numpy as np

from laserpick.description.dims import HandGeometry
from laserpick.pipeline.gpd.candidates import HandCandidates
from laserpick.pipeline.gpd.recentre import MIN_TURN, WideSlab
from laserpick.settings import GraspSettings


def square_turns(
    tgt: np.ndarray,
    normals: np.ndarray,
    hand: HandGeometry,
    s: GraspSettings,
    found: HandCandidates,
) -> np.ndarray:
    """(G,) rad: for each of `found`'s hands, the turn about its approach that brings its
    closing axis onto the normals where its pads meet the object, seen along the approach:
    the median over each pad's antipodal contacts (closing_region's, within its own pad
    width) of the angle from the closing axis toward the hand axis to their normals (to
    minus theirs, for the right pad), averaged over the pads. NaN where a pad has no such
    contact or the turn is below MIN_TURN."""
    turn = np.full(len(found), np.nan)
    if not s.gpd_square or not len(found):
        return turn
    slab = WideSlab(tgt, normals, hand, s, found, margin=0.0)
    left, right, n_c, _ = slab.extremes(found.angles[found.orientation])
    n_h = slab.along_hand_axis(normals)
    cos_fric = math.cos(math.radians(s.gpd_friction_deg))
    turn = (
        slab.medians(left & (n_c >= cos_fric), np.arctan2(n_h, n_c))
        + slab.medians(right & (n_c <= -cos_fric), np.arctan2(-n_h, -n_c))
    ) / 2
    turn[~(np.abs(turn) >= MIN_TURN)] = np.nan
    return turn


def turned_frames(
    found: HandCandidates, turn: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The frames (samples, normals, curvature axes; (G, 3) each, relative to the target's
    centre) of `found`'s hands turned by `turn` (G,) rad about their approach through their
    sample, so that each closing axis moves toward its hand axis by that angle; the
    orientation index stays each hand's own."""
    i = found.sample
    approach = found.poses[:, :3, 2]
    return (
        found.samples[i],
        _rotated(found.normal[i], approach, -turn),
        _rotated(found.axis[i], approach, -turn),
    )


def _rotated(v: np.ndarray, k: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Vectors `v` (G, 3) turned by `angle` (G,) rad about unit axes `k` (G, 3), right-handed
    (Rodrigues)."""
    c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
    along = np.einsum("gi,gi->g", k, v)[:, None] * k
    return c * v + s * np.cross(k, v) + (1 - c) * along
