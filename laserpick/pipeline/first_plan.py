"""The first grasp that plans (004 section 7.4): the grasps are planned in order until one
gives a pick plan, within a shared budget of joint-space searches. Frames: `base`, metres,
radians.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

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
from laserpick.pipeline.parking_advice import unseen_ways_failure
from laserpick.pipeline.pick_prep import PickPrep, prepare_pick
from laserpick.pipeline.plan import NO_WAY, PickPlan, transit_path, transit_to_any, way_to
from laserpick.pipeline.plan_record import record_pick
from laserpick.pipeline.rest_poses import at_pose
from laserpick.settings import MotionSettings, get_settings
from laserpick.types import Failure, Grasp

__all__ = ["QUICK_SAMPLES", "SEARCHING_LONGER", "plan_first"]

#: Said while a pick plans, when the short searches found no way: the full ones take seconds
#: (a juice bottle on the 108 cm table: 11-45 s in six of sixteen fresh `pick-place`
#: kitchens, beside another bench, where the user saw nothing new since "Picking.").
SEARCHING_LONGER = "No way to the grasps was found at once; searching longer, for some seconds."
#: The short search each grasp's transit gets first (samples; a way that exists is mostly
#: found within it, in about 0.1 s): a juice bottle on a high table spent three full
#: searches (12 s on a loaded machine) on grasps whose way up past the board was not
#: found, before the fourth grasp's way was found at once. The short searches may miss as
#: often as the full ones may fail (`rrt_max_failed`).
QUICK_SAMPLES = 300


def plan_first(
    found: GraspSet,
    q_now: np.ndarray,
    rng: np.random.Generator,
    order: Sequence[Grasp] | None = None,
    settings: MotionSettings | None = None,
    admit: Callable[[Grasp], Failure | None] | None = None,
    *,
    progress: Callable[[str], None] | None = None,
    stop: Callable[[], bool] | None = None,
) -> tuple[PickPlan | Failure, Grasp | None, int]:
    """Plan the grasps of `order` (default: all, best first) until one plans, as 004 does.
    `admit`, where given, may refuse a grasp before it is planned, with the failure that
    says why (what comes after the pick needs of it). `progress`, where given, hears
    `SEARCHING_LONGER` when the short searches found no way; once `stop` returns True (the
    operator cancelled), no further search is made and the pick's planning fails.

    The grasps are planned with short searches first (`QUICK_SAMPLES`), until one plans or
    `rrt_max_failed` of them found no way; then, where none planned, with full searches, best
    first again, the ways the short ones found kept: a grasp whose way is found at once is
    taken before a better-ranked one whose way needs seconds of search, or none is there.
    With `grasps_together`, the short searches go grasp by grasp only until the first whose
    way is not found, then search toward all the grasps after it at once (`_quick_pass`),
    and the full searches are one for each way out, toward the pre-grasps of all the grasps
    that take it (`_plan_together`).
    From anywhere but the ready pose (stowed or standing by, mostly) the transit goes
    through a ready pose; from the stowed pose, through the unstow pose first; from standing
    by, through its exit where no ready pose is clear. From either, the way to the ready
    pose is a fixed way beside the scooter (`plan.transit_path`).
    The hand is checked at the grasp only for vertical grasps: GPD and EL-E's sweep tested
    it there already.

    Where the grasps run out within the searches' budget and some found no way to their
    pre-grasp, those are planned once more, best first, through the high ready pose first
    and with the failed legs searched anew: a search held to seen space finds a narrow way
    on some draws and not others, and a pick with one grasp left had one search between it
    and "no". With `grasps_together`, where that pass found no way either, the budget left
    goes to those grasps one by one: a search toward many goals spreads its samples over
    them, and a juice bottle on a high table whose every together search failed, try after
    try, was picked grasp by grasp.

    Returns the plan (or the last failure, which says so when ways through space the
    cameras did not see were left untaken), its grasp and its place in the order (or how
    many grasps were tried).
    """
    s = settings or get_settings().motion
    grasps = list(found.ordered() if order is None else order)
    record_pick(found, q_now, rng, grasps, s, admit)
    via = () if at_pose(q_now, UR5_READY_Q) else (UR5_READY_Q, UR5_HIGH_READY_Q)
    pick = _Pick(found, q_now, rng, admit)
    searches = Searches(s.rrt_max_failed, stop=stop, each_goal=True)
    if s.rrt_max_samples > QUICK_SAMPLES:
        quick = Searches(s.rrt_max_failed, stop=stop)
        short = s.model_copy(update={"rrt_max_samples": QUICK_SAMPLES})
        done = _quick_pass(pick, grasps, short, via, quick)
        if done.grasp is not None:
            return done.plan, done.grasp, _place(grasps, done.grasp)
        searches.legs.update((key, leg) for key, leg in quick.legs.items() if leg is not None)
        if progress is not None and not searches.stopped:
            progress(SEARCHING_LONGER)
    full = _plan_together if s.grasps_together else _plan_in_order
    first = full(pick, grasps, s, via, searches)
    last = first
    if first.grasp is None and first.no_way and not searches.spent:
        searches.forget_failed()
        again, admitted = (UR5_HIGH_READY_Q, *via[:1]), replace(pick, admit=None)
        last = full(admitted, first.no_way, s, again, searches)
        if last.grasp is None and s.grasps_together and last.no_way and not searches.spent:
            last = _plan_in_order(admitted, last.no_way, s, again, searches)
    if last.grasp is not None:
        return last.plan, last.grasp, _place(grasps, last.grasp)
    plan = last.plan
    if searches.stopped:
        return plan, None, first.tried
    if isinstance(plan, Failure) and not last.refused and searches.unseen_only(s):
        plan = unseen_ways_failure(plan, found.middle)
    return plan, None, first.tried


def _place(grasps: Sequence[Grasp], grasp: Grasp) -> int:
    """The place (from 1) of `grasp` in `grasps`."""
    return next(k for k, g in enumerate(grasps, 1) if g is grasp)


@dataclass
class _Pass:
    """One pass of `plan_first` over its grasps: the plan (or the last failure) and its
    grasp, how many grasps were tried, whether the last failure was `admit`'s refusal, and
    the grasps whose transit found no way (`NO_WAY`), best first."""

    plan: PickPlan | Failure
    grasp: Grasp | None = None
    tried: int = 0
    refused: bool = False
    no_way: list[Grasp] = field(default_factory=list)


@dataclass
class _Pick:
    """What the passes of one pick's planning share: the grasps and their clouds (`found`),
    where the arm is (q_now, rad), the draws, `admit` (None: every grasp is admitted), and
    the grasps' search-free parts once made (`preps`, by grasp and where the transit's last
    leg starts)."""

    found: GraspSet
    q_now: np.ndarray
    rng: np.random.Generator
    admit: Callable[[Grasp], Failure | None] | None
    preps: dict[tuple[int, bytes], PickPrep | Failure] = field(default_factory=dict)

    def refusal(self, grasp: Grasp) -> Failure | None:
        """`admit`'s refusal of `grasp`, if any; an error for a grasp without IK."""
        if grasp.ik is None:
            raise ValueError("plan_first needs grasps from the reachability filter")
        return self.admit(grasp) if self.admit is not None else None

    def prepared(self, grasp: Grasp, out: dict, s: MotionSettings) -> PickPrep | Failure:
        """The search-free part of the pick at `grasp` (`prepare_pick`), its transit taking
        the way `out` (`_way_out`), made once a pick."""
        q_from = way_to(self.q_now, grasp.ik, self.found.world, **out)[0][-1]
        made = (id(grasp), q_from.tobytes())
        if made not in self.preps:
            self.preps[made] = prepare_pick(
                grasp.ik,
                q_from,
                self.found.world,
                self.found.surroundings,
                s,
                check_hand=self.found.strategy == "vertical",
                payload=grasp.in_hand(self.found.carried),
            )
        return self.preps[made]


