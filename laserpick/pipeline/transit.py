"""The way from where the arm is to a pick's pre-grasp (paper 004 section 7.4): out of where
it rests by a fixed way beside the scooter, or through a ready pose, then a leg held to
space the cameras saw through, searched once per pick (`joint_search.Searches`).

Frames: joint angles in rad.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from laserpick.pipeline.collision import CollisionChecker
from laserpick.pipeline.joint_search import Searches
from laserpick.pipeline.smoothing import ClearFn
from laserpick.settings import MotionSettings

__all__ = ["transit_path", "transit_way"]


def transit_way(
    q_now: np.ndarray,
    q_pre: np.ndarray,
    world: CollisionChecker,
    via: Sequence[np.ndarray] = (),
    unstow: np.ndarray | None = None,
    standby: bool = False,
    turn: np.ndarray | None = None,
) -> tuple[list[np.ndarray], bool]:
    """The transit's waypoints (rad) from q_now to where its last leg, to the pre-grasp
    q_pre (6,), starts: through the way out of where the arm rests (`_way_out`), or else
    through the first of `via` that the world shows clear; and whether they are that fixed
    way out. Pre-grasps with the same way share the last leg's start."""
    clear = [q for q in via if world.clearance_ok(q)[0]]
    out = _way_out(q_now, q_pre, world, clear, unstow, standby, turn)
    return [q_now, *(clear[:1] if out is None else out)], out is not None


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
    each leg searched once per pick (`searches`), by `transit_way`. The leg to the
    pre-grasp keeps the hand to space the cameras saw through; so do the legs before it,
    but for the fixed way out of a rest pose. q_pre (k, 6) gives pre-grasps best first with
    the way of the first: the last leg goes to the first it reaches (`Searches.path`), where
    the transit ends. None when a leg finds no way; else the waypoints and, for each
    segment between them, the check its leg was searched with (for the blends of `timed`)."""
    ends = np.atleast_2d(np.asarray(q_pre, float))
    way, fixed = transit_way(q_now, ends[0], world, via, unstow, standby, turn)
    transit = None
    checks: list[ClearFn] = []
    for k, a in enumerate(way):
        last = k == len(way) - 1
        b = ends if last else way[k + 1]
        # The way out of the stowed pose, to the unstow pose and on to a ready pose, passes
        # beside the scooter and turns the elbow over above the cameras' view; the way from
        # standing by rises from beside the scooter to the front (and turns the elbow over
        # on to the unstow pose, for a grasp on that branch). Fixed ways of straight moves,
        # not held to seen space. Only the leg to the grasp is: turning the elbow over on
        # it swings the hand through space no camera saw, and finds no way.
        seen = last or not fixed
        leg = searches.path(a, b, world, rng, s, seen=seen)
        if leg is None:
            return None
        transit = leg if transit is None else np.vstack([transit, leg[1:]])
        checks += [_leg_check(world, a, leg[-1], seen)] * (len(leg) - 1)
    return None if transit is None else (transit, checks)


def _way_out(
    q_now: np.ndarray,
    q_pre: np.ndarray,
    world: CollisionChecker,
    clear: Sequence[np.ndarray],
    unstow: np.ndarray | None,
    standby: bool,
    turn: np.ndarray | None,
) -> list[np.ndarray] | None:
    """The waypoints (rad) of the fixed way out of a rest pose to a pre-grasp q_pre: legs
    of straight moves beside the scooter, where no camera sees, not held to seen space.
    None when q_now is not a rest pose, or its way out is not clear in the `world`.

    From the stowed pose (`unstow` given, `UR5_UNSTOW_Q`): through the unstow pose, then the
    first `clear` ready pose, where the elbow turns over; where none is clear (a shelf's
    boards fill both), for a pre-grasp on the other elbow branch, on to `turn` (standing
    by's exit, `UR5_STANDBY_EXIT_Q`), the elbow up. From standing by (`standby`), the
    elbow up: to the first clear ready pose, else through `unstow`, its exit
    (`UR5_STANDBY_EXIT_Q`); for a pre-grasp on the other elbow branch, on to `turn` (the
    unstow pose) as the stow goes. Either way the elbow turns over on the way out, not on
    the leg held to seen space: turned there, the hand swings through space no camera saw,
    and each grasp's search spent all its samples (a pill bottle on the bookshelf, 16 s)."""
    if not standby:
        if unstow is None or not world.clearance_ok(unstow)[0]:
            return None
        if not clear and turn is not None and q_pre[2] * unstow[2] < 0:
            return [unstow, turn] if world.clearance_ok(turn)[0] else [unstow]
        return [unstow, *clear[:1]]
    if turn is not None and q_pre[2] * q_now[2] < 0 and world.clearance_ok(turn)[0]:
        return [*clear[:1], turn]
    if clear:
        return [clear[0]]
    return [unstow] if unstow is not None and world.clearance_ok(unstow)[0] else []


def _leg_check(world: CollisionChecker, a: np.ndarray, b: np.ndarray, seen: bool) -> ClearFn:
    """The check `Searches.path` searched the leg from a to b with, for configurations."""
    known = world.knowing(a, b) if seen else world
    return lambda Q: known.clearance_ok(Q, hand=True, seen=seen)
