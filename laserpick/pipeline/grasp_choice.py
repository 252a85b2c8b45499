"""From a perceived target to ordered, reachable grasps (004 sections 6.2 and 7); the first
of them that plans is `first_plan`'s.

The strategy's candidates (`strategies`) go through the reachability filter, are scored with
004's objective and clustered by position. When GPD's candidates offer no reachable grasp,
it tries again on the target with its unseen back filled in by symmetry; when still none is
reachable, the "vertical" grasp instead; when that is not reachable either, GPD again with
the hand tilted about its closing axis. Each stage is timed. Frames: `base`, metres,
radians.
"""

from __future__ import annotations

import functools
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from laserpick.pipeline.balance import holds_across_middle
from laserpick.pipeline.collision import (
    CARRIED_VOXEL,
    SEEN_TOLERANCE,
    CollisionChecker,
    carried_shape,
    object_middle,
)
from laserpick.pipeline.free_space import beyond_view
from laserpick.pipeline.parking_advice import back_up_advice
from laserpick.pipeline.perceive import Perception
from laserpick.pipeline.reach import reachable
from laserpick.pipeline.recall import Recalled
from laserpick.pipeline.selection import GraspClusters, group, score
from laserpick.pipeline.strategies import STRATEGIES, Strategy, candidates
from laserpick.settings import Settings, get_settings
from laserpick.types import Failure, Grasp

COMPLETED_MAX = 120  #: candidates on a target completed by symmetry that are filtered, at most
TARGET_VOXEL = 0.01  #: m: the target's whole shape, as recalled views are checked against it


@dataclass(frozen=True)
class GraspSet:
    """The grasps for one target.

    clusters: the reachable grasps, scored and clustered, best first. rejected: the
    candidates the filter dropped, each with its `ik_failure`. world: collision model of the
    whole cloud; surroundings: of the cloud without the target (the hand may touch it).
    timings: seconds per stage: "detect", "filter", "select". cut_off: points (m, `base`)
    that stand for the part of the target the cameras' view cut off (`beyond_view`).
    """

    clusters: GraspClusters
    rejected: tuple[Grasp, ...]
    world: CollisionChecker
    surroundings: CollisionChecker
    target: np.ndarray
    strategy: Strategy
    timings: dict[str, float] = field(default_factory=dict)
    #: Height (m, `base`) of the surface the target stands on; None when none was found.
    support: float | None = None
    cut_off: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    #: `carried_as_seen` where the caller worked it out already (None: worked out here).
    as_seen: np.ndarray | None = None

    def ordered(self) -> list[Grasp]:
        """Every reachable grasp, best cluster first and best first within each (004's order
        of trying them)."""
        g = self.clusters.grasps
        return [g[i] for members in self.clusters.clusters for i in members]

    @property
    def stands_on(self) -> float:
        """Height (m, `base`) the target stands on, as a carry takes it: the surface it was
        seen on, or its lowest seen point where that is lower or no surface was found (an
        object seen only from above a table's edge)."""
        return resting_height(self.target, self.support)

    @functools.cached_property
    def carried(self) -> np.ndarray:
        """The points (m, `base`) that stand for the target in the hand (`carried_shape`):
        worked out once, for the planner's lift and for the pick (5-12 ms)."""
        if not len(self.cut_off):
            return self.carried_as_seen
        return carried_shape(np.vstack([self.target, self.cut_off]), self.stands_on)

    @functools.cached_property
    def carried_as_seen(self) -> np.ndarray:
        """`carried` without `cut_off`: the target as the cameras saw it (m, `base`). The
        same points as `carried` where the view cut nothing off (most targets), so not
        worked out twice then."""
        if self.as_seen is not None:
            return self.as_seen
        return carried_shape(self.target, self.stands_on)

    @functools.cached_property
    def middle(self) -> np.ndarray:
        """The target's middle (m, `base`), which a place turns it about (`object_middle`), as
        the cameras saw it: not the part `cut_off` stands in for."""
        return object_middle(self.target, self.carried_as_seen)


