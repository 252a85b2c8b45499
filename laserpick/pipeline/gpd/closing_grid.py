"""How deep a hand swept in along its approach goes before it touches a scene point, per
frame (sample, orientation) and finger placement: scene points binned along the closing
axis (np.minimum.at), so each placement's stop is a min over a few bins. This is the direct
computation; `voxel_pruning.pruned_tips` reproduces it looking at few of the points.
Frames: a hand frame's (h, c, a) axes, metres.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

from laserpick.description.dims import HandGeometry
from laserpick.settings import GraspSettings

BINS_PER_PLACEMENT = 4  #: closing-axis bins per finger-placement step (collision resolution)
ORIENTED_BLOCK = 32768  #: (pair, orientation) combinations per block of flat arrays


class ClosingGrid:
    """Finger placements and the closing-axis bins used to find collisions (m).

    Placement k puts the hand centre at c_k = -W/2 + (k + 1/2) W/K on the closing axis, so the
    sample always lies between the open fingers; W = width_max, K = placements. Bins are W/K/4
    wide with edges on every placement's inner finger faces.
    """

    def __init__(self, hand: HandGeometry, s: GraspSettings) -> None:
        w, k = hand.width_max, s.gpd_finger_placements
        self.step = w / k
        self.offsets = -w / 2 + (np.arange(k) + 0.5) * self.step
        self.bin = self.step / BINS_PER_PLACEMENT
        self.finger_thick = hand.pad_thickness + hand.finger_thickness
        self.n_finger_bins = math.ceil(self.finger_thick / self.bin - 1e-9)
        # Bin 0 starts n0 bins below the first left inner face (at step / 2).
        self.n0 = math.ceil((w + self.finger_thick) / self.bin - 1e-9) + 1
        self.lo = 0.5 * self.step - self.n0 * self.bin
        hi = w - 0.5 * self.step + self.finger_thick
        self.n_bins = math.ceil((hi - self.lo) / self.bin) + 1
        ks = np.arange(k)
        self.left = self.n0 + ks * BINS_PER_PLACEMENT  # first bin of each left finger
        self.right = self.n0 + (ks - k) * BINS_PER_PLACEMENT  # one past each right finger
        half_palm = hand.palm_width / 2
        self.palm_lo = np.floor((self.offsets - half_palm - self.lo) / self.bin).astype(int)
        self.palm_hi = np.floor((self.offsets + half_palm - self.lo) / self.bin).astype(int) + 1
        self.palm_lo = np.clip(self.palm_lo, 0, self.n_bins)
        self.palm_hi = np.clip(self.palm_hi, 0, self.n_bins)


def orientation_blocks(
    select: np.ndarray | None, n_pairs: int, n_orient: int
) -> Iterator[tuple[int, np.ndarray]]:
    """(orientation, pair indices): for each orientation the pairs that `select` ((O, P)
    bool; all pairs if None) picks for it, ORIENTED_BLOCK at a time. Small blocks keep the
    temporaries in cache, and picking first skips the many (pair, orientation) combinations
    that cannot matter."""
    for o in range(n_orient):
        pairs = np.arange(n_pairs) if select is None else np.flatnonzero(select[o])
        for lo in range(0, len(pairs), ORIENTED_BLOCK):
            yield o, pairs[lo : lo + ORIENTED_BLOCK]


def by_orientation(
    frames: np.ndarray, sid: np.ndarray, pair_ok: np.ndarray | None = None
) -> np.ndarray:
    """(O, P) bool for orientation_blocks: the pairs of samples `sid` (P,) whose frame is set
    in `frames` ((S, O) bool), and (if given) whose `pair_ok` (P,) is set."""
    out = np.empty((frames.shape[1], len(sid)), bool)
    for o, column in enumerate(np.ascontiguousarray(frames.T)):
        np.take(column, sid, out=out[o])
        if pair_ok is not None:
            out[o] &= pair_ok
    return out


def rotated(
    u: np.ndarray, v: np.ndarray, theta: float, grid: ClosingGrid
) -> tuple[np.ndarray, np.ndarray]:
    """Approach depth a (m) and closing bin (float, floor taken; may lie outside the grid) of
    points with coordinates u, v (m, float32, see slab_pairs) once the hand is rotated by
    theta (rad), in float32."""
    ct, st = np.float32(math.cos(theta)), np.float32(math.sin(theta))
    return ct * u + st * v, np.floor((st * u - ct * v - grid.lo) / grid.bin)


def bin_minima(
    h: np.ndarray,
    u: np.ndarray,
    v: np.ndarray,
    sid: np.ndarray,
    n_samples: int,
    angles: np.ndarray,
    grid: ClosingGrid,
    hand: HandGeometry,
    s: GraspSettings,
    select: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Per closing bin and frame (sample * O + orientation), the least approach depth (m,
    from the sample) of the points in the fingers' band, and of those in the palm's band plus
    finger_length: (bins, S * O) float32 each, inf where empty.

    h, u, v: pairs' coordinates (see slab_pairs) with their sample indices `sid`; select:
    optional (O, P) mask of the (orientation, pair) combinations to use (default all). The
    fingers' band is the fingers' extent along the hand axis and approach depths from the
    starting hand's finger roots on; the palm's is wider along the hand axis and starts at the
    starting palm's rear.
    """
    F, t0, n_o, n_b = hand.finger_length, s.gpd_init_bite, len(angles), grid.n_bins
    n_frames = n_samples * n_o
    finger_min = np.full(n_b * n_frames, np.inf, np.float32)
    palm_min = np.full(n_b * n_frames, np.inf, np.float32)
    bands = (
        (finger_min, max(hand.finger_width, hand.pad_width) / 2, t0 - F, 0.0),
        (palm_min, hand.palm_depth / 2, t0 - F - hand.palm_length, F),
    )
    for o, p in orientation_blocks(select, len(h), n_o):
        ah = np.abs(h.take(p))
        a, j = rotated(u.take(p), v.take(p), angles[o], grid)
        ok = (j >= 0) & (j < n_b)
        frame = sid.take(p) * n_o + o
        for out, half_h, a_min, add in bands:
            i = np.flatnonzero(ok & (ah <= half_h) & (a >= a_min))
            key = j.take(i).astype(np.intp) * n_frames + frame.take(i)
            np.minimum.at(out, key, a.take(i) + add if add else a.take(i))
    return finger_min.reshape(n_b, n_frames), palm_min.reshape(n_b, n_frames)