def _way_out(q_now: np.ndarray, via: Sequence[np.ndarray]) -> dict:
    """The way out of where the arm rests at q_now (rad), as `plan.way_to` takes it: from the
    stowed pose through the unstow pose, from standing by through its exit where no ready
    pose is clear, each turning the elbow over where the grasp is on the other branch;
    elsewhere, through the first clear pose of `via`."""
    stowed, standby = at_pose(q_now, UR5_HOME_Q), at_pose(q_now, UR5_STANDBY_Q)
    return {
        "via": via,
        "unstow": UR5_UNSTOW_Q if stowed else UR5_STANDBY_EXIT_Q if standby else None,
        "standby": standby,
        "turn": UR5_UNSTOW_Q if standby else UR5_STANDBY_EXIT_Q if stowed else None,
    }


def _spent(searches: Searches) -> Failure:
    """The failure said when the pick's failed searches reached their budget."""
    msg = f"No collision-free path in {searches.failed} searches; no more were tried"
    return Failure("ik_plan", msg)


def _quick_pass(
    pick: _Pick,
    grasps: Sequence[Grasp],
    s: MotionSettings,
    via: Sequence[np.ndarray],
    searches: Searches,
) -> _Pass:
    """The short searches' pass (`s` holds their samples): grasp by grasp until one plans or
    the `searches` are spent; with `grasps_together`, grasp by grasp until the first whose
    way is not found, then one search for each way out toward all the grasps after it.
    Grasp by grasp, a juice bottle on a high table spent six short searches (5.2 s beside
    three benches) before the full search toward all its grasps found one at once; the
    first grasp alone stays first: an ordinary pick plans it in 0.2 s and need not
    prepare twenty."""
    if not s.grasps_together:
        return _plan_in_order(pick, grasps, s, via, searches)
    first = _plan_in_order(pick, grasps, s, via, searches, until_no_way=True)
    rest = grasps[first.tried :]
    if first.grasp is not None or not first.no_way or not rest or searches.spent:
        return first
    return _plan_together(pick, rest, s, via, searches)


