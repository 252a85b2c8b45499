"""The task's states, which state may follow which, and who asks.

    idle ─aim→ aiming ─confirm→ marked → perceived → grasps_ready ─execute→ executing
      ↑                                                                      │
      └─────── (dropped in the basket, or placed, then standing by) ←── holding
                                                     awaiting_place ─confirm→ placing

- idle: nothing under way; the laser may be off.
- aiming: the aiming beam is lit; aim and nudge move it.
- marked: both beams lit; the frames are being captured and the mark found.
- perceived: the target is segmented and lit by the projector; grasps are being found (or
  were not: `detect` tries again, perhaps with another strategy).
- grasps_ready: clusters and a current candidate; next, prev, select and auto move it.
- executing: the arm picks (for the Jeeves strategy the base drove to the object first).
- holding: the object is in the hand (carried to the basket in pick-and-drop; after a
  cancel, waiting for `execute` to drop it or for a place mark).
- awaiting_place: pick-and-place holds the object high and waits for the place mark.
- placing: the arm sets the object down at the mark, then stands by for the next pick.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import Literal

__all__ = [
    "AIMABLE",
    "HOLDING_STATES",
    "RESTING_STATES",
    "SYSTEM",
    "TRANSITIONS",
    "Actor",
    "Conflict",
    "IllegalTransition",
    "Mode",
    "Selection",
    "Source",
    "StrategyName",
    "TaskState",
    "check_transition",
]

Mode = Literal["pick_and_drop", "pick_and_place"]
Selection = Literal["auto", "manual"]
#: gpd: 004's 6-DOF candidates; overhead: EL-E's (000 section 4.4); jeeves: drive the base to
#: the target's centroid, then grasp from above (003 section IV).
StrategyName = Literal["gpd", "overhead", "jeeves"]
Source = Literal["console", "rest", "switch", "joystick", "bench", "system"]


class TaskState(StrEnum):
    IDLE = "idle"
    AIMING = "aiming"
    MARKED = "marked"
    PERCEIVED = "perceived"
    GRASPS_READY = "grasps_ready"
    EXECUTING = "executing"
    HOLDING = "holding"
    AWAITING_PLACE = "awaiting_place"
    PLACING = "placing"


#: States where the laser may be aimed (and the mark, or the place mark, confirmed).
AIMABLE = frozenset(
    {
        TaskState.IDLE,
        TaskState.AIMING,
        TaskState.PERCEIVED,
        TaskState.GRASPS_READY,
        TaskState.HOLDING,
        TaskState.AWAITING_PLACE,
    }
)
#: States that hold an object: aiming there chooses where to place it.
HOLDING_STATES = frozenset({TaskState.HOLDING, TaskState.AWAITING_PLACE})
#: Where every state may return: a job that ends (done, failed, cancelled, e-stopped) or a
#: resync rests holding the object or with an empty hand.
RESTING_STATES = frozenset({TaskState.IDLE, TaskState.HOLDING})

_S = TaskState
#: Which state may follow which, besides staying (a new message) and resting
#: (`RESTING_STATES`).
TRANSITIONS: dict[TaskState, frozenset[TaskState]] = {
    _S.IDLE: frozenset({_S.AIMING}),
    _S.AIMING: frozenset({_S.MARKED}),
    _S.MARKED: frozenset({_S.AIMING, _S.PERCEIVED}),  # the mark not found: aim again
    _S.PERCEIVED: frozenset({_S.AIMING, _S.GRASPS_READY}),
    _S.GRASPS_READY: frozenset({_S.AIMING, _S.PERCEIVED, _S.EXECUTING}),
    _S.EXECUTING: frozenset(),
    _S.HOLDING: frozenset({_S.AWAITING_PLACE}),
    _S.AWAITING_PLACE: frozenset({_S.PLACING}),
    _S.PLACING: frozenset({_S.AWAITING_PLACE}),  # the place mark not found: mark again
}


class IllegalTransition(RuntimeError):
    """The session tried a state change that `TRANSITIONS` does not allow (a bug)."""


def check_transition(old: TaskState, new: TaskState) -> None:
    """Raise `IllegalTransition` unless `new` may follow `old`."""
    if new == old or new in RESTING_STATES or new in TRANSITIONS[old]:
        return
    raise IllegalTransition(f"the task may not go from {old.value} to {new.value}")


class Conflict(Exception):
    """A command that the current state does not allow (HTTP 409). `state` is the state."""

    def __init__(self, message: str, state: TaskState) -> None:
        super().__init__(message)
        self.state = state


@dataclass(frozen=True)
class Actor:
    """Who asks: the input source, and the lease token when it came through the API (None
    for in-process callers such as the 3D console, which the watchdog does not watch)."""

    source: Source
    token: str | None = None


SYSTEM = Actor("system")
