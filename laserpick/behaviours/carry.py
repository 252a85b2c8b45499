"""Carrying what the hand holds: rising clear of what is around it, the poses it is held in
on the way (tucked in beside the scooter, raised in front), and the obstacles it leaves."""

from __future__ import annotations

import time
from collections.abc import Sequence

import numpy as np

from laserpick.behaviours.guarded_motion import GuardedMotion
from laserpick.behaviours.held import Held
from laserpick.behaviours.messages import NOT_HOLDING
from laserpick.behaviours.outcome import Outcome
from laserpick.description import dims
from laserpick.description.kinematics import tcp_pose
from laserpick.pipeline.collision import CollisionChecker, not_carried
from laserpick.pipeline.joint_search import joint_path_via
from laserpick.pipeline.lines import cartesian_line
from laserpick.pipeline.motion_limits import timed
from laserpick.settings import Settings
from laserpick.types import Failure

__all__ = [
    "RAISING",
    "TUCKING",
    "Carrying",
    "holding_pose",
    "holding_poses",
    "tuck_way",
    "without_leftovers",
]

#: What the tuck's motions do, as the user hears it: to the tucked pose, or raised in front.
TUCKING = "tucking it in"
RAISING = "raising"


def holding_pose(
    q: np.ndarray, checker: CollisionChecker, payload: np.ndarray, turns: Sequence[float]
) -> np.ndarray:
    """`q` (6,) rad with the last wrist joint turned by the first of `turns` (rad,
    `hold_turns`) at which the arm and what it holds (`payload`, TCP frame) keep clear of
    `checker`; `q` itself where none does (the planner then says it found no way)."""
    for turn in turns:
        turned = q.copy()
        turned[5] += turn
        if checker.clearance_ok(turned, payload=payload)[0]:
            return turned
    return q


def without_leftovers(
    surroundings: CollisionChecker, carried: np.ndarray, support: float, scatter: float
) -> CollisionChecker:
    """`surroundings` less the points within CARRIED_PADDING of the object's carried
    shape (`carried`, m, `base`: `carried_shape`, what the cameras saw of it, its guessed
    back and the column down to the surface it stood on, at `support`, m) and more than
    `scatter` (m, `support_scatter`) above that surface: the object's own, which leave with
    it. Parts of it the segmentation left out (a spray bottle's trigger head, a pill
    bottle's lower back just above its board), or that the views from the way in saw where
    no camera sees now. Kept, they stand where the lifted object then hangs, and no carry
    or tuck can start."""
    pts = surroundings.points
    if len(pts) == 0 or len(carried) == 0:
        return surroundings
    return surroundings.without(~not_carried(pts, carried) & (pts[:, 2] > support + scatter))


