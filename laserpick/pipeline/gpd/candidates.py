"""The candidates that passed GPD's tests, with the frames they came from. Metres, radians."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

#: HandCandidates' fields that hold one entry per hand (the others hold one per frame).
PER_HAND = ("sample", "orientation", "offset", "tip", "width", "centred", "poses")


@dataclass(frozen=True)
class HandCandidates:
    """The passing candidates of some frames: (G,) each, or (G, 4, 4) poses relative to the
    target's centre. sample, orientation: the frame's indices into `samples` and `angles`;
    offset, tip: its hand centre on the closing axis and fingertip depth (m), as
    closing_region has them."""

    samples: np.ndarray
    normal: np.ndarray
    axis: np.ndarray
    angles: np.ndarray
    sample: np.ndarray
    orientation: np.ndarray
    offset: np.ndarray
    tip: np.ndarray
    width: np.ndarray
    centred: np.ndarray
    poses: np.ndarray

    def __len__(self) -> int:
        return len(self.sample)

    def subset(self, keep: np.ndarray) -> HandCandidates:
        """The candidates `keep` (indices) of these."""
        return replace(self, **{k: getattr(self, k)[keep] for k in PER_HAND})

    def with_replaced(
        self, at: np.ndarray, other: HandCandidates, which: np.ndarray
    ) -> HandCandidates:
        """These candidates with those at `at` (indices) replaced by `other`'s `which`
        (indices, one for each), in place: their frames are appended to these."""
        n = len(self.samples)
        out = {
            "samples": np.vstack([self.samples, other.samples]),
            "normal": np.vstack([self.normal, other.normal]),
            "axis": np.vstack([self.axis, other.axis]),
        }
        for k in PER_HAND:
            mine, theirs = getattr(self, k).copy(), getattr(other, k)[which]
            mine[at] = theirs + n if k == "sample" else theirs
            out[k] = mine
        return replace(self, **out)
