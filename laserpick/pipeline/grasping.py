"""From a perceived target to ordered, reachable grasps (004 sections 6.2 and 7), by one of
three strategies:

- "gpd": GPD-style 6-DOF candidates on the target, checked against the whole cloud (004);
  when none of them is reachable, again on the target with its unseen back filled in by
  symmetry; when still none is, the "vertical" grasp instead; when that is not reachable
  either, GPD again with the hand tilted about its closing axis.
- "overhead": EL-E's single overhead grasp from the target's 2D occupancy (000 section 4.4).
- "vertical": a top-down grasp across the narrow side of the target's top, as Jeeves takes
  once its base has centred the object (003 section IV).

Every candidate then goes through the reachability filter, is scored with 004's objective and
clustered by position. Each stage is timed. Frames: `base`, metres, radians.
"""

from __future__ import annotations

import functools
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from scipy.spatial import cKDTree

from laserpick.description.dims import (
    ARM_MOUNT_POS,
    GRIPPER_HAND,
    UR5_HIGH_READY_Q,
    UR5_HOME_Q,
    UR5_READY_Q,
    UR5_UNSTOW_Q,
)
from laserpick.pipeline.collision import (
    CARRIED_VOXEL,
    SEEN_TOLERANCE,
    CollisionChecker,
    carried_shape,
    mirrored_back,
    object_middle,
)
from laserpick.pipeline.free_space import beyond_view, fingers_seen_free
from laserpick.pipeline.gpd import detect_grasps
from laserpick.pipeline.overhead import overhead_grasp
from laserpick.pipeline.perceive import Perception
from laserpick.pipeline.plan import PickPlan, Searches, plan_pick
from laserpick.pipeline.reach import reachable
from laserpick.pipeline.recall import Recalled
from laserpick.pipeline.selection import GraspClusters, group, score
from laserpick.pipeline.surface import surface_height
from laserpick.settings import MotionSettings, Settings, get_settings
from laserpick.types import Failure, Grasp

Strategy = Literal["gpd", "overhead", "vertical"]
VERTICAL_BITE = 0.02  #: m the fingertips of a vertical grasp reach below the object's top
VERTICAL_FLOOR_GAP = 0.003  #: m they stay above the support surface
VERTICAL_CAP = 0.005  #: m below the top that a vertical grasp counts as the object's top face
VERTICAL_TOP_POINTS = 30  #: points needed to place a vertical grasp by its band or top face
#: Fewest other target points within a grid cell of a point that stands above the surface
#: for EL-E's grasp to count it as the object's: the table's speckle stands alone. Ours.
SPECKLE_NEIGHBOURS = 3
STRATEGIES: tuple[Strategy, ...] = ("gpd", "overhead", "vertical")
READY_TOLERANCE = 0.05  #: rad: the arm counts as at the ready (or stowed) pose within this
#: Said after a pick's planning failure when some way to its grasps passed only through space
#: no camera saw: the arm keeps to seen space, so the user knows why it did not go.
UNSEEN_WAYS = (
    "; the only ways found pass where the cameras could not see, and the arm keeps to where"
    " they saw"
)
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
        lowest = float(self.target[:, 2].min())
        return lowest if self.support is None else min(self.support, lowest)

    @functools.cached_property
    def carried(self) -> np.ndarray:
        """The points (m, `base`) that stand for the target in the hand (`carried_shape`):
        worked out once, for the planner's lift and for the pick (5-12 ms)."""
        return carried_shape(np.vstack([self.target, self.cut_off]), self.stands_on)

    @functools.cached_property
    def carried_as_seen(self) -> np.ndarray:
        """`carried` without `cut_off`: the target as the cameras saw it (m, `base`). The
        same points as `carried` where the view cut nothing off (most targets), so not
        worked out twice then."""
        if not len(self.cut_off):
            return self.carried
        return carried_shape(self.target, self.stands_on)

    @functools.cached_property
    def middle(self) -> np.ndarray:
        """The target's middle (m, `base`), which a place turns it about (`object_middle`), as
        the cameras saw it: not the part `cut_off` stands in for."""
        return object_middle(self.target, self.carried_as_seen)


