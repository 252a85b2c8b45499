"""The grasp detector's shortcuts (`laserpick.pipeline.gpd`) against the direct computations
they stand for: the voxel-pruned collision depths, the antipodal bound, the range maxima, the
voxel groups and the whole detector. Synthetic clouds (`gpd_shapes`); metres."""

from __future__ import annotations

import numpy as np
from gpd_shapes import box, cylinder, noisy, table

from laserpick.description.dims import GRIPPER_HAND
from laserpick.pipeline.gpd import detect_grasps
from laserpick.pipeline.gpd.antipodal import (
    antipodal_possible,
    closing_region,
    pad_pairs,
)
from laserpick.pipeline.gpd.closing_grid import ClosingGrid, deepest_tips, middle_placement
from laserpick.pipeline.gpd.frames import (
    local_frames,
    orientation_angles,
    sample_indices,
)
from laserpick.pipeline.gpd.hand import cleared_hand, grasp_poses, hand_regions
from laserpick.pipeline.gpd.neighbourhoods import VoxelGroups, slab_pairs
from laserpick.pipeline.gpd.voxel_pruning import (
    COLLISION_VOXEL,
    CoarsePairs,
    RangeMax,
    pruned_tips,
)
from laserpick.settings import GraspSettings

S = GraspSettings()
HAND = GRIPPER_HAND


def local_setup(target: np.ndarray, normals: np.ndarray, n_samples: int, seed: int = 1):
    """Samples, their frames, orientations and closing grid, as detect_grasps builds them."""
    idx = sample_indices(len(target), n_samples, np.random.default_rng(seed))
    normal, axis = local_frames(target, normals, idx, S)
    return target[idx], normal, axis, orientation_angles(S.gpd_orientations), ClosingGrid(HAND, S)


def test_pruned_tips_equal_the_direct_computation():
    pts, n = cylinder()
    other, _ = box((0.04, 0.04, 0.10), centre=(0.06, 0.0))
    cloud = np.vstack([table(), other, pts])
    samples, normal, axis, angles, grid = local_setup(pts, noisy(n), 120)
    regions = hand_regions(HAND, S)
    sid, _, h, u, v = slab_pairs(cloud, samples, normal, axis, regions)
    direct = deepest_tips(h, u, v, sid, len(samples), angles, grid, HAND, S)
    want = np.random.default_rng(2).random(direct.shape[:2]) < 0.7
    pairs = CoarsePairs(VoxelGroups(cloud, COLLISION_VOXEL), samples, normal, axis, regions)
    pruned = pruned_tips(pairs, samples, normal, axis, angles, grid, HAND, S, regions, want)
    free = np.isfinite(direct) & want[:, :, None]
    assert free.sum() > 500 and (~free & want[:, :, None]).sum() > 500  # both kinds occur
    np.testing.assert_array_equal(np.isfinite(pruned), free)
    np.testing.assert_allclose(pruned[free], direct[free], rtol=0, atol=1e-6)


def test_antipodal_possible_never_rules_out_a_passing_frame():
    pts, n = cylinder()
    normals = noisy(n)
    samples, normal, axis, angles, grid = local_setup(pts, normals, 150)
    sid, _, h, u, v, nu, nv = pad_pairs(pts, normals, samples, normal, axis, HAND)
    possible = antipodal_possible(u, v, nu, nv, sid, len(samples), angles, grid, HAND, S).ravel()
    rng = np.random.default_rng(3)
    passed = np.zeros(len(possible), bool)
    for _ in range(30):  # any placement, any depth the collision test could give
        offset = rng.choice(grid.offsets, len(possible)).astype(np.float32)
        tip = rng.uniform(S.gpd_init_bite, HAND.finger_length - S.gpd_clearance, len(possible))
        _, ok, _ = closing_region(
            h, u, v, nu, nv, sid * len(angles), angles, offset, tip.astype(np.float32), HAND, S
        )
        passed |= ok
    assert passed.sum() > 50 and not possible.all()
    assert not (passed & ~possible).any()


