"""The first grasp that plans (004 section 7.4): the grasps are planned in order until one
gives a pick plan, within a shared budget of joint-space searches. Frames: `base`, metres,
radians.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from laserpick.description.dims import (
    UR5_HIGH_READY_Q,
    UR5_HOME_Q,
    UR5_READY_Q,
    UR5_STANDBY_EXIT_Q,
    UR5_STANDBY_Q,
    UR5_UNSTOW_Q,
)
from laserpick.pipeline.grasp_choice import GraspSet
from laserpick.pipeline.joint_search import Searches
from laserpick.pipeline.plan import PickPlan, plan_pick
from laserpick.settings import MotionSettings, get_settings
from laserpick.types import Failure, Grasp

__all__ = ["READY_TOLERANCE", "UNSEEN_WAYS", "at_pose", "at_rest", "plan_first"]

READY_TOLERANCE = 0.05  #: rad: the arm counts as at the ready (or stowed) pose within this
#: Said after a pick's planning failure when some way to its grasps passed only through space
#: no camera saw: the arm keeps to seen space, so the user knows why it did not go.
UNSEEN_WAYS = (
    "; the only ways found pass where the cameras could not see, and the arm keeps to where"
    " they saw"
)


def at_pose(q: np.ndarray | None, pose: np.ndarray) -> bool:
    """Whether joint angles q (6,) (rad) are at `pose` (6,), within READY_TOLERANCE."""
    return q is not None and bool(np.max(np.abs(q - pose)) < READY_TOLERANCE)


def at_rest(q: np.ndarray | None) -> bool:
    """Whether joint angles q (6,) (rad) are at a pose the arm rests in between tasks: stowed
    (`UR5_HOME_Q`) or standing by between picks (`UR5_STANDBY_Q`)."""
    return at_pose(q, UR5_HOME_Q) or at_pose(q, UR5_STANDBY_Q)


def plan_first(
    found: GraspSet,
    q_now: np.ndarray,
    rng: np.random.Generator,
    order: Sequence[Grasp] | None = None,
    settings: MotionSettings | None = None,
    admit: Callable[[Grasp], Failure | None] | None = None,
) -> tuple[PickPlan | Failure, Grasp | None, int]:
    """Plan the grasps of `order` (default: all, best first) until one plans, as 004 does.
    `admit`, where given, may refuse a grasp before it is planned, with the failure that
    says why (what comes after the pick needs of it).

    From anywhere but the ready pose (stowed or standing by, mostly) the transit goes
    through a ready pose; from the stowed pose, through the unstow pose first; from standing
    by, through its exit where no ready pose is clear. From either, the way to the ready
    pose is a fixed way beside the scooter (`plan.transit_path`).
    The hand is checked at the grasp only for vertical grasps: GPD and EL-E's sweep tested
    it there already. Returns the plan (or the last failure, which says so when ways
    through space the cameras did not see were left untaken), its grasp and how many grasps
    were tried.
    """
    s = settings or get_settings().motion
    at_ready = at_pose(q_now, UR5_READY_Q)
    via = () if at_ready else (UR5_READY_Q, UR5_HIGH_READY_Q)
    stowed = at_pose(q_now, UR5_HOME_Q)
    standby = at_pose(q_now, UR5_STANDBY_Q)
    plan: PickPlan | Failure = Failure("ik_plan", "There is no grasp to plan for.")
    searches = Searches(s.rrt_max_failed)
    carried = found.carried
    tried, refused = 0, None
    for grasp in found.ordered() if order is None else order:
        tried += 1
        if grasp.ik is None:
            raise ValueError("plan_first needs grasps from the reachability filter")
        refused = admit(grasp) if admit is not None else None
        if refused is not None:
            plan = refused
            continue
        plan = plan_pick(
            q_now,
            grasp.ik,
            found.world,
            found.surroundings,
            rng,
            s,
            via=via,
            check_hand=found.strategy == "vertical",
            searches=searches,
            unstow=UR5_UNSTOW_Q if stowed else UR5_STANDBY_EXIT_Q if standby else None,
            standby=standby,
            turn=UR5_UNSTOW_Q if standby else UR5_STANDBY_EXIT_Q if stowed else None,
            payload=grasp.in_hand(carried),
        )
        if not isinstance(plan, Failure):
            return plan, grasp, tried
        if searches.spent:
            msg = f"No collision-free path in {searches.failed} searches; no more were tried"
            plan = Failure("ik_plan", msg)
            break
    if isinstance(plan, Failure) and plan is not refused and searches.unseen_only(s):
        plan = Failure("ik_plan", f"{plan.message.rstrip('.')}{UNSEEN_WAYS}")
    return plan, None, tried
