"""Behaviours: pick, carry, drop in the basket, place at a mark, put back, approach, executed
on any `Robot`.

Each checks its preconditions before it moves and its postconditions after (EL-E, 000
section 4.6; the re-grip of 002), and ends in one `Outcome`: done, or a typed `Failure` with
a sentence the user can read. A failed behaviour leaves the arm at rest, and never holding
the gripper half closed on nothing. `Behaviours` is the one object the session drives: each
behaviour is a class of its own module, all built on `GuardedMotion`. Their tunables are the
settings' `behaviour` group (`BehaviourSettings`, `LASERPICK_BEHAVIOUR__*`).
"""

from __future__ import annotations

from laserpick.behaviours.ahead import Ahead
from laserpick.behaviours.approach import Approaching
from laserpick.behaviours.basket import BasketDrop
from laserpick.behaviours.basket_way import BasketWay, basket_way
from laserpick.behaviours.carry import Carrying, holding_pose, tuck_way, without_leftovers
from laserpick.behaviours.drop_postures import (
    basket_opening,
    drop_candidates,
    drop_configurations,
    holds_over_basket,
    past_the_opening,
    rank_drop_postures,
    warm_drop_postures,
)
from laserpick.behaviours.guarded_motion import GuardedMotion
from laserpick.behaviours.hand import wait_for_gripper
from laserpick.behaviours.held import Held, WayIn
from laserpick.behaviours.leave import Leaving
from laserpick.behaviours.messages import (
    MARK_MOVES,
    NO_BASKET_HOLD,
    NOT_HOLDING,
    PAST_THE_OPENING,
    TUCKING_FIRST,
    crowded_message,
)
from laserpick.behaviours.outcome import CARRY_PLANNING, Outcome
from laserpick.behaviours.pick import Picking
from laserpick.behaviours.place import Placing
from laserpick.behaviours.place_poses import PlacePoses, front_wall, place_poses, turned_hand_xy
from laserpick.behaviours.put_back import PuttingBack
from laserpick.behaviours.stow import Stowing
from laserpick.behaviours.withdraw import Withdrawing

__all__ = [
    "CARRY_PLANNING",
    "MARK_MOVES",
    "NOT_HOLDING",
    "NO_BASKET_HOLD",
    "PAST_THE_OPENING",
    "TUCKING_FIRST",
    "Ahead",
    "Approaching",
    "BasketDrop",
    "BasketWay",
    "Behaviours",
    "Carrying",
    "GuardedMotion",
    "Held",
    "Leaving",
    "Outcome",
    "Picking",
    "PlacePoses",
    "Placing",
    "PuttingBack",
    "Stowing",
    "WayIn",
    "Withdrawing",
    "basket_opening",
    "basket_way",
    "crowded_message",
    "drop_candidates",
    "drop_configurations",
    "front_wall",
    "holding_pose",
    "holds_over_basket",
    "past_the_opening",
    "place_poses",
    "rank_drop_postures",
    "tuck_way",
    "turned_hand_xy",
    "wait_for_gripper",
    "warm_drop_postures",
    "without_leftovers",
]


class Behaviours(Picking, BasketDrop, Placing, PuttingBack, Approaching):
    """The robot's behaviours, run one at a time from the caller's thread: `pick`, `tuck`,
    `drop_in_basket`, `place`, `put_back`, `approach`, `go_ready`, `stow` and `stand_by`, on the
    `Robot` given (see `GuardedMotion` for the arguments). `held` is what the hand holds."""
