"""Where the pads close and whether they hold: each candidate's closing region, GPD's
antipodal test with its cheap upper bound, and whether the pads meet the object about their
middle. Frames: a hand frame's (h, c, a) axes, metres.
"""

from __future__ import annotations

import math

import numpy as np

from laserpick.description.dims import HandGeometry
from laserpick.pipeline.gpd.closing_grid import ClosingGrid
from laserpick.pipeline.gpd.neighbourhoods import ROUNDING, slab_pairs
from laserpick.settings import GraspSettings

PAIR_BLOCK = 8192  #: (sample, point) pairs per block of (orientations, pairs) arrays


def pad_pairs(
    target: np.ndarray,
    normals: np.ndarray,
    samples: np.ndarray,
    normal: np.ndarray,
    axis: np.ndarray,
    hand: HandGeometry,
) -> tuple[np.ndarray, ...]:
    """Target points where some candidate's pads could be, for each sample: (sample index,
    point index, h, u, v, nu, nv), the points' coordinates (m) and their normals' components
    along the same axes (see slab_pairs). The pads' hand-axis extent, out to the farthest pad
    corner."""
    reach = math.hypot(hand.width_max, hand.finger_length)
    region = [(hand.pad_width / 2, reach, np.inf)]
    return slab_pairs(target, samples, normal, axis, region, normals)


def antipodal_possible(
    u: np.ndarray,
    v: np.ndarray,
    nu: np.ndarray,
    nv: np.ndarray,
    sid: np.ndarray,
    n_samples: int,
    angles: np.ndarray,
    grid: ClosingGrid,
    hand: HandGeometry,
    s: GraspSettings,
) -> np.ndarray:
    """(S, O) bool: whether each frame could pass closing_region's antipodal test with any
    finger placement and fingertip depth, so that only these frames need the collision test.

    Inputs as for closing_region (from pad_pairs; `sid` the pairs' samples). Any
    candidate's pads lie in the union over placements and depths: closing coordinate within
    width_max / 2 of the farthest placement, depth from gpd_init_bite - pad_depth (the
    shallowest free tips) to finger_length (the sample itself stops the palm there, and the
    tips stay gpd_clearance short of that). Counting each pad's possible contacts there bounds
    closing_region's counts from above, so a frame that fails here fails there for any tips.
    """
    n_o = len(angles)
    c_max = hand.width_max / 2 + float(np.max(np.abs(grid.offsets))) + ROUNDING
    a_lo, a_hi = s.gpd_init_bite - hand.pad_depth - ROUNDING, hand.finger_length
    cos_fric = math.cos(math.radians(s.gpd_friction_deg))
    ct = np.cos(angles).astype(np.float32)
    st = np.sin(angles).astype(np.float32)
    left, right = np.zeros(n_samples * n_o, np.int64), np.zeros(n_samples * n_o, np.int64)
    for lo in range(0, len(u), PAIR_BLOCK):
        sl = slice(lo, lo + PAIR_BLOCK)
        # (O, m) with the long axis inner. Normals first: being within the friction cone of
        # the closing axis is the rare part.
        ndot = st[:, None] * nu[sl] - ct[:, None] * nv[sl]  # as in closing_region
        i = np.flatnonzero(np.abs(ndot) >= cos_fric)
        o, col = np.divmod(i, len(ndot[0]))
        uu, vv, c_o, s_o = u[sl].take(col), v[sl].take(col), ct.take(o), st.take(o)
        a = c_o * uu + s_o * vv
        inside = np.flatnonzero((a >= a_lo) & (a <= a_hi) & (np.abs(s_o * uu - c_o * vv) < c_max))
        f = sid[sl].take(col.take(inside)) * n_o + o.take(inside)
        toward = ndot.ravel().take(i.take(inside)) > 0  # toward the left pad (+closing)
        left += np.bincount(f[toward], minlength=len(left))
        right += np.bincount(f[~toward], minlength=len(right))
    return ((left >= s.gpd_min_contacts) & (right >= s.gpd_min_contacts)).reshape(n_samples, n_o)