def _plan_in_order(
    pick: _Pick,
    grasps: Sequence[Grasp],
    s: MotionSettings,
    via: Sequence[np.ndarray],
    searches: Searches,
    until_no_way: bool = False,
) -> _Pass:
    """The pick at each of `grasps` in turn, through the first clear pose of `via`, until one
    plans or the `searches` are spent (or, `until_no_way`, until the first whose transit
    found no way)."""
    out = _way_out(pick.q_now, via)
    done = _Pass(Failure("ik_plan", "There is no grasp to plan for."))
    for grasp in grasps:
        done.tried += 1
        refused = pick.refusal(grasp)
        done.refused = refused is not None
        prep = refused if refused is not None else pick.prepared(grasp, out, s)
        if isinstance(prep, Failure):
            done.plan = prep
            continue
        transit = transit_path(
            pick.q_now, prep.q_pre, pick.found.world, pick.rng, s, searches, **out
        )
        if transit is not None:
            done.plan, done.grasp = prep.planned(transit, s), grasp
            return done
        done.plan = Failure("ik_plan", NO_WAY)
        done.no_way.append(grasp)
        if until_no_way:
            break
        if searches.spent:
            done.plan = _spent(searches)
            break
    return done


def _plan_together(
    pick: _Pick,
    grasps: Sequence[Grasp],
    s: MotionSettings,
    via: Sequence[np.ndarray],
    searches: Searches,
) -> _Pass:
    """`_plan_in_order` with the transits searched together: every grasp's search-free part
    first, then for each way out, best grasp first, one search toward the pre-grasps of all
    the grasps that take it (`transit_to_any`): the grasp whose way is found is taken, not
    the best-ranked whose way a full search of its own might find."""
    out = _way_out(pick.q_now, via)
    done = _Pass(Failure("ik_plan", "There is no grasp to plan for."))
    ways: dict[bytes, list[tuple[Grasp, PickPrep]]] = {}
    for grasp in grasps:
        done.tried += 1
        refused = pick.refusal(grasp)
        if refused is not None:
            done.plan, done.refused = refused, not ways
            continue
        prep = pick.prepared(grasp, out, s)
        if isinstance(prep, Failure):
            done.plan = prep
            continue
        key = np.vstack(way_to(pick.q_now, prep.q_pre, pick.found.world, **out)[0]).tobytes()
        ways.setdefault(key, []).append((grasp, prep))
    for takers in ways.values():
        q_pres = np.array([prep.q_pre for _, prep in takers])
        transit = transit_to_any(pick.q_now, q_pres, pick.found.world, pick.rng, s, searches, **out)
        if transit is not None:
            grasp, prep = takers[transit[0]]
            done.plan, done.grasp = prep.planned(transit[1:], s), grasp
            return done
        done.plan, done.refused = Failure("ik_plan", NO_WAY), False
        done.no_way += [grasp for grasp, _ in takers]
        if searches.spent:
            done.plan = _spent(searches)
            break
    return done
