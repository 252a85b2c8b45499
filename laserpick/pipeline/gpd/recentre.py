"""The second pass: hands whose pads do not meet the object about their middle, turned about
their hand axis and shifted along it onto the patch where they would. Ours, beyond GPD.
Frames: a hand frame's (h, c, a) axes, metres, radians.
"""

from __future__ import annotations

import math

import numpy as np

from laserpick.description.dims import HandGeometry
from laserpick.pipeline.gpd.candidates import HandCandidates
from laserpick.pipeline.gpd.neighbourhoods import slab_pairs
from laserpick.settings import GraspSettings

MIN_SHIFT = 0.001  #: m; patch_moves shifts no hand by less: the pads would feel no change
MIN_TURN = math.radians(1.0)  #: rad; nor turns one by less


def patch_moves(
    tgt: np.ndarray,
    normals: np.ndarray,
    hand: HandGeometry,
    s: GraspSettings,
    found: HandCandidates,
) -> tuple[np.ndarray, np.ndarray]:
    """How to move each of `found`'s hands so that its pads meet the object along their
    faces, about their middle (closing_region's tangent patches): a turn (rad) about the hand
    axis, through the sample, that brings the closing axis onto the normals where the pads
    touch, then a shift (m) along the hand axis that brings the patches' middle onto the
    pads' middle. (G,) each. Where there is no such move, the shift is NaN (and the turn 0):
    either pad has no patch within gpd_recentre of its edges, or the move is below MIN_TURN
    and MIN_SHIFT.

    The contacts are found as closing_region finds them, at the hand's depth and placement,
    but over a slab gpd_recentre wider on each side of the pads, and against the extremes of
    that slab: off its middle, a pad meets a can's side where it is narrower than at its
    axis, and the can is widest where the pad is not. The turn is the median over each pad's
    contacts of the angle from the closing axis to their normals (to minus theirs, for the
    right pad), in the plane the hand turns in, averaged over the pads.

    The turned hand keeps the placement and fingertip depth found for the first; the second
    pass (`CandidateSearch.recentred`) finds its own.

    Ours, beyond GPD. Its eight orientations step 26 degrees about the curvature axis and do
    not include the normal itself, so no hand comes straight down onto the top of a can: the
    nearest lean 13 degrees and close across it at that slant. And 500 samples seldom put a
    hand right over an upright mug's axis: a mug held a centimetre off it slides along the
    pads, and one held at a slant turns in them.
    """
    turn, shift = np.full(len(found), np.nan), np.full(len(found), np.nan)
    if s.gpd_recentre <= 0 or not len(found):
        return turn, shift
    slab = WideSlab(tgt, normals, hand, s, found)
    theta = found.angles[found.orientation]
    left, right, n_c, n_a = slab.extremes(theta)
    turn = (
        slab.medians(left, np.arctan2(n_a, n_c)) + slab.medians(right, np.arctan2(-n_a, -n_c))
    ) / 2
    turned = theta + np.nan_to_num(turn)
    left, right, n_c, _ = slab.extremes(turned)
    cos_tangent = math.cos(math.radians(s.gpd_tangent_deg))
    middles = [
        slab.patch_middle(on) for on in (left & (n_c >= cos_tangent), right & (n_c <= -cos_tangent))
    ]
    shift = (middles[0] + middles[1]) / 2
    still = ~(np.abs(turn) >= MIN_TURN) & ~(np.abs(shift) >= MIN_SHIFT)
    none = np.isnan(shift) | still
    turn[none], shift[none] = np.nan, np.nan
    return np.nan_to_num(turn), shift


class WideSlab:
    """The target points in a slab `margin` (m; default gpd_recentre) wider on each side of
    the pads of each of `found`'s hands, as slab_pairs gives them: f (P,) the hand, p (P,)
    the point, h, u, v (P,) coordinates (m) and nu, nv (P,) the normals' components, in its
    sample's frame."""

    def __init__(
        self,
        tgt: np.ndarray,
        normals: np.ndarray,
        hand: HandGeometry,
        s: GraspSettings,
        found: HandCandidates,
        margin: float | None = None,
    ) -> None:
        i = found.sample
        margin = s.gpd_recentre if margin is None else margin
        region = [
            (
                hand.pad_width / 2 + margin,
                math.hypot(hand.width_max, hand.finger_length),
                np.inf,
            )
        ]
        self.f, self.p, self.h, self.u, self.v, self.nu, self.nv = slab_pairs(
            tgt, found.samples[i], found.normal[i], found.axis[i], region, normals
        )
        self.found, self.hand, self.band = found, hand, s.gpd_contact_band

    def extremes(self, theta: np.ndarray) -> tuple[np.ndarray, ...]:
        """Per pad, the pairs at its extreme within the hand turned to `theta` (G,) rad,
        and their normals' components along its closing axis and approach."""
        f, u, v, nu, nv, found = self.f, self.u, self.v, self.nu, self.nv, self.found
        ct, st = np.cos(theta).astype(np.float32).take(f), np.sin(theta).astype(np.float32).take(f)
        a = ct * u + st * v
        cc = st * u - ct * v - found.offset.take(f)
        tip = found.tip.take(f)
        inside = (
            (a <= tip) & (a >= tip - self.hand.pad_depth) & (np.abs(cc) < self.hand.width_max / 2)
        )
        cmax = np.full(len(found), -np.inf, np.float32)
        cmin = np.full(len(found), np.inf, np.float32)
        np.maximum.at(cmax, f[inside], cc[inside])
        np.minimum.at(cmin, f[inside], cc[inside])
        left = inside & (cc >= cmax.take(f) - self.band)
        right = inside & (cc <= cmin.take(f) + self.band)
        return left, right, st * nu - ct * nv, ct * nu + st * nv

    def along_hand_axis(self, vectors: np.ndarray) -> np.ndarray:
        """(P,) each pair's point's vector (`vectors` (N, 3), e.g. the normals) along its
        hand's axis."""
        axes = self.found.axis.take(self.found.sample.take(self.f), axis=0)
        return np.einsum("pi,pi->p", np.take(vectors, self.p, axis=0), axes)

    def medians(self, on: np.ndarray, x: np.ndarray) -> np.ndarray:
        """(G,) the median of `x` over each hand's pairs `on`; NaN for a hand with none."""
        out = np.full(len(self.found), np.nan)
        fs = self.f[on]
        order = np.argsort(fs, kind="stable")
        fs, xs = fs[order], x[on][order]
        starts = np.flatnonzero(np.r_[True, fs[1:] != fs[:-1]]) if len(fs) else fs
        for k, lo in enumerate(starts):
            hi = starts[k + 1] if k + 1 < len(starts) else len(fs)
            out[fs[lo]] = np.median(xs[lo:hi])
        return out

    def patch_middle(self, on: np.ndarray) -> np.ndarray:
        """(G,) float64: the middle (m) along the hand axis of each hand's pairs `on`, as
        closing_region's patch extents; inf - inf: NaN where the pad has no patch."""
        f, h = self.f, self.h
        lo = np.full(len(self.found), np.inf, np.float32)
        hi = np.full(len(self.found), -np.inf, np.float32)
        np.minimum.at(lo, f[on], h[on])
        np.maximum.at(hi, f[on], h[on])
        with np.errstate(invalid="ignore"):
            return ((lo + hi) / 2).astype(np.float64)
