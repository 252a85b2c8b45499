"""The pick (004 section 7.4): try the grasps in score order and execute the first that
plans; move to the pre-grasp; approach in a straight, guarded line (an unexpected contact
stops the arm, which then backs off); close; lift 2 cm and close again (the re-grip of
002); lift 10 cm; check the hold (EL-E, 000 section 4.6); from the side, draw back out."""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence

import numpy as np

from laserpick.behaviours.ahead import Ahead
from laserpick.behaviours.basket_way import basket_way
from laserpick.behaviours.carry import tuck_way, without_leftovers
from laserpick.behaviours.drop_postures import holds_over_basket
from laserpick.behaviours.hand import GRIPPER_TIME, closed_on_something, wait_for_gripper
from laserpick.behaviours.held import Held, WayIn
from laserpick.behaviours.messages import NO_BASKET_HOLD
from laserpick.behaviours.outcome import Outcome
from laserpick.behaviours.withdraw import Withdrawing
from laserpick.description.kinematics import tcp_pose
from laserpick.pipeline.first_plan import plan_first
from laserpick.pipeline.grasp_choice import GraspSet
from laserpick.pipeline.lines import cartesian_line
from laserpick.pipeline.motion_limits import timed
from laserpick.pipeline.parking_advice import park_aside_sentence
from laserpick.pipeline.plan import PickPlan
from laserpick.pipeline.reach import pregrasp_pose
from laserpick.types import Failure, Grasp

__all__ = ["Picking"]