def find_grasps(
    perception: Perception,
    q_ref: np.ndarray,
    *,
    q_capture: np.ndarray | None = None,
    strategy: Strategy = "gpd",
    settings: Settings | None = None,
    rng: np.random.Generator | None = None,
    recalled: Recalled | None = None,
) -> GraspSet | Failure:
    """Detect, filter, score and cluster grasps on the target of a successful perception.

    q_ref (6,) rad: the arm's configuration when the grasp motion starts (Cj's origin and the
    IK branch preference). q_capture (6,) rad: the arm's joint angles when the frames were
    captured; the arm's own points are then left out of the obstacles, and the space they
    filled counts as seen. recalled: the views kept on the way in (`recall.ViewMemory`):
    the planner counts what they saw through as seen too, and what they saw where no camera
    sees now as obstacles.
    """
    s = settings or get_settings()
    if not perception.ok or perception.segmentation is None or perception.mark is None:
        return perception.failure or Failure("detect_laser", "There is no target to grasp.")
    if strategy not in STRATEGIES:
        raise ValueError(f"unknown grasp strategy {strategy!r}; use one of {STRATEGIES}")
    rng = rng if rng is not None else np.random.default_rng(0)
    seg = perception.segmentation
    target = perception.cloud.points[seg.indices].astype(np.float64)
    support = seg.surface.height if seg.surface is not None else None
    timings = {"detect": 0.0, "filter": 0.0}
    as_seen = carried_shape(target, resting_height(target, support))
    middle = object_middle(target, as_seen)

    t0 = time.perf_counter()
    found = candidates(perception, strategy, s, rng)
    timings["detect"] += time.perf_counter() - t0
    t0 = time.perf_counter()
    world, surroundings, cut_off = collision_models(
        perception, target, support, recalled or Recalled(), q_capture, s
    )
    pool = FilteredCandidates(perception, q_ref, s, rng, world, timings, middle)
    pool.checked = [] if isinstance(found, Failure) else pool.reachable(found)
    timings["filter"] += time.perf_counter() - t0
    strategy = pool.fall_back(strategy)
    checked = pool.checked
    if isinstance(found, Failure) and not checked:
        return found
    if not checked:
        return Failure("detect_grasp", "No grasp fits this object.")
    ok = [g for g in checked if g.ik is not None]
    rejected = tuple(g for g in checked if g.ik is None)
    if not ok:
        t0 = time.perf_counter()
        back = back_up_advice(checked, world, q_ref, s.motion)
        timings["filter"] += time.perf_counter() - t0
        return unreachable(len(checked), rejected[0].ik_failure, back)

    t0 = time.perf_counter()
    mark = perception.mark.point
    scored = [score(g, q_now=q_ref, sample=target, mark=mark, settings=s.grasp) for g in ok]
    clusters = group(scored, s.grasp, middle)
    timings["select"] = time.perf_counter() - t0
    return GraspSet(
        clusters,
        rejected,
        world,
        surroundings,
        target,
        strategy,
        timings,
        support,
        cut_off,
        as_seen,
    )


def resting_height(target: np.ndarray, support: float | None) -> float:
    """Height (m, `base`) a target (N, 3; m, `base`) stands on: the `support` surface it was
    seen on, or its lowest point where that is lower or no surface was found (an object seen
    only from above a table's edge)."""
    lowest = float(target[:, 2].min())
    return lowest if support is None else min(support, lowest)


def unreachable(grasps: int, reason: str | None, back: float | None) -> Failure:
    """Why none of `grasps` grasps can be taken (`reason`, the first one's), and, where
    backing up `back` (m) would let the arm take one, that the user should."""
    msg = f"The arm cannot take any of {grasps} grasps ({reason})."
    if back is not None:
        msg += f" Back up about {round(back * 100)} cm and mark it again: from there it can."
    return Failure("ik_plan", msg, back_up=back)


def collision_models(
    perception: Perception,
    target: np.ndarray,
    support: float | None,
    recalled: Recalled,
    q_capture: np.ndarray | None,
    s: Settings,
) -> tuple[CollisionChecker, CollisionChecker, np.ndarray]:
    """The collision models a pick's grasps are filtered and planned with: of the whole
    cloud (the world) and of the cloud without the target (its surroundings), and the
    points that stand for the part of the `target` (m, `base`) the cameras' view cut off
    (`beyond_view`). What the `recalled` views saw through counts as seen, and what they saw
    where no camera sees now is an obstacle, but not where the target's whole shape is."""
    cloud, seg = perception.cloud, perception.segmentation
    assert seg is not None
    cut_off = beyond_view(
        target, perception.frames, CARRIED_VOXEL, SEEN_TOLERANCE, support, recalled.frames
    )
    blind = recalled.points
    if len(blind):
        # The views saw the target from elsewhere: what they saw of it that is hidden now
        # is the target, not an obstacle beside it. Its extent is the carry's model of it.
        whole = carried_shape(np.vstack([target, cut_off]), support, voxel=TARGET_VOXEL)
        blind = recalled.blind_points(perception.frames, whole, support)
    world, surroundings = CollisionChecker.world_and_surroundings(
        np.vstack([cloud.points, blind]) if len(blind) else cloud.points,
        seg.indices,
        margin=s.motion.clearance,
        q_self=q_capture,
        frames=(*perception.frames, *recalled.frames),
    )
    return world, surroundings, cut_off


