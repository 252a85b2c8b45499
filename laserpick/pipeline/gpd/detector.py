"""The detector: sample the target, build a local frame at each sample, rotate and slide
the hand there, push it in until just before contact, and keep the collision-free hands
whose pads close antipodally on the object; then move the hands that are not centred onto
their patches, turn those whose pads meet the object's faces at a slant square to them, and
test them again. Frames: `base` (x forward, y left, z up), metres.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
from scipy.spatial import cKDTree

from laserpick.description.dims import GRIPPER_HAND, HandGeometry
from laserpick.pipeline.gpd.antipodal import antipodal_possible, closing_region, pad_pairs
from laserpick.pipeline.gpd.candidates import HandCandidates
from laserpick.pipeline.gpd.closing_grid import ClosingGrid, middle_placement
from laserpick.pipeline.gpd.frames import (
    local_frames,
    orientation_angles,
    sample_indices,
    tilted_frames,
)
from laserpick.pipeline.gpd.hand import cleared_hand, grasp_poses, hand_regions
from laserpick.pipeline.gpd.neighbourhoods import VoxelGroups, collision_cloud
from laserpick.pipeline.gpd.recentre import patch_moves
from laserpick.pipeline.gpd.square import square_turns, turned_frames
from laserpick.pipeline.gpd.voxel_pruning import COLLISION_VOXEL, CoarsePairs, pruned_tips
from laserpick.settings import GraspSettings, get_settings
from laserpick.types import Grasp


def detect_grasps(
    target: np.ndarray,
    target_normals: np.ndarray,
    scene: np.ndarray,
    settings: GraspSettings | None = None,
    rng: np.random.Generator | None = None,
    timings: dict[str, float] | None = None,
    tilts: tuple[float, ...] = (0.0,),
    guessed: np.ndarray | None = None,
) -> list[Grasp]:
    """Grasp candidates on `target` that keep side_clearance from `scene` (cleared_hand).

    target: (M, 3) the segmented object's points in `base` (m); target_normals: (M, 3) their
    unit normals, pointing outward (toward the sensors). scene: (N, 3) the full cloud in
    `base`, table included; the target's own points are added to it for collisions. rng seeds
    the sampling: the same seed gives the same grasps. Returns grasps with pose (TCP in
    `base`; columns hand axis, closing axis, approach) and width (m), in sample order, then
    the hands moved onto their patches (`CandidateSearch.recentred`). timings, if given,
    receives the seconds spent in each stage (bench/grasp_detect_speed.py; the later passes
    add to the first's stages). Each hand whose pads meet the object's faces at a slant
    about its approach is replaced by the hand turned square to them, where that one passes
    (`CandidateSearch.squared`). tilts (rad): each sample's frame is tried turned about its
    closing axis by each of these (`tilted_frames`); the default, no tilt, is GPD's.
    guessed: (M,) bool, the target points that were guessed (`mirrored_back`) rather than
    seen; see `guesses_face_seen`.
    """
    lap = StageTimer(timings)
    s = settings or get_settings().grasp
    hand = cleared_hand(GRIPPER_HAND, s.side_clearance)
    rng = rng if rng is not None else np.random.default_rng(0)
    target = np.asarray(target, np.float64).reshape(-1, 3)
    if len(target) < 3:
        return []
    normals = np.asarray(target_normals, np.float64).reshape(-1, 3)
    # Work relative to the target's centre: float32 keeps sub-micron precision there.
    centre = 0.5 * (target.min(axis=0) + target.max(axis=0))
    tgt = target - centre
    tree = cKDTree(tgt)

    idx = sample_indices(len(tgt), s.gpd_samples, rng)
    samples = tgt[idx]
    normal, axis = local_frames(tgt, normals, idx, s, tree)
    if tilts != (0.0,):
        normal, axis = tilted_frames(normal, axis, np.asarray(tilts, np.float64))
        samples = np.tile(samples, (len(tilts), 1))
    lap("frames")
    search = CandidateSearch(tgt, normals, scene, centre, tree, hand, s, guessed, lap)
    first = search.candidates(samples, normal, axis)
    passes = (first, search.recentred(first))
    grasps = as_grasps(tuple(search.squared(found) for found in passes), centre)
    if timings is not None:
        timings["total"] = time.perf_counter() - lap.start
    return grasps


class StageTimer:
    """Adds the seconds since its last call (or its making) to `timings[stage]` when called
    with a stage's name; nothing when `timings` is None."""

    def __init__(self, timings: dict[str, float] | None) -> None:
        self.timings = timings
        self.start = self.last = time.perf_counter()

    def __call__(self, stage: str) -> None:
        now = time.perf_counter()
        if self.timings is not None:
            self.timings[stage] = self.timings.get(stage, 0.0) + now - self.last
        self.last = now


def as_grasps(passes: tuple[HandCandidates, ...], centre: np.ndarray) -> list[Grasp]:
    """The candidates of the detector's `passes`, in order, as grasps in `base`: their poses
    are relative to the target's `centre` (m, `base`)."""
    poses = np.vstack([f.poses for f in passes])
    poses[:, :3, 3] += centre
    return [
        Grasp(pose=T, width=float(w), pads_centred=bool(c))
        for T, w, c in zip(
            poses,
            np.concatenate([f.width for f in passes]),
            np.concatenate([f.centred for f in passes]),
            strict=True,
        )
    ]


class CandidateSearch:
    """The detector's passes over frames of one target: its points relative to their centre
    (`tgt`, with their normals and KD-tree), the collision cloud around them (built once, when
    a frame first needs it), the cleared hand `hand` and the settings `s`."""

    def __init__(
        self,
        tgt: np.ndarray,
        normals: np.ndarray,
        scene: np.ndarray,
        centre: np.ndarray,
        tree: cKDTree,
        hand: HandGeometry,
        s: GraspSettings,
        guessed: np.ndarray | None,
        lap: Callable[[str], None],
    ) -> None:
        self.tgt, self.normals, self.tree = tgt, normals, tree
        self.scene, self.centre = scene, centre
        self.hand, self.s, self.guessed, self.lap = hand, s, guessed, lap
        self.angles = orientation_angles(s.gpd_orientations)
        self.grid = ClosingGrid(hand, s)
        self.regions = hand_regions(hand, s)
        self._voxels: VoxelGroups | None = None

    def voxels(self) -> VoxelGroups:
        """The collision cloud (`collision_cloud`), relative to the target's centre, grouped
        into COLLISION_VOXEL voxels for `pruned_tips`: made when a frame first needs it,
        once for all the passes."""
        if self._voxels is None:
            cloud = collision_cloud(
                self.scene, self.centre, self.tgt, self.tree, self.regions, self.s
            )
            self._voxels = VoxelGroups(cloud, COLLISION_VOXEL)
            self.lap("crop")
        return self._voxels

    def candidates(
        self,
        samples: np.ndarray,
        normal: np.ndarray,
        axis: np.ndarray,
        only: np.ndarray | None = None,
    ) -> HandCandidates:
        """The passing candidates of every orientation of the frames at `samples` ((S, 3),
        relative to the target's centre) with those normals and curvature axes; with `only`
        ((S,) orientation indices), of that one orientation of each."""
        hand, s, angles, grid, lap = self.hand, self.s, self.angles, self.grid, self.lap
        # The pads' contents: target points where the pads could be. Most frames cannot pass
        # the antipodal test whatever the hand's depth and offset: they need no collision
        # test.
        tsid, tpid, th, tu, tv, nu, nv = pad_pairs(
            self.tgt, self.normals, samples, normal, axis, hand
        )
        possible = antipodal_possible(tu, tv, nu, nv, tsid, len(samples), angles, grid, hand, s)
        if only is not None:
            possible &= np.arange(len(angles)) == np.asarray(only)[:, None]
        lap("pad_pairs")

        tips = self.deepest_tips(samples, normal, axis, possible)
        has, k = middle_placement(np.isfinite(tips))
        offset = np.where(has, grid.offsets[k], np.nan).astype(np.float32)
        tip = np.where(has, tips[np.arange(len(tips)), k], np.nan).astype(np.float32)
        lap("deepest_tips")

        keep = np.flatnonzero(has.reshape(len(samples), len(angles)).any(axis=1).take(tsid))
        th, tu, tv, nu, nv, tsid, tpid = (x.take(keep) for x in (th, tu, tv, nu, nv, tsid, tpid))
        pair_guessed = None if self.guessed is None else np.asarray(self.guessed, bool).take(tpid)
        width, ok, centred = closing_region(
            th, tu, tv, nu, nv, tsid * len(angles), angles, offset, tip, hand, s, pair_guessed
        )
        lap("closing_region")
        good = np.flatnonzero(ok & has)
        sample, orientation = np.divmod(good, len(angles))
        poses = grasp_poses(samples, normal, axis, angles, good, offset[good], tip[good], hand)
        return HandCandidates(
            samples,
            normal,
            axis,
            angles,
            sample,
            orientation,
            offset[good],
            tip[good],
            width[good],
            centred[good],
            poses,
        )

    def deepest_tips(
        self, samples: np.ndarray, normal: np.ndarray, axis: np.ndarray, possible: np.ndarray
    ) -> np.ndarray:
        """(S * O, K) the deepest collision-free fingertip depth (m; -inf for none) of each
        frame and placement, for the frames `possible` ((S, O) bool) marks; -inf for the
        others. Only the scene points where the hand could be are looked at
        (`pruned_tips`)."""
        angles, grid = self.angles, self.grid
        live = np.flatnonzero(possible.any(axis=1))
        tips = np.full((len(samples), len(angles), len(grid.offsets)), -np.inf, np.float32)
        if len(live):
            pairs = CoarsePairs(
                self.voxels(), samples[live], normal[live], axis[live], self.regions
            )
            self.lap("collision_pairs")
            tips[live] = pruned_tips(
                pairs,
                samples[live],
                normal[live],
                axis[live],
                angles,
                grid,
                self.hand,
                self.s,
                self.regions,
                possible[live],
            )
        return tips.reshape(len(samples) * len(angles), -1)

    def recentred(self, found: HandCandidates) -> HandCandidates:
        """The hands of `found` that are not centred, moved onto their patches
        (`patch_moves`) and tested again from scratch: those that pass and are centred now.
        Ours, beyond GPD (see patch_moves)."""
        off = np.flatnonzero(~found.centred)
        turn, shift = patch_moves(self.tgt, self.normals, self.hand, self.s, found.subset(off))
        moved = np.flatnonzero(np.isfinite(shift))
        self.lap("recentre")
        if not len(moved):
            return found.subset(moved)
        i = found.sample[off[moved]]
        normal, axis = found.normal[i], found.axis[i]
        c, s = np.cos(turn[moved])[:, None], np.sin(turn[moved])[:, None]
        again = self.candidates(
            found.samples[i] + shift[moved, None] * axis,
            c * normal + s * np.cross(axis, normal),  # turns the approach by `turn`
            axis,
            only=found.orientation[off[moved]],
        )
        return again.subset(np.flatnonzero(again.centred))

    def squared(self, found: HandCandidates) -> HandCandidates:
        """`found`, each hand whose pads meet the object's faces at a slant about its
        approach (`square_turns`) replaced by that hand turned square to them and tested
        again from scratch, where it passes, and is centred if the first was. Ours, beyond
        GPD (see square.py)."""
        turn = square_turns(self.tgt, self.normals, self.hand, self.s, found)
        moved = np.flatnonzero(np.isfinite(turn))
        self.lap("square")
        if not len(moved):
            return found
        samples, normal, axis = turned_frames(found.subset(moved), turn[moved])
        again = self.candidates(samples, normal, axis, only=found.orientation[moved])
        keep = np.flatnonzero(again.centred | ~found.centred[moved[again.sample]])
        return found.with_replaced(moved[again.sample[keep]], again, keep)
