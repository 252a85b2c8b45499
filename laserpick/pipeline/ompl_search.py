"""The joint-space search on OMPL (Sucan, Moll and Kavraki 2012): RRT-Connect (Kuffner and
LaValle 2000) in the arm's six joint angles, its path shortened by OMPL's `PathSimplifier`.
The collision check stays ours: each state and each straight edge is asked of a
`CollisionChecker` (its spheres against the cloud), an edge at the resolution of
`CollisionChecker.segment_ok`, and the path OMPL returns is checked again edge by edge.

Deterministic: OMPL's random generators are seeded from the caller's generator before each
search, and the search stops after a number of samples (a wall-clock budget only caps it
for a machine far slower than the bench's). Frames: joint angles in rad.
"""

from __future__ import annotations

import itertools
import time

import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from laserpick.pipeline.collision import CollisionChecker
from laserpick.pipeline.rrt import search_bounds

__all__ = ["OMPL_RANGE", "ompl_connect"]

#: RRT-Connect's extension step (rad, Euclidean in joint space): on the recorded problems
#: (bench/planners.py) 0.5 solved as many as 0.73 and 1.0 in less time.
OMPL_RANGE = 0.5
#: Seeds are drawn below this bound (OMPL's seeds are 32-bit; 0 is not one).
_SEED_BOUND = 2**31 - 1

ou.setLogLevel(ou.LogLevel.LOG_WARN)


def _as_q(state) -> np.ndarray:
    return np.array([state[i] for i in range(6)])


class _SegmentCheck(ob.MotionValidator):
    """A straight edge is clear when `CollisionChecker.segment_ok` says so (every
    `segment_ok` step, largest joint, coarse configurations first). The edges found clear
    are kept, so that the final path's check asks the checker only about edges it was not
    asked about (OMPL's simplifier interpolates new states)."""

    def __init__(self, si: ob.SpaceInformation, checker: CollisionChecker, kw: dict):
        super().__init__(si)
        self.checker, self.kw = checker, kw
        self.clear: set[bytes] = set()

    def checkMotion(self, a, b) -> bool:
        return self.ok(_as_q(a), _as_q(b))

    def ok(self, qa: np.ndarray, qb: np.ndarray) -> bool:
        key = qa.tobytes() + qb.tobytes()
        if key in self.clear:
            return True
        if not self.checker.segment_ok(qa, qb, **self.kw):
            return False
        self.clear |= {key, qb.tobytes() + qa.tobytes()}  # the same configurations either way
        return True


def _space(lo: np.ndarray, hi: np.ndarray, checker: CollisionChecker, kw: dict):
    space = ob.RealVectorStateSpace(6)
    bounds = ob.RealVectorBounds(6)
    for i in range(6):
        bounds.setLow(i, float(lo[i]))
        bounds.setHigh(i, float(hi[i]))
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    # A state alone is checked without the seen-space test (its projection into every
    # frame costs 5 ms a call with 45 frames): OMPL asks a state before the edge to it, and
    # the edge's check, ends included, is the whole test.
    quick = {k: v for k, v in kw.items() if k != "seen"}
    si.setStateValidityChecker(lambda s: bool(checker.clearance_ok(_as_q(s), **quick)[0]))
    validator = _SegmentCheck(si, checker, kw)
    si.setMotionValidator(validator)
    si.setup()
    return space, si, validator


def _state(space, q: np.ndarray):
    state = space.allocState()
    for i in range(6):
        state[i] = float(q[i])
    return state


def _reseed(seed: int) -> None:
    """Seed OMPL's generator of seeds: every generator made after this (the planner's
    sampler, its nearest-neighbour structure, the simplifier's) draws from it. OMPL logs an
    error when it is seeded again after its first use; a new seed per search is the point."""
    level = ou.getLogLevel()
    ou.setLogLevel(ou.LogLevel.LOG_NONE)
    ou.RNG.setSeed(seed)
    ou.setLogLevel(level)


def _simplify(si, path) -> None:
    """OMPL's shortening: fewer vertices (joins between the path's vertices), shortcuts
    between points on its edges, fewer vertices again."""
    simplifier = og.PathSimplifier(si)
    simplifier.reduceVertices(path)
    simplifier.partialShortcutPath(path)
    simplifier.reduceVertices(path)


def _waypoints(path, q_start: np.ndarray, q_goal: np.ndarray) -> np.ndarray:
    out = np.array([_as_q(path.getState(i)) for i in range(path.getStateCount())])
    out[0], out[-1] = q_start, q_goal
    return out


def ompl_connect(
    q_start: np.ndarray,
    q_goal: np.ndarray,
    checker: CollisionChecker,
    rng: np.random.Generator,
    *,
    max_samples: int = 2000,
    time_budget: float = 60.0,
    search_range: float = OMPL_RANGE,
    **kw,
) -> np.ndarray | None:
    """A clear, shortened joint path (K, 6) rad from q_start to q_goal, or None when RRT-Connect
    found none within `max_samples` samples (or `time_budget` s of wall-clock time).

    rng: draws the search's seed (one draw); kw: `CollisionChecker.clearance_ok`'s options
    (hand, seen, payload), for states and edges alike. Both ends must be clear (the caller
    checks): OMPL reports an invalid start or goal as no path.
    """
    _reseed(int(rng.integers(1, _SEED_BOUND)))
    lo, hi = search_bounds(np.asarray(q_start, float), np.asarray(q_goal, float))
    space, si, validator = _space(lo, hi, checker, kw)
    problem = ob.ProblemDefinition(si)
    problem.setStartAndGoalStates(_state(space, q_start), _state(space, q_goal))
    planner = og.RRTConnect(si)
    planner.setRange(search_range)
    planner.setProblemDefinition(problem)
    planner.setup()
    samples, deadline = [0], time.monotonic() + time_budget

    def spent() -> bool:  # evaluated once a sample
        samples[0] += 1
        return samples[0] > max_samples or time.monotonic() > deadline

    status = planner.solve(ob.PlannerTerminationCondition(spent))
    if status.getStatus() != ob.PlannerStatus.EXACT_SOLUTION:
        return None
    found = problem.getSolutionPath()
    path = og.PathGeometric(found)
    _simplify(si, path)
    # A shortcut from a point inside an edge leaves the rest of that edge, which the checker
    # saw only at the edge's own steps: checked at its own, it may touch. The path as found
    # was checked edge by edge as it stands.
    for candidate in (path, found):
        out = _waypoints(candidate, q_start, q_goal)
        if all(validator.ok(a, b) for a, b in itertools.pairwise(out)):
            return out
    return None
