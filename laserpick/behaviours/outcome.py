"""How a behaviour ends: done, or a typed `Failure` with a sentence the user can read."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from laserpick.types import Failure, Grasp

__all__ = ["CARRY_PLANNING", "SEARCH", "Outcome"]

#: `Outcome.timings` keys: wall-clock seconds spent searching a joint path (`go_to`), and
#: spent planning the way of what the hand holds (its postures and paths), during which the
#: arm stands still with the object in the hand.
SEARCH = "search"
CARRY_PLANNING = "plan_carry"


@dataclass(frozen=True)
class Outcome:
    """How a behaviour ended. attempts: grasps tried in planning; timings: seconds per stage;
    spot: where a place set the object down (the surface point under the TCP, m, `base`);
    standing: the object there as the hand let it go (its carried shape, m, `base`);
    closed_width: a pick's finger gap once it has squeezed again after the first lift (m),
    beside `grasp.width`, the width it planned: an object turned in the pads shows less;
    caution: a sentence for the user about what went otherwise than planned, which no sensor
    can confirm (an object let go partly past the basket's opening)."""

    failure: Failure | None = None
    grasp: Grasp | None = None
    attempts: int = 0
    timings: dict[str, float] = field(default_factory=dict)
    spot: np.ndarray | None = None
    standing: np.ndarray | None = None
    closed_width: float | None = None
    caution: str | None = None

    @property
    def ok(self) -> bool:
        return self.failure is None

    def planned_for(self, seconds: float) -> Outcome:
        """This outcome with `seconds` (wall clock) of carry planning as its only timing."""
        return replace(self, timings={CARRY_PLANNING: seconds})

    def cautioned(self, caution: str | None) -> Outcome:
        """This outcome with `caution` said: as its caution when it is done, after its
        failure's sentence when it failed; itself when there is none to say."""
        if caution is None:
            return self
        if self.failure is None:
            return replace(self, caution=caution)
        failure = Failure(self.failure.kind, f"{self.failure.message} {caution}")
        return replace(self, failure=failure)