def placement_minima(finger_min: np.ndarray, palm_min: np.ndarray, grid: ClosingGrid) -> np.ndarray:
    """(F, K) float32: for each frame and finger placement, the least depth (m) at which a
    scene point stops the fingertips: the least of bin_minima over the bins of the placement's
    fingers (finger_min) and palm (palm_min), each (bins, F)."""
    nf = grid.n_finger_bins
    stop = np.empty((len(grid.offsets), finger_min.shape[1]), np.float32)
    for k in range(len(grid.offsets)):
        left = finger_min[grid.left[k] : grid.left[k] + nf].min(axis=0)
        right = finger_min[max(grid.right[k] - nf, 0) : grid.right[k]].min(axis=0)
        palm = palm_min[grid.palm_lo[k] : grid.palm_hi[k]].min(axis=0)
        stop[k] = np.minimum(np.minimum(left, right), palm)
    return np.ascontiguousarray(stop.T)


def tips_from_stops(stop: np.ndarray, s: GraspSettings) -> np.ndarray:
    """Fingertip depths (m) from placement_minima: gpd_clearance short of the first stop, and
    -inf where even the starting hand (tips at gpd_init_bite) collides."""
    tips = stop - s.gpd_clearance
    tips[tips < s.gpd_init_bite] = -np.inf
    return tips


def deepest_tips(
    h: np.ndarray,
    u: np.ndarray,
    v: np.ndarray,
    sid: np.ndarray,
    n_samples: int,
    angles: np.ndarray,
    grid: ClosingGrid,
    hand: HandGeometry,
    s: GraspSettings,
) -> np.ndarray:
    """(S, O, K) deepest fingertip position t (m along the approach, from the sample) that a
    hand swept in from behind reaches without touching a scene point; -inf if none.

    The hand starts with its fingertips gpd_init_bite past the sample. A point in a finger's
    band (closing and hand-axis extent) at approach depth a stops the tips at a; a point in the
    palm's band stops them at a + finger_length. Points already behind the starting hand are
    out of its way.

    This is the direct computation over every (sample, point) pair of slab_pairs(cloud, ...,
    hand_regions); the detector gets the same result faster from pruned_tips.
    """
    stop = placement_minima(*bin_minima(h, u, v, sid, n_samples, angles, grid, hand, s), grid)
    return tips_from_stops(stop, s).reshape(n_samples, len(angles), len(grid.offsets))


def middle_placement(free: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each row of `free` (F, K) bool: whether any placement is free, and the middle of
    the longest run of free placements (GPD's choice: it centres the hand on the object)."""
    run = np.zeros(free.shape, np.int64)
    run[:, 0] = free[:, 0]
    for k in range(1, free.shape[1]):
        run[:, k] = (run[:, k - 1] + 1) * free[:, k]
    end = np.argmax(run, axis=1)
    length = run[np.arange(len(run)), end]
    return length > 0, end - (length - 1) // 2
