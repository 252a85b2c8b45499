"""Our joint-space search, the default: RRT-Connect (Kuffner and LaValle 2000) with random
shortcuts, beside OMPL's (`ompl_search`; `bench/planners.py` compares the two), and the box
of joint angles both draw their samples from. A search of ours that found no way can be
grown on (`ConnectSearch`).

Frames: joint angles in rad.
"""

from __future__ import annotations

import math

import numpy as np

from laserpick.description import dims
from laserpick.pipeline.collision import CollisionChecker

__all__ = ["ConnectSearch", "rrt_connect", "search_bounds", "shortcut"]

#: A tree that meets this many blocked steps before it has POCKET_NODES nodes grows from a
#: pocket, and steps POCKET_STEP of the full step while it is that small: a tall box held
#: low in the basket meets a wall with almost every full step (0 or 1 of 64 directions
#: clear). Replayed (`bench/planners.py --full-steps`, two runs each), the 42 searches
#: recorded in `isolation` seeds 3 and 8, 19 of them a cereal box's carries, were found in
#: 71 of 84 runs against 60, with 29 % less CPU (docs/pipeline.md).
POCKET_TRAPS = 20
POCKET_NODES = 30
POCKET_STEP = 0.25


def search_bounds(q_start: np.ndarray, q_goal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The box (lo, hi) (6,) rad that samples are drawn from: the joint limits, within a half
    turn of the box around the start and the goal, or goals (k, 6) (a way around an obstacle
    needs no more)."""
    ends = np.vstack([q_start, q_goal])
    lo = np.maximum(dims.UR5_Q_MIN, ends.min(axis=0) - math.pi)
    hi = np.minimum(dims.UR5_Q_MAX, ends.max(axis=0) + math.pi)
    return lo, hi


def shortcut(
    path: np.ndarray, checker: CollisionChecker, rng: np.random.Generator, tries: int = 60, **kw
) -> np.ndarray:
    """Shorten a joint path by joining random pairs of its points where the join is clear.

    A join found blocked is not checked again; the search ends early when every join left
    has been."""
    points = [np.asarray(q) for q in path]
    keep = list(range(len(points)))  # indices into `points` of the path so far
    blocked: set[tuple[int, int]] = set()
    for _ in range(tries):
        if len(keep) < 3:
            break
        joins = (len(keep) - 1) * (len(keep) - 2) // 2  # pairs with a point between them
        on_path = set(keep)
        if sum(a in on_path and b in on_path for a, b in blocked) >= joins:
            break
        i, j = sorted(rng.choice(len(keep), size=2, replace=False))
        pair = (keep[i], keep[j])
        if j - i < 2 or pair in blocked:
            continue
        if checker.segment_ok(points[pair[0]], points[pair[1]], **kw):
            keep = keep[: i + 1] + keep[j:]
        else:
            blocked.add(pair)
    return np.array([points[k] for k in keep])


class _Tree:
    """One tree of the search, or a forest of trees grown together: its nodes (rad), each
    one's parent (-1: a root), and how many of its steps were blocked."""

    def __init__(self, roots: np.ndarray) -> None:
        self.nodes = list(np.atleast_2d(roots))
        self.parents = [-1] * len(self.nodes)
        self.blocked = 0

    def in_pocket(self, traps: int | None) -> bool:
        """Whether it is still under POCKET_NODES nodes after `traps` blocked steps (None:
        never)."""
        return traps is not None and len(self.nodes) < POCKET_NODES and self.blocked >= traps

    def branch(self, index: int) -> list[np.ndarray]:
        """The nodes from node `index` back to the root."""
        out = []
        while index >= 0:
            out.append(self.nodes[index])
            index = self.parents[index]
        return out


def rrt_connect(
    q_start: np.ndarray,
    q_goal: np.ndarray,
    checker: CollisionChecker,
    rng: np.random.Generator,
    *,
    step: float = 0.3,
    max_samples: int = 2000,
    pocket_traps: int | None = POCKET_TRAPS,
    **kw,
) -> np.ndarray | None:
    """A clear joint path (K, 6) from q_start to q_goal, or None after `max_samples` samples:
    `ConnectSearch` grown once."""
    search = ConnectSearch(
        q_start, q_goal, checker, rng, step=step, pocket_traps=pocket_traps, **kw
    )
    return search.grow(max_samples)


class ConnectSearch:
    """RRT-Connect from q_start to q_goal, which can be grown on where it found no way yet.

    Two trees grow toward random samples within the joint limits and toward each other, in
    steps of at most `step` rad (largest joint); each new edge is collision-checked with
    `checker` (its options `kw`). A tree still small after `pocket_traps` blocked steps takes
    shorter ones (POCKET_TRAPS; None: never). q_goal (k, 6) gives k goals: the goal side
    grows from all of them at once, and the path ends at the one it reached first. Its draws
    come from `rng`, as it grows: grown to N samples in one go or in several, it draws and
    finds the same.
    """

    def __init__(
        self,
        q_start: np.ndarray,
        q_goal: np.ndarray,
        checker: CollisionChecker,
        rng: np.random.Generator,
        *,
        step: float = 0.3,
        pocket_traps: int | None = POCKET_TRAPS,
        **kw,
    ) -> None:
        self.start = np.asarray(q_start, float)
        self.goals = np.atleast_2d(np.asarray(q_goal, float))
        self.checker, self.rng, self.kw = checker, rng, kw
        self.step, self.pocket_traps = step, pocket_traps
        self.bounds = search_bounds(self.start, self.goals)
        #: the tree that grows toward the next sample first; they swap after every sample
        self.trees = [_Tree(self.start), _Tree(self.goals)]
        #: samples drawn so far
        self.samples = 0

    def grow(self, max_samples: int) -> np.ndarray | None:
        """Draw samples until the trees meet, or `max_samples` have been drawn in all: the
        path (K, 6) rad from the start to the goal it reached, or None."""
        trees = self.trees
        while self.samples < max_samples:
            self.samples += 1
            status, a = self._extend(trees[0], self.rng.uniform(*self.bounds))
            if status != "trapped":
                q_new = trees[0].nodes[a]
                while True:  # connect: the other tree steps toward q_new until blocked or there
                    status, b = self._extend(trees[1], q_new)
                    if status != "advanced":
                        break
                if status == "reached":
                    path = trees[0].branch(a)[::-1] + trees[1].branch(b)[1:]
                    if not np.array_equal(path[0], self.start):  # swapped an odd time
                        path = path[::-1]
                    return np.array(path)
            trees.reverse()
        return None

    def _extend(self, tree: _Tree, target: np.ndarray) -> tuple[str, int]:
        """Step `tree` from its node nearest `target` toward it: "reached", "advanced" or
        "trapped" (the step was blocked), and the node it ends at."""
        nodes = tree.nodes
        near = int(np.argmin(np.max(np.abs(np.array(nodes) - target), axis=1)))
        delta = target - nodes[near]
        span = float(np.max(np.abs(delta)))
        reach = self.step * POCKET_STEP if tree.in_pocket(self.pocket_traps) else self.step
        reached = span <= reach
        q_new = target if reached else nodes[near] + delta * (reach / span)
        if not self.checker.segment_ok(nodes[near], q_new, **self.kw):
            tree.blocked += 1
            return "trapped", near
        nodes.append(q_new)
        tree.parents.append(near)
        return ("reached" if reached else "advanced"), len(nodes) - 1