class Picking(Withdrawing):
    """The pick (`pick`)."""

    def pick(
        self, grasps: GraspSet, order: Sequence[Grasp] | None = None, *, to_basket: bool = False
    ) -> Outcome:
        """Pick with the first grasp of `order` (default: all, in score order) that plans.
        Done, the hand holds the object (`held`), lifted and, from the side, drawn back.
        to_basket: the object goes to the basket next, so a grasp that holds it where no
        drop posture fits is not taken (`holds_over_basket`); else it is tucked in next.
        From the moment the pick is planned, while the arm moves in, grasps and lifts, the
        way there is searched (`ahead`: `basket_way`, `tuck_way`) from where the lift will
        leave the arm, for `drop_in_basket` or `tuck` to take up."""
        s = self.settings.motion
        if self.robot.gripper_state().holding:
            return Outcome(Failure("precondition", "The hand is already holding something."))
        order = list(order) if order is not None else grasps.ordered()
        self.way_in = self.ahead = None
        t0 = time.perf_counter()
        admit = self._basket_admits(grasps) if to_basket else None
        self.progress("Planning the arm's way to the grasp.")
        plan, grasp, attempts = plan_first(
            grasps,
            self.current_q(),
            self.rng,
            order,
            s,
            admit,
            progress=self.progress,
            stop=self.should_stop,
        )
        timings = {"plan": time.perf_counter() - t0}
        if isinstance(plan, Failure) and self.should_stop():
            failure = Failure("execute", "Stopped while planning: the pick was cancelled.")
            return Outcome(failure, attempts=attempts, timings=timings)
        if isinstance(plan, Failure):
            msg = f"None of the {attempts} grasps could be planned ({plan.message})"
            if plan.park_left is not None:
                msg += "." + park_aside_sentence(plan.park_left)
            failure = Failure("ik_plan", msg, park_left=plan.park_left)
            return Outcome(failure, attempts=attempts, timings=timings)
        self.progress(f"Grasp {attempts} of {len(order)} planned; moving to it.")
        # The carry's search reads only the plan and what the cameras saw: started now, it
        # runs while the arm moves in, not only while it lifts (`isolation`: the arm stood
        # still for it 0.18 s an attempt, against 0.69 s started at the close).
        held = self._to_hold(grasps, grasp)
        way_out = self._search_ahead(held, plan, to_basket)
        failure = self._reach_and_close(plan)
        if failure:
            self.ahead = None
            return Outcome(failure, grasp, attempts, timings)
        # Held from here on, so that a cancel or an e-stop while lifting still knows what
        # the hand has (the object's points travel with it in later collision checks).
        self.held, self.way_in = held, WayIn(self.robot.base_pose(), plan.approach.q)
        self.progress("Lifting the object.")
        failure, closed = self._regrip_and_lift(plan)
        if failure:
            if not self.should_stop():  # a cancel or an e-stop keeps what the hand holds
                self.release()
            return Outcome(failure, grasp, attempts, timings, closed_width=closed)
        failure = None if way_out is None else self.run_withdrawal(way_out, s.lift_speed)
        if failure:  # the hand keeps what it holds: the session tucks it in
            return Outcome(failure, grasp, attempts, timings, closed_width=closed)
        self.progress("Holding the object.")
        return Outcome(None, grasp, attempts, timings, closed_width=closed)

    def _search_ahead(self, held: Held, plan: PickPlan, to_basket: bool) -> np.ndarray | None:
        """Start the search for the carry of `held` that follows the pick (`ahead`: to the
        basket, `basket_way`, or tucked in, `tuck_way`), from where the lift will leave the
        arm: the planned lifted posture, or after a grasp from the side, the end of the way
        back out of it, found from there. Returns that way (N, 6) rad, None from above."""
        approach = held.grasp.approach
        way_out = self.withdrawal_path(
            approach, held.surroundings, held.points_tcp, q_from=plan.q_lifted
        )
        q_from = plan.q_lifted if way_out is None else way_out[-1]
        rng = np.random.default_rng(self.rng.integers(2**63))  # the thread's own
        carry = basket_way if to_basket else tuck_way
        # Taken up for this carry only, of this object among these surroundings (replaced
        # where the scooter has moved).
        owners = (carry, held, held.surroundings)
        self.ahead = Ahead(
            self.robot, q_from, owners, lambda: carry(q_from, held, self.settings, rng)
        )
        return way_out

    def _basket_admits(self, grasps: GraspSet) -> Callable[[Grasp], Failure | None]:
        """For `plan_first`: refuses a grasp that holds the object, as carried and as it
        falls, where no drop posture holds it over the basket. Each grasp is judged once:
        `plan_first` may ask of it again in a later pass."""
        carried, falls = grasps.carried, grasps.carried_as_seen  # one array where none was cut off
        margin, b = self.settings.motion.clearance, self.settings.behaviour
        judged: dict[int, Failure | None] = {}

        def admits(grasp: Grasp) -> Failure | None:
            if id(grasp) not in judged:
                fall = None if falls is carried else grasp.in_hand(falls)
                held = grasp.in_hand(carried)
                ok = holds_over_basket(held, fall, margin=margin, settings=b)
                judged[id(grasp)] = None if ok else Failure("ik_plan", NO_BASKET_HOLD)
            return judged[id(grasp)]

        return admits

    def _reach_and_close(self, plan: PickPlan) -> Failure | None:
        """Open the hand, move to the pre-grasp, approach guarded, and close: None when the
        gripper closed on something. Met on the way in, the hand backs off; closed on
        nothing, it opens and retreats."""
        s = self.settings.motion
        self.robot.gripper(False)
        failure = self.run(plan.transit, "moving to the grasp")
        if failure:
            return failure
        guarded = plan.approach.guarded(s.guard_force)
        self.progress("Approaching the object.")
        failure = self.run(guarded, "approaching the object")
        if failure and "unexpected contact" in failure.message:
            self._back_off_along_approach()
            touched = failure.message.split("unexpected contact: ", 1)[1].rstrip(".")
            msg = f"The hand touched something on its way in ({touched}), stopped and backed off."
            return Failure("execute", msg)
        if failure:
            return failure
        self.progress("Closing the gripper.")
        self.robot.gripper(True)
        # The full stroke's time, not until the gripper reports still (some 0.35 s sooner):
        # lifted then, a tissue packet and a chip can held off their middles slipped out
        # (isolation seeds 4 and 12; not traced).
        self.robot.sleep(GRIPPER_TIME)
        if not closed_on_something(self.robot):
            self._open_and_retreat(plan)
            return Failure("execute", "The gripper closed on nothing.")
        return None

    def _to_hold(self, grasps: GraspSet, grasp: Grasp) -> Held:
        """What the hand will hold once `grasp` closes (`held`): the object's carried shape
        in the TCP frame, and its surroundings less its own leftovers
        (`without_leftovers`)."""
        support = grasps.stands_on
        pts = grasps.carried
        pts_tcp = grasp.in_hand(pts)
        scatter = self.settings.behaviour.support_scatter
        around = without_leftovers(grasps.surroundings, pts, support, scatter)
        height = float(grasp.position[2] - support)
        middle = grasp.in_hand(grasps.middle[None])[0]
        seen_tcp = grasp.in_hand(grasps.carried_as_seen) if len(grasps.cut_off) else None
        return Held(grasp, height, pts_tcp, middle, around, self.robot.base_pose(), seen_tcp)

    def _regrip_and_lift(self, plan: PickPlan) -> tuple[Failure | None, float]:
        """002's re-grip: lift a little, so the object hangs in the hand, and squeeze again,
        for as long as the gripper reports its fingers moving (`wait_for_gripper`); then the
        full lift. Returns why it failed (None: lifted, still holding) and the finger gap
        (m) after the second squeeze."""
        s = self.settings.motion
        failure = self.run(plan.regrip, "lifting") if s.regrip_lift > 0 else None
        self.robot.gripper(True)
        # `isolation`: 88 of 90 with this wait, 87 with a fixed 0.3 s, which took 0.3 s more.
        wait_for_gripper(self.robot)
        closed = self.robot.gripper_state().width
        failure = failure or self.run(plan.lift, "lifting")
        # The hold is judged with the fingers still: an object slipping out lets them close
        # on, and they stop on the next hold or shut. A firm hold is judged at once, rather
        # than after a fixed 0.3 s that every attempt spent.
        if self.robot.gripper_state().moving:
            wait_for_gripper(self.robot)
        if failure is None and not self.robot.gripper_state().holding:
            failure = Failure("execute", "The object slipped out of the hand while lifting.")
        return failure, closed

    def _back_off_along_approach(self) -> None:
        """After a stopped approach: straight back along the approach axis by `backoff`."""
        q = self.current_q()
        T = tcp_pose(q)
        T_back = pregrasp_pose(T, self.settings.motion.backoff)
        path = cartesian_line(q, T_back, self.settings.motion.cartesian_step)
        if path is not None:
            self.run(timed(path, self.settings.motion, tcp_speed=0.05), "backing off")

    def _open_and_retreat(self, plan: PickPlan) -> None:
        """After closing on nothing: open the hand and go back to the pre-grasp pose."""
        self.robot.gripper(False)
        wait_for_gripper(self.robot)
        back = cartesian_line(
            self.current_q(), tcp_pose(plan.approach.q[0]), self.settings.motion.cartesian_step
        )
        if back is not None:
            self.run(timed(back, self.settings.motion, tcp_speed=0.1), "retreating")
