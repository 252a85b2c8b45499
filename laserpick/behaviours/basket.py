"""The basket drop: carry what the hand holds over the basket, let it go, and take the arm
back to ready (or stowed), around the object where it was let go."""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from laserpick.behaviours.carry import Carrying, holding_pose
from laserpick.behaviours.drop_postures import drop_configurations, past_the_opening
from laserpick.behaviours.held import Held
from laserpick.behaviours.messages import NOT_HOLDING, PAST_THE_OPENING
from laserpick.behaviours.outcome import SEARCH, Outcome
from laserpick.behaviours.stow import Stowing
from laserpick.description import dims
from laserpick.description.kinematics import tcp_pose
from laserpick.pipeline.collision import CollisionChecker
from laserpick.types import Failure

__all__ = ["BasketDrop"]


class BasketDrop(Carrying, Stowing):
    """The drop in the basket (`drop_in_basket`)."""

    def drop_in_basket(self) -> Outcome:
        """Carry what the hand holds to the basket, release it, and return to ready (stowed
        where neither ready pose is clear). Let go partly past the basket's opening, the
        outcome says so (`PAST_THE_OPENING`): as its caution, or in its failure. Its timings
        give the carry's planning (`CARRY_PLANNING`, wall-clock s)."""
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
        """Rise clear, then carry `held` to the first of the best `drop_tries` postures over
        the basket that a path reaches. The outcome's timings hold the wall-clock seconds
        spent choosing the postures and searching the paths (`CARRY_PLANNING`)."""
        b = self.settings.behaviour
        t0 = time.perf_counter()
        drops = drop_configurations(
            self.current_q(),
            held.surroundings,
            held.points_tcp,
            held.as_seen_tcp,
            settings=b,
            motion=self.settings.motion,
        )
        planning = time.perf_counter() - t0
        if not drops:
            msg = "The arm cannot hold the object over the basket; it keeps it."
            return Outcome(Failure("ik_plan", msg)).planned_for(planning)
        self.progress("Carrying the object to the basket.")
        failure = self.rise_clear(held.surroundings, held.points_tcp)
        if failure is not None:
            return Outcome(failure).planned_for(planning)
        high = holding_pose(dims.UR5_HIGH_READY_Q, held.surroundings, held.points_tcp, b.hold_turns)
        for q_drop in drops[: b.drop_tries]:
            out = self.go_to(
                q_drop,
                held.surroundings,
                "carrying to the basket",
                via=(high,),
                payload=held.points_tcp,
            )
            planning += out.timings[SEARCH]
            if out.ok or out.failure is None or out.failure.kind != "ik_plan":
                break  # there, or a motion was stopped: no other posture is tried
        return out.planned_for(planning)

    def _leave_basket(self, held: Held, let_go: np.ndarray) -> Outcome:
        """From over the basket, the open hand rises off the object (`let_go`, m, `base`)
        before it turns away: a tall bottle stands up out of the basket, and a straight way
        to ready sweeps the fingers through it. Then to ready around the object as it was
        let go, else as it fell, lower (no way around it); where a shelf's or a high
        table's boards fill both ready poses, folded away from the basket instead, as the
        session's stow would do next."""
        around = CollisionChecker(
            np.vstack([held.surroundings.points, let_go]),
            margin=self.settings.motion.clearance,
            filtered=True,
        )
        failure = self.rise_clear(around, hand_on_the_way=False)
        if failure is not None:
            return Outcome(failure)
        for leave in (self.go_ready, self.fold_away):
            for checker in (around, held.surroundings):
                back = leave(checker)
                if back.failure is None or back.failure.kind != "ik_plan":
                    return back
        return back
