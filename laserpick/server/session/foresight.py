"""Foresight: a clicked mark worked out as soon as it is aimed, on a thread of its own, so
that the confirming click finds its target segmented and the highlight on its way.

Frames: points in `base` (m).
"""

from __future__ import annotations

import itertools
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from laserpick.pipeline.perceive import Perception, perceive
from laserpick.pipeline.projector import highlight_points
from laserpick.server.session.captures import Capture, CaptureReads
from laserpick.types import FusedCloud


@dataclass(frozen=True)
class Foreseen:
    """A clicked mark worked out before the click that confirms it: the perception at
    `point` (m, `base`) in `capture`, and the projector image lighting its target (None when
    there is none)."""

    capture: Capture
    point: np.ndarray
    perception: Perception
    lit: np.ndarray | None

    def of(self, capture: Capture | None, point: np.ndarray) -> bool:
        """Whether this is the mark at `point` (m, `base`) worked out in `capture`."""
        return self.capture is capture and np.array_equal(self.point, point)


class Foresight(CaptureReads):
    """Works clicked marks out ahead of their confirm, on the foresight thread."""

    def _init_foresight(self) -> None:
        self._foresight = ThreadPoolExecutor(
            max_workers=1, thread_name_prefix="laserpick-foresight"
        )
        self._foresee_seqs = itertools.count(1)
        self._foresee_seq = 0  #: the newest request; older ones not yet begun are dropped

    def _close_foresight(self) -> None:
        self._foresight.shutdown(wait=True, cancel_futures=True)

    def _foresee(self, point: np.ndarray) -> Future[Foreseen | None]:
        """Work out the mark at `point` (m, `base`) in the capture it was aimed in, on the
        foresight thread: the perception a confirm there uses, and its highlight, which the
        3D view sends ahead, hidden, to show at the confirm. Resolves to None when there is
        no fresh capture (the scooter moved), or when a newer request came before it began."""
        seq = self._foresee_seq = next(self._foresee_seqs)
        return self._foresight.submit(self._perceive_ahead, self._capture, point, seq)

    def _perceive_ahead(
        self, capture: Capture | None, point: np.ndarray, seq: int
    ) -> Foreseen | None:
        seen = self._foreseen
        if seen is not None and seen.of(capture, point):
            return seen
        if seq != self._foresee_seq or capture is None or capture is not self._fresh_capture():
            return None
        perception = perceive(
            capture.frames, point=point, settings=self.settings.perception, cloud=capture.cloud
        )
        lit = highlight_points(self.projector, perception.target_points) if perception.ok else None
        seen = Foreseen(capture, np.array(point, float), perception, lit)
        self._foreseen = seen
        with self._lock:
            self._emit("foreseen")
        return seen

    @property
    def foreseen(self) -> tuple[FusedCloud, np.ndarray] | None:
        """The cloud and the projector image of the mark worked out ahead of its confirm,
        while that capture is the latest: what the 3D view may send ahead, hidden."""
        seen = self._foreseen
        if seen is None or seen.lit is None or seen.capture is not self._capture:
            return None
        return seen.capture.cloud, seen.lit

    @property
    def foreseen_mark(self) -> Foreseen | None:
        """The last mark worked out ahead of its confirm, whichever capture it was in."""
        return self._foreseen
