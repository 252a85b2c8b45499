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
from laserpick.pipeline.plan import NO_PATH, GraspEnds, PickPlan, grasp_ends
from laserpick.pipeline.transit import transit_path, transit_way
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

    The way to a grasp's pre-grasp is planned together with those of the next grasps
    (`grasps_searched_together` in all) that plan at their ends and share its way there
    (`_together`): the straight move to the first that has one, else one search toward all
    of them, which ends at the first it reaches (`transit.transit_path`).
    From anywhere but the ready pose (stowed or standing by, mostly) the transit goes
    through a ready pose; from the stowed pose, through the unstow pose first; from standing
    by, through its exit where no ready pose is clear. From either, the way to the ready
    pose is a fixed way beside the scooter (`transit.transit_way`).
    The hand is checked at the grasp only for vertical grasps: GPD and EL-E's sweep tested
    it there already. Returns the plan (or the last failure, which says so when ways
    through space the cameras did not see were left untaken), its grasp and how many grasps
    were tried (for a plan, the taken grasp's place in the order).
    """
    s = settings or get_settings().motion
    at = _AtGrasps(found, list(found.ordered() if order is None else order), q_now, s, admit)
    plan: PickPlan | Failure = Failure("ik_plan", "There is no grasp to plan for.")
    searches = Searches(s.rrt_max_failed)
    searched: set[int] = set()
    for i in range(len(at.grasps)):
        if i in searched:
            continue
        ends = at.ends(i)
        if isinstance(ends, Failure):
            plan = ends
            continue
        group = _together(at, i, searched, s.grasps_searched_together)
        searched.update(group)
        pres = np.array([at.ends(j).q_pre for j in group])
        transit = transit_path(q_now, pres, found.world, rng, s, searches, **at.way)
        if transit is not None:
            taken = group[int(np.flatnonzero((pres == transit[0][-1]).all(axis=1))[0])]
            return at.ends(taken).plan(transit, s), at.grasps[taken], taken + 1
        plan = Failure("ik_plan", NO_PATH)
        if searches.spent:
            msg = f"No collision-free path in {searches.failed} searches; no more were tried"
            plan = Failure("ik_plan", msg)
            break
    refused = any(plan is r for r in at.refused)
    if isinstance(plan, Failure) and not refused and searches.unseen_only(s):
        plan = Failure("ik_plan", f"{plan.message.rstrip('.')}{UNSEEN_WAYS}")
    return plan, None, at.tried


class _AtGrasps:
    """The grasps of one pick in the order they are tried, with what each needs at its
    grasp (`grasp_ends`, or the failure that rules it out, `admit`'s among them: `refused`),
    worked out once as the planning comes to it, and the way to their pre-grasps (`way`,
    `transit_path`'s options, from where the arm is, q_now)."""

    def __init__(
        self,
        found: GraspSet,
        grasps: list[Grasp],
        q_now: np.ndarray,
        s: MotionSettings,
        admit: Callable[[Grasp], Failure | None] | None,
    ) -> None:
        self.found, self.grasps, self.q_now, self.s, self.admit = found, grasps, q_now, s, admit
        stowed, standby = at_pose(q_now, UR5_HOME_Q), at_pose(q_now, UR5_STANDBY_Q)
        self.way = {
            "via": () if at_pose(q_now, UR5_READY_Q) else (UR5_READY_Q, UR5_HIGH_READY_Q),
            "unstow": UR5_UNSTOW_Q if stowed else UR5_STANDBY_EXIT_Q if standby else None,
            "standby": standby,
            "turn": UR5_UNSTOW_Q if standby else UR5_STANDBY_EXIT_Q if stowed else None,
        }
        self.refused: list[Failure] = []
        self._ends: dict[int, GraspEnds | Failure] = {}

    @property
    def tried(self) -> int:
        """How many grasps, in order, the planning came to."""
        return max(self._ends, default=-1) + 1

    def ends(self, i: int) -> GraspEnds | Failure:
        """What grasp i needs at its grasp, or why it is ruled out."""
        if i not in self._ends:
            grasp, found = self.grasps[i], self.found
            if grasp.ik is None:
                raise ValueError("plan_first needs grasps from the reachability filter")
            refused = self.admit(grasp) if self.admit is not None else None
            if refused is not None:
                self.refused.append(refused)
                self._ends[i] = refused
            else:
                self._ends[i] = grasp_ends(
                    grasp.ik,
                    found.world,
                    found.surroundings,
                    self.s,
                    check_hand=found.strategy == "vertical",
                    payload=grasp.in_hand(found.carried),
                )
        return self._ends[i]

    def way_to(self, i: int) -> list[np.ndarray]:
        """The waypoints (rad) to where the last leg to grasp i's pre-grasp starts."""
        return transit_way(self.q_now, self.ends(i).q_pre, self.found.world, **self.way)[0]


def _together(at: _AtGrasps, i: int, searched: set[int], most: int) -> list[int]:
    """Grasp i (its ends planned) and those of the next `most` - 1 grasps not yet searched
    whose ends plan and whose way to the pre-grasp is grasp i's, in order."""
    way = at.way_to(i)
    after = [j for j in range(i + 1, len(at.grasps)) if j not in searched][: most - 1]
    same = [
        j
        for j in after
        if not isinstance(at.ends(j), Failure)
        and len(w := at.way_to(j)) == len(way)
        and all(np.array_equal(a, b) for a, b in zip(w, way, strict=True))
    ]
    return [i, *same]
