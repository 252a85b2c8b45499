"""The basket drop: carry what the hand holds over the basket, let it go, and take the arm
to stand by for the next pick (or to ready, or stowed), around the object where it was let
go."""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from laserpick.behaviours.basket_way import (
    BasketWay,
    basket_way,
    drop_postures_for,
    path_to_a_drop,
)
from laserpick.behaviours.carry import TUCKING, Carrying
from laserpick.behaviours.drop_postures import past_the_opening
from laserpick.behaviours.held import Held
from laserpick.behaviours.leave import Leaving
from laserpick.behaviours.messages import NOT_HOLDING, PAST_THE_OPENING, TUCKING_FIRST
from laserpick.behaviours.outcome import Outcome
from laserpick.behaviours.stow import Stowing
from laserpick.description.kinematics import tcp_pose
from laserpick.pipeline.collision import CollisionChecker
from laserpick.types import Failure

__all__ = ["BasketDrop"]


#: The progress message as the carry to the basket starts.
CARRYING = "Carrying the object to the basket."


class BasketDrop(Carrying, Leaving, Stowing):
    """The drop in the basket (`drop_in_basket`)."""

    def drop_in_basket(self) -> Outcome:
        """Carry what the hand holds to the basket, release it, and stand by for the next
        pick (to ready, or stowed, where no way there is found: `_leave_basket`). Let go
        partly past the basket's opening, the outcome says so (`PAST_THE_OPENING`): as its
        caution, or in its failure. Its timings give the carry's planning
        (`CARRY_PLANNING`, wall-clock s)."""
        if self.held is None or not self.robot.gripper_state().holding:
            self.held = None
            return Outcome(Failure("precondition", NOT_HOLDING))
        held = self.held
        out = self._carry_to_basket(held)
        if not out.ok:
            return out
        lost = self.dropped_on_the_way("the basket")
        if lost is not None:
            return replace(lost, timings=out.timings)
        self.release()
        self.progress("Released into the basket.")
        # The object can only have fallen from where the hand let it go.
        let_go = held.standing_at(tcp_pose(self.current_q()))
        caution = PAST_THE_OPENING if past_the_opening(let_go).any() else None
        left = self._leave_basket(held, let_go).cautioned(caution)
        return replace(left, timings=out.timings)

    def _carry_to_basket(self, held: Held) -> Outcome:
        """Carry `held` to the first of the best `drop_tries` postures over the basket that a
        path reaches: as searched ahead while the pick lifted it (`basket_way`), or searched
        now, after rising clear (`_search_basket_way`). The outcome's timings hold the
        wall-clock seconds the arm stood still for the postures and the paths to be found
        (`CARRY_PLANNING`)."""
        way, planning = self._way_searched_ahead(held)
        if way is not None and way.tucking is not None:
            # Out of a narrow gap the search found the way to the tucked pose, not on from it:
            # taken now, then searched on from there, as the session's tuck would, without
            # searching that way again (a juice bottle from a high table: 4.5 s).
            self.progress(TUCKING_FIRST)
            failure = self.follow(way.tucking, held.surroundings, TUCKING, payload=held.points_tcp)
            if failure is not None:
                return Outcome(failure).planned_for(planning)
            way = None
        if way is None:
            way, searched = self._search_basket_way(held)
            planning += searched
            if isinstance(way, Failure):
                return Outcome(way).planned_for(planning)
        if not way.drops:
            msg = "The arm cannot hold the object over the basket; it keeps it."
            return Outcome(Failure("ik_plan", msg)).planned_for(planning)
        if way.path is None:
            msg = "No collision-free path was found for carrying to the basket."
            return Outcome(Failure("ik_plan", msg)).planned_for(planning)
        failure = self.follow(
            way.path, held.surroundings, "carrying to the basket", payload=held.points_tcp
        )
        return Outcome(failure).planned_for(planning)

    def _way_searched_ahead(self, held: Held) -> tuple[BasketWay | None, float]:
        """The carry searched ahead for `held` from where the arm stands (None: none was,
        or its start was not clear), and the seconds (s) the arm stood still for it."""
        way, waited = self.searched_ahead(basket_way, held)
        if way is not None and way.drops:
            self.progress(CARRYING)
        return way, waited

    def _search_basket_way(self, held: Held) -> tuple[BasketWay | Failure, float]:
        """The drop postures ranked from where the arm stands, then, risen clear
        (`rise_clear`), the path to the first a search reaches; or why the rise failed.
        With the seconds (s, wall clock) the arm stood still for them."""
        t0 = time.perf_counter()
        drops = drop_postures_for(self.current_q(), held, self.settings)
        planning = time.perf_counter() - t0
        if not drops:
            return BasketWay(drops, None), planning
        self.progress(CARRYING)
        failure = self.rise_clear(held.surroundings, held.points_tcp)
        if failure is not None:
            return failure, planning
        t0 = time.perf_counter()
        path = path_to_a_drop(self.current_q(), drops, held, self.settings, self.rng)
        return BasketWay(drops, path), planning + time.perf_counter() - t0

    def _leave_basket(self, held: Held, let_go: np.ndarray) -> Outcome:
        """From over the basket, the open hand rises off the object (`let_go`, m, `base`)
        before it turns away: a tall bottle stands up out of the basket, and a straight way
        to ready sweeps the fingers through it. Where its pads still press the object, they
        are freed first (`free_the_pads`): risen, the hand would lift it out. Then straight
        to stand by for the next pick (`go_stand_by`), as the session does next, around the
        object as it was let go, else as it fell, lower (no way around it); where no way
        there is found, to ready, else folded away. Through ready, the arm stood by only
        where a ready pose was clear; where a shelf's or a high table's boards filled both,
        it folded away, and the next pick turned its elbow over on the way out."""
        around = CollisionChecker(
            np.vstack([held.surroundings.points, let_go]),
            margin=self.settings.motion.clearance,
            filtered=True,
        )
        self.free_the_pads(held.surroundings)
        failure = self.rise_clear(around, hand_on_the_way=held.surroundings)
        if failure is not None:
            return Outcome(failure)
        for leave in (self.go_stand_by, self.go_ready, self.fold_away):
            for checker in (around, held.surroundings):
                back = leave(checker)
                if back.failure is None or back.failure.kind != "ik_plan":
                    return back
        return back
