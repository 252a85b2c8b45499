"""Motion planning for picks and places (paper 004 section 7.4).

A pick's transit to its pre-grasp: a straight joint-space move when it is clear, else
RRT-Connect around the obstacle (`joint_search`), through the way out of where the arm
rests; and the pick it completes with the parts that need no search (`pick_prep`: the
straight Cartesian approach and lift). Every path is checked against a `CollisionChecker`,
then time-parametrized within the motion limits of `MotionSettings` (`motion_limits`).

Frames: TCP poses in `base` (m); joint angles in rad.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np

from laserpick.pipeline.collision import CollisionChecker
from laserpick.pipeline.joint_search import Searches
from laserpick.pipeline.pick_prep import PickPlan, prepare_pick
from laserpick.pipeline.smoothing import ClearFn
from laserpick.settings import MotionSettings, get_settings
from laserpick.types import Failure

__all__ = [
    "NO_WAY",
    "PickPlan",
    "plan_pick",
    "transit_path",
    "transit_to_any",
    "way_to",
]

#: Said when a pick's transit to its pre-grasp found no way (`plan_pick`).
NO_WAY = "No collision-free path to this grasp was found."


def transit_path(
    q_now: np.ndarray,
    q_pre: np.ndarray,
    world: CollisionChecker,
    rng: np.random.Generator,
    s: MotionSettings,
    searches: Searches,
    via: Sequence[np.ndarray] = (),
    unstow: np.ndarray | None = None,
    standby: bool = False,
    turn: np.ndarray | None = None,
) -> tuple[np.ndarray, list[ClearFn]] | None:
    """Joint waypoints (K, 6) rad from q_now to the pre-grasp q_pre, clear of the `world`,
    each leg searched once per pick (`searches`): through the way out of where the arm
    rests (`way_to`), or else through the first of `via` that the world shows clear. The
    leg to the pre-grasp keeps the hand to space the cameras saw through; so do the legs
    before it, but for the fixed way out of a rest pose. None when a leg finds no way; else
    the waypoints and, for each segment between them, the check its leg was searched with
    (for the blends of `timed`)."""
    found = transit_to_any(q_now, q_pre, world, rng, s, searches, via, unstow, standby, turn)
    return None if found is None else found[1:]


def transit_to_any(
    q_now: np.ndarray,
    q_pres: np.ndarray,
    world: CollisionChecker,
    rng: np.random.Generator,
    s: MotionSettings,
    searches: Searches,
    via: Sequence[np.ndarray] = (),
    unstow: np.ndarray | None = None,
    standby: bool = False,
    turn: np.ndarray | None = None,
) -> tuple[int, np.ndarray, list[ClearFn]] | None:
    """`transit_path` to whichever of the pre-grasps q_pres (k, 6) rad, best first, on one
    way out (`way_to` of the first), the last leg searched toward them all at once
    (`joint_search.joint_path`: the straight move to the first that has one, else one
    search that ends at the one it reaches). The seen-space test of that search counts
    where the arm will stand at each of them as seen; the leg found is kept only where it
    passes knowing the one it reached alone, else that one is left out and the others
    searched again. Returns which pre-grasp (its row), the waypoints and their checks."""
    goals = np.atleast_2d(np.asarray(q_pres, float))
    way, fixed = way_to(q_now, goals[0], world, via, unstow, standby, turn)
    transit, checks = np.atleast_2d(way[0]), []
    for a, b in itertools.pairwise(way):
        # The way out of the stowed pose, to the unstow pose and on to a ready pose, passes
        # beside the scooter and turns the elbow over above the cameras' view; the way from
        # standing by rises from beside the scooter to the front (and turns the elbow over
        # on to the unstow pose, for a grasp on that branch). Fixed ways of straight moves,
        # not held to seen space. Only the leg to the grasp is: turning the elbow over on
        # it swings the hand through space no camera saw, and finds no way.
        leg = searches.path(a, b, world, rng, s, seen=not fixed)
        if leg is None:
            return None
        transit = np.vstack([transit, leg[1:]])
        checks += [_leg_check(world, a, b, not fixed)] * (len(leg) - 1)
    last = _last_leg(way[-1], goals, world, rng, s, searches)
    if last is None:
        return None
    row, leg = last
    checks += [_leg_check(world, way[-1], goals[row], True)] * (len(leg) - 1)
    return row, np.vstack([transit, leg[1:]]), checks


def _last_leg(
    a: np.ndarray,
    goals: np.ndarray,
    world: CollisionChecker,
    rng: np.random.Generator,
    s: MotionSettings,
    searches: Searches,
) -> tuple[int, np.ndarray] | None:
    """The leg from a to whichever of `goals` (k, 6) rad it reaches, held to seen space
    (`transit_to_any`): the goal's row and the leg's waypoints, or None."""
    rows = np.arange(len(goals))
    while len(rows):
        leg = searches.path(a, goals[rows] if len(rows) > 1 else goals[rows[0]], world, rng, s)
        if leg is None:
            return None
        k = int(np.flatnonzero((goals[rows] == leg[-1]).all(axis=1))[0])
        if len(rows) == 1 or _seen_knowing(world, a, goals[rows[k]], leg):
            return int(rows[k]), leg
        # It passed only where the arm will stand at another goal.
        rows = np.delete(rows, k)
    return None


def _seen_knowing(world: CollisionChecker, a: np.ndarray, b: np.ndarray, leg: np.ndarray) -> bool:
    """Whether every segment of `leg` (K, 6) rad passes the seen-space check of the leg from
    a to b alone (`Searches.path`)."""
    known = world.knowing(a, b)
    return all(known.segment_ok(p, q, hand=True, seen=True) for p, q in itertools.pairwise(leg))


def way_to(
    q_now: np.ndarray,
    q_pre: np.ndarray,
    world: CollisionChecker,
    via: Sequence[np.ndarray],
    unstow: np.ndarray | None,
    standby: bool,
    turn: np.ndarray | None,
) -> tuple[list[np.ndarray], bool]:
    """The configurations (rad) the transit to the pre-grasp q_pre passes before its last
    leg, q_now first, and whether they are the fixed way out of a rest pose: legs of
    straight moves beside the scooter, where no camera sees, not held to seen space. Not
    from a rest pose, or where its way out is not clear in the `world`: q_now and the first
    of `via` that the world shows clear. Only q_pre's elbow branch counts.

    From the stowed pose (`unstow` given, `UR5_UNSTOW_Q`): through the unstow pose, then the
    first clear pose of `via`, where the elbow turns over; where none is clear (a shelf's
    boards fill both ready poses), for a pre-grasp on the other elbow branch, on to `turn`
    (standing by's exit, `UR5_STANDBY_EXIT_Q`), the elbow up. From standing by (`standby`),
    the elbow up: to the first clear ready pose, else through `unstow`, its exit
    (`UR5_STANDBY_EXIT_Q`); for a pre-grasp on the other elbow branch, on to `turn` (the
    unstow pose) as the stow goes. Either way the elbow turns over on the way out, not on
    the leg held to seen space: turned there, the hand swings through space no camera saw,
    and each grasp's search spent all its samples (a pill bottle on the bookshelf, 16 s)."""
    clear = [q for q in via if world.clearance_ok(q)[0]]
    if not standby:
        if unstow is None or not world.clearance_ok(unstow)[0]:
            return [q_now, *clear[:1]], False
        if not clear and turn is not None and q_pre[2] * unstow[2] < 0:
            return [q_now, unstow, *([turn] if world.clearance_ok(turn)[0] else [])], True
        return [q_now, unstow, *clear[:1]], True
    if turn is not None and q_pre[2] * q_now[2] < 0 and world.clearance_ok(turn)[0]:
        return [q_now, *clear[:1], turn], True
    if clear:
        return [q_now, clear[0]], True
    exit_clear = unstow is not None and world.clearance_ok(unstow)[0]
    return [q_now, *([unstow] if exit_clear else [])], True


def _leg_check(world: CollisionChecker, a: np.ndarray, b: np.ndarray, seen: bool) -> ClearFn:
    """The check `Searches.path` searched the leg from a to b with, for configurations."""
    known = world.knowing(a, b) if seen else world
    return lambda Q: known.path_clear(Q, hand=True, seen=seen)


def plan_pick(
    q_now: np.ndarray,
    q_grasp: np.ndarray,
    world: CollisionChecker,
    surroundings: CollisionChecker,
    rng: np.random.Generator,
    settings: MotionSettings | None = None,
    via: Sequence[np.ndarray] = (),
    check_hand: bool = True,
    searches: Searches | None = None,
    unstow: np.ndarray | None = None,
    payload: np.ndarray | None = None,
    standby: bool = False,
    turn: np.ndarray | None = None,
) -> PickPlan | Failure:
    """Plan a pick at the grasp whose IK solution is q_grasp (from `reach.reachable`).

    unstow: a configuration the transit passes through first, when the cloud shows it clear
    (from a stowed arm, `UR5_UNSTOW_Q`: the way out of the stowed pose, which stays beside
    the scooter, where no camera sees).
    standby: the arm stands by between picks (`UR5_STANDBY_Q`): its way to a ready pose is
    fixed too, beside the scooter; `unstow` is then its exit, taken only where no ready
    pose is clear (`transit_path`). turn: where the way out ends for a grasp on the other
    elbow branch: from standing by, `UR5_UNSTOW_Q`; from the stowed pose where no ready
    pose is clear, `UR5_STANDBY_EXIT_Q` (`way_to`).
    via: configurations the transit may pass through next (the ready poses, from a stowed
    arm): the first that is clear of the cloud is used; none if none is.
    check_hand: check the hand at the grasp against the surroundings; grasp detection that
    already tested the hand's exact shape there (GPD, EL-E's sweep) may skip it.
    searches: the pick's joint-space searches so far, when several grasps are tried.
    payload: the object as the hand will hold it (points, m, TCP frame), for the lift.

    world: the whole cloud; surroundings: the cloud less the target. The arm is checked
    against the world all the way. The hand is checked against the world on the transit,
    and on its last leg, to the pre-grasp, also kept to space the cameras saw through (the
    world's frames); on the straight approach it is not, because grasp detection swept the
    hand in along this very line (GPD pushes it in from behind, finger and palm length
    back); at the grasp itself the hand's spheres may dip HAND_CONTACT_TOLERANCE into the
    surroundings (its fingertips stop millimetres above the table, whose points scatter by
    as much). On the lift only the arm is checked against the surroundings, as the hand
    rises from its grasp.
    """
    s = settings or get_settings().motion
    searches = searches or Searches(s.rrt_max_failed)
    way, _ = way_to(q_now, q_grasp, world, via, unstow, standby, turn)
    prep = prepare_pick(q_grasp, way[-1], world, surroundings, s, check_hand, payload)
    if isinstance(prep, Failure):
        return prep
    transit = transit_path(q_now, prep.q_pre, world, rng, s, searches, via, unstow, standby, turn)
    if transit is None:
        return Failure("ik_plan", NO_WAY)
    return prep.planned(transit, s)