def vertical_grasp(
    target: np.ndarray, support: float | None, settings: Settings
) -> Grasp | Failure:
    """A top-down grasp on the target's top band, closing across its narrow side, the pads
    reaching 2 cm below the top but stopping 3 mm above the support surface at `support`
    (m). The hand is centred on the band's extent across, which must leave the open fingers
    side_clearance on each side, and along it on the middle of the object's top face.

    The band is the target's points within VERTICAL_BITE of its top, where the fingers go,
    when the cameras see enough of it; the top face, those within VERTICAL_CAP. The cameras
    look down on the object from the front and see its top whole; they see less of its sides
    and back, and the mean of all its points lies toward them (a mug's, 1.5 cm: its far rim
    then met the far finger).
    """
    top = float(target[:, 2].max())
    band = target[target[:, 2] > top - VERTICAL_BITE]
    band = band if len(band) >= VERTICAL_TOP_POINTS else target
    cap = target[target[:, 2] > top - VERTICAL_CAP]
    centre = (cap if len(cap) >= VERTICAL_TOP_POINTS else band).mean(axis=0)
    xy = band[:, :2] - centre[:2]
    _, vecs = np.linalg.eigh(np.cov(xy.T) if len(xy) > 2 else np.eye(2))
    closing = np.append(vecs[:, 0], 0.0)
    across = xy @ vecs[:, 0]
    # Robust extent: a few stray points (a shadow's edge, the table's rim) do not widen it.
    lo, hi = np.percentile(across, [0.5, 99.5])
    width = float(hi - lo)
    if width > GRIPPER_HAND.width_max - 2 * settings.grasp.side_clearance:
        return Failure("detect_grasp", "The object is wider than the gripper opens.")
    middle = centre + 0.5 * (lo + hi) * closing
    approach = np.array([0.0, 0.0, -1.0])
    pose = np.eye(4)
    pose[:3, 0] = np.cross(closing, approach)
    pose[:3, 1] = closing
    pose[:3, 2] = approach
    tips = top - VERTICAL_BITE
    if support is not None:
        tips = max(tips, support + VERTICAL_FLOOR_GAP)
    pose[:3, 3] = [middle[0], middle[1], tips + GRIPPER_HAND.pad_depth / 2]
    return Grasp(pose=pose, width=width)


def _above_surface(
    points: np.ndarray, target: np.ndarray, mark: np.ndarray, settings: Settings
) -> np.ndarray:
    """The `target` points (m, `base`) that stand above the surface at the `mark`: EL-E
    grasps what its segmentation left once the surface's points were gone (000 section
    4.2.2), so its overhead grasp takes the target's points over the top of the surface's
    height histogram in the VOI (`surface_height`), by one grid layer, as `segment`'s grid
    does, less the surface's speckle (under SPECKLE_NEIGHBOURS others within a grid cell).
    004's 10 cm fallback ball about an 8 mm pill held 12,000 table points; the 24 of them
    left above the surface were scattered over the ball, and the raised-point rule chose
    one, 7 cm from the pill. The whole target where no surface is seen."""
    s = settings.perception
    z_top = surface_height(points, s, center=mark)
    if z_top is None:
        return target
    above = target[target[:, 2] > z_top + s.grid_surface_margin]
    if len(above) == 0:
        return above
    near = cKDTree(above).query_ball_point(above, s.grid_cell_xy, return_length=True)
    return above[near > SPECKLE_NEIGHBOURS]  # each point counts itself


def candidates(
    perception: Perception,
    strategy: Strategy,
    settings: Settings,
    rng: np.random.Generator,
    *,
    complete: bool = False,
    tilted: bool = False,
) -> list[Grasp] | Failure:
    """Raw grasp candidates on the perceived target. complete: for "gpd", add the target's
    back as `mirrored_back` guesses it (to the target and to the obstacles). tilted: for
    "gpd", the hand tilted about its closing axis by `gpd_tilts_deg` instead of untilted.
    GPD's are only those whose fingers go where the cameras saw free space
    (`fingers_seen_free`): its collision test knows only the seen surfaces."""
    cloud, seg = perception.cloud, perception.segmentation
    assert seg is not None
    target = cloud.points[seg.indices].astype(np.float64)
    if strategy == "gpd":
        normals, scene = cloud.normals[seg.indices], cloud.points
        guessed = None
        if complete:
            back, back_normals = mirrored_back(target, normals)
            guessed = np.r_[np.zeros(len(target), bool), np.ones(len(back), bool)]
            target, normals = np.vstack([target, back]), np.vstack([normals, back_normals])
            scene = np.vstack([scene, back])
        tilts = tuple(np.radians(settings.grasp.gpd_tilts_deg)) if tilted else (0.0,)
        found = detect_grasps(
            target, normals, scene, settings.grasp, rng=rng, tilts=tilts, guessed=guessed
        )
        seen = fingers_seen_free(found, perception.frames, settings.grasp)
        return [g for g, ok in zip(found, seen, strict=True) if ok]
    support = seg.surface.height if seg.surface is not None else None
    if strategy == "overhead":
        floor = support if support is not None else float(target[:, 2].min())
        assert perception.mark is not None  # segmented: there is a mark
        target = _above_surface(cloud.points, target, perception.mark.point, settings)
        if len(target) == 0:
            return Failure("detect_grasp", "Nothing stands above the surface at the mark.")
        g = overhead_grasp(target, cloud.points, floor, ARM_MOUNT_POS[:2])
    else:
        g = vertical_grasp(target, support, settings)
    return g if isinstance(g, Failure) else [g]