class Carrying(GuardedMotion):
    """Rising clear (`rise_clear`) and tucking in (`tuck`) what the hand holds."""

    def rise_clear(
        self,
        checker: CollisionChecker,
        payload: np.ndarray | None = None,
        *,
        hand_on_the_way: bool | CollisionChecker = True,
    ) -> Failure | None:
        """Lift straight up, `rise_step` at a time and at most `rise_max`, until the arm,
        the hand and what it holds (`payload`, in the TCP frame) are clear of `checker`: a
        planner cannot start among obstacles. Just after a lift the held object may still be
        near its neighbours or the parts of itself the segmentation missed; just after a
        place the open hand is still about the object it let go of.
        A step that would bring the arm itself near anything is not taken: a hand held out
        level and raised swings the elbow back over the scooter, into the tiller and the
        sensor posts, and no path leaves from there. Where straight up does, a held object
        may instead rise and reach out `rise_out`, away from the arm's mount, which keeps the
        elbow forward: only where that step ends with the object clear (out of a shelf's
        gap, it would carry the object deeper in). hand_on_the_way: whether the hand is kept
        clear of `checker` on each step too; or, where it starts among what it let go of,
        the checker of all but that, which the hand is kept clear of instead (unchecked, an
        open hand rose off a chip can into the projector's post over the basket, and no way
        left from there)."""
        s, b = self.settings.motion, self.settings.behaviour
        risen = 0.0
        while not checker.clearance_ok(self.current_q(), payload=payload)[0]:
            if risen >= b.rise_max:
                return None  # let the planner say it found no way
            path = self._rise_step_path(checker, payload, hand_on_the_way)
            if path is None:
                return None
            failure = self.run(timed(path, s, tcp_speed=s.approach_speed), "lifting clear")
            if failure is not None:
                return failure
            risen += b.rise_step
        return None

    def _rise_step_path(
        self,
        checker: CollisionChecker,
        payload: np.ndarray | None,
        hand: bool | CollisionChecker,
    ) -> np.ndarray | None:
        """The joint path (N, 6) of one `rise_step` up that keeps the arm (and the hand, if
        `hand` is True) clear of `checker`, and the hand clear of `hand` where that is a
        checker: straight, or, holding `payload`, reaching out `rise_out` from the arm's
        mount where that brings the payload clear. None when neither does.
        Clear, where the arm starts within a checker's margin, means keeping at least the
        clearance it starts with (`clearance_kept`): an object set down on a low table can
        leave the forearm a few millimetres above the top, and a rise held to the full
        margin could not leave."""
        b = self.settings.behaviour
        q = self.current_q()
        kept = checker.clearance_kept(q, hand=hand is True)
        hand_kept = hand.clearance_kept(q) if isinstance(hand, CollisionChecker) else 0.0
        if kept is None or hand_kept is None:
            return None
        here = tcp_pose(q)
        out = here[:2, 3] - dims.ARM_MOUNT_POS[:2]
        out = out / max(float(np.linalg.norm(out)), 1e-6)
        for reach in (0.0, b.rise_out) if payload is not None else (0.0,):
            T = here.copy()
            T[:2, 3] += reach * out
            T[2, 3] += b.rise_step
            path = cartesian_line(q, T, self.settings.motion.cartesian_step)
            if path is None or not checker.clearance_ok(path, hand=hand is True, margin=kept).all():
                continue
            if (
                isinstance(hand, CollisionChecker)
                and not hand.clearance_ok(path, margin=hand_kept).all()
            ):
                continue
            if reach == 0.0 or checker.clearance_ok(path[-1], payload=payload)[0]:
                return path
        return None

    def dropped_on_the_way(self, where: str) -> Outcome | None:
        """After a carry to `where`: the failure to end with if the hand no longer holds the
        object (it fell on the way), else None."""
        if self.robot.gripper_state().holding:
            return None
        self.held = None
        msg = f"The object fell from the hand while it was carried to {where}."
        return Outcome(Failure("execute", msg))

    def tuck(self) -> Outcome:
        """Hold what the hand holds folded back beside the scooter (`dims.UR5_CARRY_Q`) while
        the user drives and marks where it goes: out of the cameras' view, the laser's way and
        the furniture's (raised in front, the object hangs 1.6 m ahead of the rear axle, into
        a shelf the scooter parks at). Where `tuck_searches` searches find no way there,
        raised in front (the high ready pose). As searched while the pick lifted the object
        (`tuck_way`, `ahead`) where the arm stands at that search's start; else searched now,
        after rising clear. The outcome's timings give the seconds the arm stood still for
        the searches (`CARRY_PLANNING`)."""
        held = self.held
        if held is None:
            return Outcome(Failure("precondition", NOT_HOLDING))
        way, planning = self.searched_ahead(tuck_way, held)
        if way is None:
            failure = self.rise_clear(held.surroundings, held.points_tcp)
            if failure is not None:
                return Outcome(failure)
            t0 = time.perf_counter()
            way = tuck_way(self.current_q(), held, self.settings, self.rng)
            planning += time.perf_counter() - t0
        if way is None:
            msg = f"No collision-free path was found for {RAISING}."
            return Outcome(Failure("ik_plan", msg)).planned_for(planning)
        what, path = way
        failure = self.follow(path, held.surroundings, what, payload=held.points_tcp)
        return Outcome(failure).planned_for(planning)


def holding_poses(held: Held, settings: Settings) -> tuple[np.ndarray, np.ndarray]:
    """The tucked pose and the high ready pose (6,) rad, each with the wrist turned where
    `held` keeps clear there (`holding_pose`)."""
    turns = settings.behaviour.hold_turns
    return (
        holding_pose(dims.UR5_CARRY_Q, held.surroundings, held.points_tcp, turns),
        holding_pose(dims.UR5_HIGH_READY_Q, held.surroundings, held.points_tcp, turns),
    )


def tuck_way(
    q_from: np.ndarray, held: Held, settings: Settings, rng: np.random.Generator
) -> tuple[str, np.ndarray] | None:
    """The tuck's way for `held` from q_from (6,) rad, searched with `rng` as `tuck`
    searches it: what the motion does (`TUCKING` or `RAISING`) and its joint path (K, 6)
    rad. None where the arm and what it holds are not clear at q_from (the tuck rises clear
    first) or no search found a way. Reads nothing of the robot: run while the arm lifts."""
    if not held.clear_at(q_from):
        return None
    carry, high = holding_poses(held, settings)
    kw = {"payload": held.points_tcp}
    for _ in range(settings.behaviour.tuck_searches):
        path = joint_path_via(
            q_from, carry, held.surroundings, rng, settings.motion, via=(high,), **kw
        )
        if path is not None:
            return TUCKING, path
    path = joint_path_via(q_from, high, held.surroundings, rng, settings.motion, **kw)
    return None if path is None else (RAISING, path)