def test_range_max_matches_a_direct_max():
    rng = np.random.default_rng(0)
    table_ = rng.normal(size=(37, 5)).astype(np.float32)
    widest = 9
    range_max = RangeMax(table_, widest)
    lo = rng.integers(0, 37, 2000)
    hi = np.minimum(lo + rng.integers(0, widest, 2000), 36)
    col = rng.integers(0, 5, 2000)
    expected = [table_[a : b + 1, c].max() for a, b, c in zip(lo, hi, col, strict=True)]
    np.testing.assert_array_equal(range_max(lo, hi, col), expected)


def test_voxel_groups_hold_each_point_once_within_its_radius():
    pts = np.random.default_rng(0).uniform(-0.1, 0.1, (5000, 3))
    vox = VoxelGroups(pts, 0.01)
    parent, members = vox.members(np.arange(len(vox.starts)))
    np.testing.assert_array_equal(np.sort(members), np.arange(len(pts)))
    for axis in range(3):  # each group fits in one 1 cm cube
        x = vox.points[members, axis]
        span = np.maximum.reduceat(x, vox.starts) - np.minimum.reduceat(x, vox.starts)
        assert span.max() < 0.01
    spread = np.linalg.norm(vox.points[members] - vox.points[vox.rep[parent]], axis=1)
    assert (spread <= vox.radius[parent]).all()


def test_detector_equals_the_direct_computation():
    # detect_grasps' shortcuts (the antipodal bound, voxel-pruned collisions, the cropped and
    # de-duplicated scene) change nothing: the same grasps as deepest_tips over every frame
    # and every (sample, scene point) pair, then the antipodal test. Without re-centring and
    # squaring, which test_grasp_detect covers.
    given = GraspSettings(gpd_samples=200, gpd_recentre=0.0, gpd_square=False)
    pts, n = cylinder()
    other, _ = box((0.04, 0.04, 0.10), centre=(0.06, 0.0))
    normals, target = noisy(n), pts.astype(np.float32).astype(np.float64)
    scene = np.vstack([table(), pts, other]).astype(np.float32)
    fast = detect_grasps(target, normals, scene, given, np.random.default_rng(5))

    hand = cleared_hand(HAND, given.side_clearance)  # the hand the detector tests

    centre = 0.5 * (target.min(axis=0) + target.max(axis=0))
    tgt = target - centre
    idx = sample_indices(len(tgt), given.gpd_samples, np.random.default_rng(5))
    normal, axis = local_frames(tgt, normals, idx, given)
    angles, grid = orientation_angles(given.gpd_orientations), ClosingGrid(hand, given)
    cloud = np.vstack([scene - centre, tgt])
    sid, _, h, u, v = slab_pairs(cloud, tgt[idx], normal, axis, hand_regions(hand, given))
    tips = deepest_tips(h, u, v, sid, len(idx), angles, grid, hand, given).reshape(
        -1, len(grid.offsets)
    )
    has, k = middle_placement(np.isfinite(tips))
    offset = np.where(has, grid.offsets[k], np.nan).astype(np.float32)
    tip = np.where(has, tips[np.arange(len(tips)), k], np.nan).astype(np.float32)
    tsid, _, th, tu, tv, nu, nv = pad_pairs(tgt, normals, tgt[idx], normal, axis, hand)
    width, ok, centred = closing_region(
        th, tu, tv, nu, nv, tsid * len(angles), angles, offset, tip, hand, given
    )
    good = np.flatnonzero(ok & has)
    poses = grasp_poses(tgt[idx], normal, axis, angles, good, offset[good], tip[good], hand)
    poses[:, :3, 3] += centre

    assert len(fast) == len(good) > 50
    np.testing.assert_allclose([g.pose for g in fast], poses, rtol=0, atol=1e-6)
    np.testing.assert_allclose([g.width for g in fast], width[good], rtol=0, atol=1e-6)
    assert [g.pads_centred for g in fast] == centred[good].tolist()
