"""The joint-space search's front: the straight joint move where it is clear, else
RRT-Connect (Kuffner and LaValle 2000) around the obstacle, ours shortened by random
shortcuts (`rrt`) or OMPL's by OMPL's path simplifier (`ompl_search`;
`MotionSettings.planner`), then made quicker to run by partial shortcuts (`quicken`); toward
one goal or the first reached of several; and the searches of one pick, shared by its
grasps (`Searches`).

Frames: joint angles in rad.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from laserpick.description.kinematics import nearest_turns
from laserpick.pipeline.collision import CollisionChecker
from laserpick.pipeline.motion_limits import motion_limits, timed
from laserpick.pipeline.ompl_search import ompl_connect
from laserpick.pipeline.plan_record import record_search
from laserpick.pipeline.quicken import merge_short_legs, quicken
from laserpick.pipeline.rrt import rrt_connect, shortcut
from laserpick.settings import MotionSettings

__all__ = [
    "BLIND_LEGS",
    "QUICKEN_TRIES",
    "UNSEEN_SAMPLES",
    "Searches",
    "joint_path",
    "joint_path_via",
]

#: The search that tells whether a blocked leg had a way through unseen space: its samples
#: (a way is found in about 0.05 s where there is one), and how many legs it tries.
UNSEEN_SAMPLES = 300
BLIND_LEGS = 3
#: Partial shortcuts `quicken` tries on a searched path: (empty hand, carrying). A carry is
#: searched while the arm lifts, which covers most of the longer work; nearly every carry
#: to the basket turns the elbow over and is searched. On 72 recorded carries
#: (`bench/path_quickening.py`), 240 against 40 ran them in 8.96 s against 9.67 s, for
#: about 1 s more search beside two benches.
QUICKEN_TRIES = {False: 40, True: 240}


def joint_path(
    q_start: np.ndarray,
    q_goal: np.ndarray,
    checker: CollisionChecker,
    rng: np.random.Generator,
    s: MotionSettings,
    planner: Literal["ompl", "ours"] | None = None,
    give_up: Callable[[], bool] | None = None,
    **kw,
) -> np.ndarray | None:
    """A clear joint path: the straight one if clear, else RRT-Connect (`planner`, default
    `s.planner`: ours or OMPL's), shortened, then, with `s.quicken_paths`, made quicker to
    run by partial shortcuts (`quicken`) and rid of its short legs (`merge_short_legs`)
    where the timing says so. None at once when the start or the goal is not clear: no edge
    can leave it, and the search would spend all its samples (seconds) finding that out.

    q_goal (k, 6) rad gives goals best first: the straight move to the first that has one,
    else a search toward those that are clear (`_search`), which ends at the goal it reaches.
    give_up: asked after each goal OMPL searched toward in vain; True ends the search there.
    """
    goals = np.atleast_2d(np.asarray(q_goal, float))
    for goal in goals:
        if checker.segment_ok(q_start, goal, **kw):
            return np.array([q_start, goal], float)
    ends_clear = checker.clearance_ok(np.vstack([q_start, goals]), **kw)
    if not ends_clear[0] or not ends_clear[1:].any():
        return None
    planner = planner or s.planner
    path = _search(q_start, goals[ends_clear[1:]], checker, rng, s, planner, kw, give_up)
    if path is None or not s.quicken_paths:
        return path
    # A carry runs at the carrying limits (`GuardedMotion.follow`): so is its path quickened.
    carrying = kw.get("payload") is not None
    limits, tries = motion_limits(s, carrying=carrying), QUICKEN_TRIES[carrying]
    quick = shortcut(quicken(path, checker, rng, limits, tries=tries, **kw), checker, rng, **kw)
    quick = merge_short_legs(quick, checker, **kw)
    if quick.shape == path.shape and np.array_equal(quick, path):
        return path  # nothing was shortened: no timing to compare (a fifth of isolation's)
    # The estimate `quicken` goes by leaves out the corners; the arm's own timing decides,
    # its corners blended where this search's check passes (`GuardedMotion.follow`).
    clear = functools.partial(checker.path_clear, **kw)
    return min((path, quick), key=lambda p: timed(p, s, carrying=carrying, clear=clear).duration)


def _search(
    q_start: np.ndarray,
    goals: np.ndarray,
    checker: CollisionChecker,
    rng: np.random.Generator,
    s: MotionSettings,
    planner: Literal["ompl", "ours"],
    kw: dict,
    give_up: Callable[[], bool] | None = None,
) -> np.ndarray | None:
    """A clear, shortened joint path from q_start to one of `goals` (k, 6) rad, best first,
    by `planner`; None where the search found none. Ours grows the goal side from every goal
    at once: searched one after another, goals in a pocket spent the whole search each (a
    cereal box's drops deep in the basket, 20 s a goal). OMPL's RRT-Connect adds a further goal to
    its goal tree only as that tree grows, so a goal in a pocket keeps it from the others:
    it searches them one after another, each with the whole budget, asking `give_up` after
    each it found no way to (a pick counts each as a failed search)."""
    for goal in goals:
        record_search(q_start, goal, checker, kw)
    if planner == "ours":
        path = rrt_connect(
            q_start, goals, checker, rng, step=s.rrt_step, max_samples=s.rrt_max_samples, **kw
        )
        return None if path is None else shortcut(path, checker, rng, **kw)
    budget = {"max_samples": s.rrt_max_samples, "time_budget": s.search_time}
    for goal in goals:
        path = ompl_connect(q_start, goal, checker, rng, **budget, **kw)
        if path is not None or (give_up is not None and give_up()):
            return path
    return None


def joint_path_via(
    q_start: np.ndarray,
    q_goal: np.ndarray,
    checker: CollisionChecker,
    rng: np.random.Generator,
    s: MotionSettings,
    via: Sequence[np.ndarray] = (),
    turn_goals: bool = False,
    reached: list[np.ndarray] | None = None,
    **kw,
) -> np.ndarray | None:
    """`joint_path` to q_goal (6,) or to the first reached of goals (k, 6) rad; where it finds
    none, through each configuration of `via` (6,) rad in turn: two shorter searches
    instead of one long. None where no search found a path. reached: where given, each
    path found to a configuration of `via` is appended to it, whether or not the way on
    from there was found.

    turn_goals: the goals hold the hand where its wrists' whole turns are free (a posture
    over the basket): the leg on from a via pose searches them with the wrists turned the
    short way from it (`nearest_turns`), as they were chosen for q_start. Searched as
    chosen, from the tucked pose a juice bottle's carry found no way on 1 of 4 draws and
    took 16-21 s; turned, 4 of 4 in 11-14 s."""
    path = joint_path(q_start, q_goal, checker, rng, s, **kw)
    for q_via in via:
        if path is not None:
            break
        goals = np.atleast_2d(np.asarray(q_goal, float))
        if turn_goals:
            goals = np.array([nearest_turns(goal, q_via) for goal in goals])
        first = joint_path(q_start, q_via, checker, rng, s, **kw)
        if first is not None and reached is not None:
            reached.append(first)
        second = joint_path(q_via, goals, checker, rng, s, **kw) if first is not None else None
        path = None if second is None else np.vstack([first, second[1:]])
    return path


@dataclass
class Searches:
    """The joint-space searches of one pick, shared by the grasps it tries: a leg already
    searched is reused (the leg from the stowed arm to the ready pose is the same for every
    grasp), and failed searches are counted, so the pick can stop after `max_failed`. The
    legs held to seen space that found no way are kept (`blocked`), to say why. Once `stop`
    returns True (the operator cancelled), no further search is made: a leg not yet
    searched finds no way, and the searches count as spent. each_goal: a leg OMPL searched
    toward several goals, one after another, counts a failed search for each goal it found
    no way to, and stops once they are spent (full searches: each takes seconds)."""

    max_failed: int
    stop: Callable[[], bool] | None = None
    each_goal: bool = False
    failed: int = 0
    legs: dict[tuple[bytes, bytes], np.ndarray | None] = field(default_factory=dict)
    blocked: dict[tuple[bytes, bytes], tuple[np.ndarray, np.ndarray, CollisionChecker]] = field(
        default_factory=dict
    )

    def path(
        self,
        a: np.ndarray,
        b: np.ndarray,
        checker: CollisionChecker,
        rng: np.random.Generator,
        s: MotionSettings,
        seen: bool = True,
    ) -> np.ndarray | None:
        """`joint_path` from a to b (6,), or to the first reached of goals b (k, 6) rad, with
        the hand checked, searched by `s.pick_planner` once per pick; seen: with the hand
        kept where the cameras saw through (`CollisionChecker.clearance_ok`), or where it
        stands at either end (at any of the goals)."""
        key = (np.asarray(a, float).tobytes(), np.asarray(b, float).tobytes())
        if key not in self.legs:
            if self.stopped:
                return None
            known = checker.knowing(a, *np.atleast_2d(b)) if seen else checker
            before = self.failed
            give_up = self._failed_goal if self.each_goal else None
            leg = joint_path(
                a, b, known, rng, s, planner=s.pick_planner, give_up=give_up, hand=True, seen=seen
            )
            self.legs[key] = leg
            if leg is None and self.failed == before:  # once, where not counted goal by goal
                self.failed += 1
            # Keyed as `legs`: searched again after `forget_failed`, still one leg.
            if leg is None and seen and checker.frames:
                self.blocked.setdefault(key, (a, b, checker))
        return self.legs[key]

    def _failed_goal(self) -> bool:
        """Count a goal an OMPL search found no way to as a failed search (`each_goal`):
        each took the whole budget, and a juice bottle on the 108 cm table whose seven
        grasps had no way spent 122 s before "no", six searches counted. Returns whether the
        searches are spent."""
        self.failed += 1
        return self.spent

    def unseen_only(self, s: MotionSettings) -> bool:
        """Whether one of the first BLIND_LEGS `blocked` legs has a way through space no
        camera saw: the cameras' view, not what they saw, kept the arm from it (over their
        heads, above a high table, their rays end on nothing in range). A short search
        (UNSEEN_SAMPLES) with its own generator, so the pick's own searches stay as they
        were; it only explains a failure, and such a way is never taken: an object seen in
        part may reach into that space."""
        rng = np.random.default_rng(0)
        quick = s.model_copy(update={"rrt_max_samples": UNSEEN_SAMPLES})
        return any(
            joint_path(a, b, checker, rng, quick, hand=True) is not None
            for a, b, checker in list(self.blocked.values())[:BLIND_LEGS]
        )

    def forget_failed(self) -> None:
        """Let the legs that found no way be searched again, with new draws; the failures
        stay counted against `max_failed`."""
        self.legs = {key: leg for key, leg in self.legs.items() if leg is not None}

    @property
    def stopped(self) -> bool:
        """Whether `stop` says to make no further search."""
        return self.stop is not None and self.stop()

    @property
    def spent(self) -> bool:
        return self.failed >= self.max_failed or self.stopped