Contacts = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]
"""Antipodal contacts: each one's frame, pad (0 left, 1 right), depth along the approach (m)
and whether its point is guessed."""


def closing_region(
    h: np.ndarray,
    u: np.ndarray,
    v: np.ndarray,
    nu: np.ndarray,
    nv: np.ndarray,
    frame: np.ndarray,
    angles: np.ndarray,
    offset: np.ndarray,
    tip: np.ndarray,
    hand: HandGeometry,
    s: GraspSettings,
    guessed: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Width (m), the antipodal verdict and whether the pads meet the object about their
    middle, for each candidate frame.

    h, u, v: target points' coordinates (see slab_pairs) for pairs already inside the
    pads' hand-axis extent; nu, nv: their normals' u and v components; frame: each pair's
    sample index times O (the orientation is added here). offset, tip: per frame (S * O), the
    chosen hand centre on the closing axis and fingertip depth (m); NaN for no candidate.
    guessed: per pair, whether the point is guessed (`mirrored_back`) rather than seen.

    The pads touch the points between their inner faces within pad_depth of the tips. Their
    closing extent is the width. A pad's contacts are the points within gpd_contact_band of
    the extreme on its side; enough of them (gpd_min_contacts) must have normals within the
    friction cone about the closing axis, pointing at that pad (GPD's antipodal rule). A pad
    that touches only guessed points must touch them where the other pad touches seen ones
    (`guesses_face_seen`).

    Ours, beyond GPD: whether each pad meets the object along its face, about its middle
    (`Grasp.pads_centred`). A pad's tangent patch is its contacts whose normals lie within
    gpd_tangent_deg of the closing axis: where the object's face lies along the pad. Each
    pad must have one, and the middle of its extent along the hand axis must lie within
    gpd_patch_offset of the pad's. The friction cone alone passes pads that meet a can's
    side only past their edges, where a pad's corner turns the contact normal and spins the
    can out. A verdict, not a rule: such a grasp is often the only one an object offers.
    """
    n_frames = len(offset)
    parts, cmax, cmin, count = _pad_contents(h, u, v, nu, nv, frame, angles, offset, tip, hand)
    left, right, patch_lo, patch_hi, contacts = _pad_contacts(
        parts, cmax, cmin, n_frames, s, guessed
    )
    width = cmax - cmin
    ok = (
        (count >= s.gpd_min_points)
        & (left >= s.gpd_min_contacts)
        & (right >= s.gpd_min_contacts)
        & (width > 0)
        & (width <= hand.width_max)
    )
    if guessed is not None:
        ok &= guesses_face_seen(contacts, n_frames)
    centred = (patch_lo <= patch_hi).all(axis=0) & (
        np.abs(patch_lo + patch_hi) / 2 <= s.gpd_patch_offset
    ).all(axis=0)
    return width, ok, centred


PadPoints = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]
"""The target points between one orientation's pads: each one's pair index, frame, closing
coordinate from the hand centre (m), normal . closing axis, depth along the approach (m) and
hand-axis coordinate (m)."""


def _pad_contents(
    h: np.ndarray,
    u: np.ndarray,
    v: np.ndarray,
    nu: np.ndarray,
    nv: np.ndarray,
    frame: np.ndarray,
    angles: np.ndarray,
    offset: np.ndarray,
    tip: np.ndarray,
    hand: HandGeometry,
) -> tuple[list[PadPoints], np.ndarray, np.ndarray, np.ndarray]:
    """closing_region's points between the pads, per orientation (`PadPoints`), and per
    frame their largest and least closing coordinates (m) and their count."""
    n_frames = len(offset)
    cmax = np.full(n_frames, -np.inf, np.float32)
    cmin = np.full(n_frames, np.inf, np.float32)
    count = np.zeros(n_frames, np.int64)
    half = hand.width_max / 2
    parts = []
    for o, theta in enumerate(angles):
        ct, st = math.cos(theta), math.sin(theta)
        f = frame + o
        # Depth first: it is NaN-safe (no candidate: never inside) and drops most pairs.
        a = ct * u + st * v
        t = tip[f]
        i = np.flatnonzero((a <= t) & (a >= t - hand.pad_depth))
        f = f[i]
        cc = st * u[i] - ct * v[i] - offset[f]
        inside = np.abs(cc) < half
        i, f, cc = i[inside], f[inside], cc[inside]
        ndot = st * nu[i] - ct * nv[i]  # normal . closing axis
        np.maximum.at(cmax, f, cc)
        np.minimum.at(cmin, f, cc)
        count += np.bincount(f, minlength=n_frames)
        parts.append((i, f, cc, ndot, a[i], h[i]))
    return parts, cmax, cmin, count


def _pad_contacts(
    parts: list[PadPoints],
    cmax: np.ndarray,
    cmin: np.ndarray,
    n_frames: int,
    s: GraspSettings,
    guessed: np.ndarray | None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, list[Contacts]]:
    """closing_region's contacts: per frame, the antipodal contacts on the left and right
    pads (counts), each pad's tangent patch along the hand axis ([pad, frame] least and
    largest, m; empty where lo > hi) and, with `guessed`, the antipodal contacts."""
    cos_fric = math.cos(math.radians(s.gpd_friction_deg))
    left = np.zeros(n_frames, np.int64)
    right = np.zeros(n_frames, np.int64)
    band = s.gpd_contact_band
    contacts: list[Contacts] = []
    cos_tangent = math.cos(math.radians(s.gpd_tangent_deg))
    # Each pad's tangent patch along the hand axis, [pad, frame]; 1 m is past any coordinate.
    patch_lo = np.full((2, n_frames), 1.0, np.float32)
    patch_hi = np.full((2, n_frames), -1.0, np.float32)
    for i, f, cc, ndot, depth, hh in parts:
        at_left, at_right = cc >= cmax[f] - band, cc <= cmin[f] + band
        on_left = at_left & (ndot >= cos_fric)
        on_right = at_right & (ndot <= -cos_fric)
        left += np.bincount(f[on_left], minlength=n_frames)
        right += np.bincount(f[on_right], minlength=n_frames)
        for pad, on in enumerate(
            (at_left & (ndot >= cos_tangent), at_right & (ndot <= -cos_tangent))
        ):
            np.minimum.at(patch_lo[pad], f[on], hh[on])
            np.maximum.at(patch_hi[pad], f[on], hh[on])
        if guessed is not None:
            at = np.flatnonzero(on_left | on_right)
            side = (~on_left).take(at).astype(np.int64)  # 0 left, 1 right
            contacts.append((f.take(at), side, depth.take(at), guessed.take(i.take(at))))
    return left, right, patch_lo, patch_hi, contacts


def guesses_face_seen(contacts: list[Contacts], n_frames: int) -> np.ndarray:
    """(n_frames,) bool: False where a pad's antipodal contacts are all guessed points and
    their depths along the approach do not overlap those of the other pad's seen contacts.

    The back `mirrored_back` guesses is right for a symmetric object seen square on. Seen at
    a slant, or past an end, it lies beside the seen face rather than opposite it, and pads
    on the one and the other close on a sliver of the object, which turns out of them. A pad
    on seen points, and a guessed one at the same depth, are at least a real surface faced
    by its likely back.
    """
    lo = np.full((2, 2, n_frames), np.inf, np.float32)  # [pad, guessed, frame]
    hi = np.full((2, 2, n_frames), -np.inf, np.float32)
    for f, side, depth, g in contacts:
        at = (side, g.astype(np.int64), f)
        np.minimum.at(lo, at, depth)
        np.maximum.at(hi, at, depth)
    ok = np.ones(n_frames, bool)
    for pad, other in ((0, 1), (1, 0)):
        only_guessed = ~np.isfinite(lo[pad, 0])
        overlap = np.maximum(lo[pad, 1], lo[other, 0]) <= np.minimum(hi[pad, 1], hi[other, 0])
        ok &= ~only_guessed | overlap
    return ok