@dataclass
class FilteredCandidates:
    """One target's grasp candidates so far, each through the reachability filter against
    `world` from q_ref (6,) rad (`checked`), and the seconds spent detecting and filtering
    them (`timings`: "detect", "filter"). middle: the target's middle (m, `base`;
    `GraspSet.middle`), which a grasp should hold it across (`holds_across_middle`)."""

    perception: Perception
    q_ref: np.ndarray
    settings: Settings
    rng: np.random.Generator
    world: CollisionChecker
    timings: dict[str, float]
    middle: np.ndarray | None = None
    checked: list[Grasp] = field(default_factory=list)

    def reachable(self, grasps: Sequence[Grasp]) -> list[Grasp]:
        """`grasps` through the reachability filter (`reach.reachable`)."""
        m = self.settings.motion
        return reachable(grasps, self.world, self.q_ref, m.approach_distance, m.lift_least)

    def add(
        self, kind: Strategy, complete: bool = False, tilted: bool = False, most: int | None = None
    ) -> bool:
        """Detect `kind` candidates (`strategies.candidates`) and filter them (at most
        `most`, evenly sampled) into `checked`, timed. False when the detection failed."""
        t0 = time.perf_counter()
        more = candidates(
            self.perception, kind, self.settings, self.rng, complete=complete, tilted=tilted
        )
        self.timings["detect"] += time.perf_counter() - t0
        if isinstance(more, Failure):
            return False
        t0 = time.perf_counter()
        step = 1 if most is None else max(1, -(-len(more) // most))
        self.checked.extend(self.reachable(more[::step]))
        self.timings["filter"] += time.perf_counter() - t0
        return True

    def none_reachable(self) -> bool:
        """Whether no grasp checked so far is reachable."""
        return not any(g.ik is not None for g in self.checked)

    def none_across_middle(self) -> bool:
        """Whether no grasp checked so far is reachable and holds the target across its
        middle (`holds_across_middle`)."""
        limit = self.settings.grasp.balance_lever
        return not any(
            g.ik is not None and holds_across_middle(g.pose, self.middle, limit)
            for g in self.checked
        )

    def fall_back(self, strategy: Strategy) -> Strategy:
        """For "gpd" with no reachable grasp, the other passes, in order, while none is:
        completed by symmetry, vertical, tilted; the first of them also where no reachable
        grasp holds the target across its middle. The strategy the grasps are then from
        ("vertical" when that pass gave the reachable ones)."""
        gpd = strategy == "gpd"
        if gpd and self.none_across_middle():
            # GPD needs both sides of a grasp in view. Seen from the front only (a tall bottle
            # off to the side has no seen face opposite a seen face), its back is guessed by
            # symmetry, as Bohg et al. complete a partial view, and the detection runs again.
            # A remote lying flat whose far side the cameras barely see offers GPD a grasp
            # only at its near end, 8 cm off its middle, where it turns in the pads and
            # falls; completed, 10-16 of its 45 grasps hold it across the middle.
            # A whole object offers many more grasps (800 on a ball) than its seen part, and
            # the filter's time grows with them: an even sample of them is filtered.
            self.add("gpd", complete=True, most=COMPLETED_MAX)
        # A low, a round or a near object may still offer no reachable candidate, or no room
        # for the hand toward them. The centroid top grasp (Jeeves') is then the fallback. It
        # goes before the tilted pass: it costs a millisecond where the tilted pass costs half
        # a second, and in the open, where nothing is above the object, it is what serves.
        if gpd and self.none_reachable() and self.add("vertical") and not self.none_reachable():
            strategy = "vertical"
        if gpd and self.settings.grasp.gpd_tilts_deg and self.none_reachable():
            # Under a shelf's board a low object lying pointed at the robot offers only grasps
            # from above, across its girth, and the wrist does not fit above it; from the
            # front and above, with the hand tilted about its closing axis, it does.
            self.add("gpd", complete=True, tilted=True, most=COMPLETED_MAX)
        return strategy