def at_pose(q: np.ndarray | None, pose: np.ndarray) -> bool:
    """Whether joint angles q (6,) (rad) are at `pose` (6,), within READY_TOLERANCE."""
    return q is not None and bool(np.max(np.abs(q - pose)) < READY_TOLERANCE)


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
    timings: dict[str, float] = {}
    cloud, seg = perception.cloud, perception.segmentation
    target = cloud.points[seg.indices].astype(np.float64)
    approach, lift = s.motion.approach_distance, s.motion.lift_least

    t0 = time.perf_counter()
    found = candidates(perception, strategy, s, rng)
    timings["detect"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    recalled = recalled or Recalled()
    support = seg.surface.height if seg.surface is not None else None
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
    checked = [] if isinstance(found, Failure) else reachable(found, world, q_ref, approach, lift)
    timings["filter"] = time.perf_counter() - t0

    def add(
        kind: Strategy, complete: bool = False, tilted: bool = False, most: int | None = None
    ) -> bool:
        """Detect `kind` candidates and filter them (at most `most`, evenly sampled) into
        `checked`, timed. False when the detection failed."""
        t0 = time.perf_counter()
        more = candidates(perception, kind, s, rng, complete=complete, tilted=tilted)
        timings["detect"] += time.perf_counter() - t0
        if isinstance(more, Failure):
            return False
        t0 = time.perf_counter()
        step = 1 if most is None else max(1, -(-len(more) // most))
        checked.extend(reachable(more[::step], world, q_ref, approach, lift))
        timings["filter"] += time.perf_counter() - t0
        return True

    def none_reachable() -> bool:
        return not any(g.ik is not None for g in checked)

    gpd = strategy == "gpd"
    if gpd and none_reachable():
        # GPD needs both sides of a grasp in view. Seen from the front only (a tall bottle
        # off to the side has no seen face opposite a seen face), its back is guessed by
        # symmetry, as Bohg et al. complete a partial view, and the detection runs again.
        # A whole object offers many more grasps (800 on a ball) than its seen part, and
        # the filter's time grows with them: an even sample of them is filtered.
        add("gpd", complete=True, most=COMPLETED_MAX)
    # A low, a round or a near object may still offer no reachable candidate, or no room
    # for the hand toward them. The centroid top grasp (Jeeves') is then the fallback. It
    # goes before the tilted pass: it costs a millisecond where the tilted pass costs half a
    # second, and in the open, where nothing is above the object, it is what serves.
    if gpd and none_reachable() and add("vertical") and not none_reachable():
        strategy = "vertical"
    if gpd and s.grasp.gpd_tilts_deg and none_reachable():
        # Under a shelf's board a low object lying pointed at the robot offers only grasps
        # from above, across its girth, and the wrist does not fit above it; from the front
        # and above, with the hand tilted about its closing axis, it does.
        add("gpd", complete=True, tilted=True, most=COMPLETED_MAX)
    if isinstance(found, Failure) and not checked:
        return found
    if not checked:
        return Failure("detect_grasp", "No grasp fits this object.")
    ok = [g for g in checked if g.ik is not None]
    rejected = tuple(g for g in checked if g.ik is None)
    if not ok:
        reason = rejected[0].ik_failure
        return Failure("ik_plan", f"The arm cannot take any of {len(checked)} grasps ({reason}).")

    t0 = time.perf_counter()
    mark = perception.mark.point
    scored = [score(g, q_now=q_ref, sample=target, mark=mark, settings=s.grasp) for g in ok]
    clusters = group(scored, s.grasp)
    timings["select"] = time.perf_counter() - t0
    return GraspSet(
        clusters, rejected, world, surroundings, target, strategy, timings, support, cut_off
    )


def plan_first(
    found: GraspSet,
    q_now: np.ndarray,
    rng: np.random.Generator,
    order: Sequence[Grasp] | None = None,
    settings: MotionSettings | None = None,
) -> tuple[PickPlan | Failure, Grasp | None, int]:
    """Plan the grasps of `order` (default: all, best first) until one plans, as 004 does.

    From anywhere but the ready pose (stowed, mostly) the transit goes through a ready pose;
    from the stowed pose, through the unstow pose first.
    The hand is checked at the grasp only for vertical grasps: GPD and EL-E's sweep tested
    it there already. Returns the plan (or the last failure, which says so when ways
    through space the cameras did not see were left untaken), its grasp and how many grasps
    were tried.
    """
    s = settings or get_settings().motion
    at_ready = at_pose(q_now, UR5_READY_Q)
    via = () if at_ready else (UR5_READY_Q, UR5_HIGH_READY_Q)
    stowed = at_pose(q_now, UR5_HOME_Q)
    plan: PickPlan | Failure = Failure("ik_plan", "There is no grasp to plan for.")
    searches = Searches(s.rrt_max_failed)
    carried = found.carried
    tried = 0
    for grasp in found.ordered() if order is None else order:
        tried += 1
        if grasp.ik is None:
            raise ValueError("plan_first needs grasps from the reachability filter")
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
            unstow=UR5_UNSTOW_Q if stowed else None,
            payload=grasp.in_hand(carried),
        )
        if not isinstance(plan, Failure):
            return plan, grasp, tried
        if searches.spent:
            msg = f"No collision-free path in {searches.failed} searches; no more were tried"
            plan = Failure("ik_plan", msg)
            break
    if isinstance(plan, Failure) and searches.unseen_only(s):
        plan = Failure("ik_plan", f"{plan.message.rstrip('.')}{UNSEEN_WAYS}")
    return plan, None, tried
