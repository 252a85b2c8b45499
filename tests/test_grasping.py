"""`find_grasps`: detection, the filter, scoring and clustering joined up, on synthetic clouds
in `base` (a table at the isolation scene's height with one object on it)."""

from __future__ import annotations

import numpy as np
import pytest
from table_clouds import table_perception

from laserpick.description import dims
from laserpick.description.kinematics import tcp_pose
from laserpick.pipeline.gpd import detect_grasps
from laserpick.pipeline.grasp_choice import GraspSet, find_grasps
from laserpick.pipeline.perceive import Perception
from laserpick.pipeline.strategies import vertical_grasp
from laserpick.settings import get_settings
from laserpick.types import Grasp

TABLE = 0.46
SPACING = 0.003


def _cylinder(centre, r=0.03, height=0.11):
    ang = np.linspace(0, 2 * np.pi, int(2 * np.pi * r / SPACING), endpoint=False)
    hh = TABLE + (np.arange(int(height / SPACING)) + 0.5) * SPACING
    a, z = np.meshgrid(ang, hh)
    side = np.column_stack([r * np.cos(a).ravel(), r * np.sin(a).ravel(), z.ravel()])
    side_n = np.column_stack([np.cos(a).ravel(), np.sin(a).ravel(), np.zeros(a.size)])
    g = np.arange(-r, r, SPACING)
    x, y = np.meshgrid(g, g)
    m = x**2 + y**2 <= r * r
    top = np.column_stack([x[m], y[m], np.full(m.sum(), TABLE + height)])
    pts = np.vstack([side, top])
    pts[:, :2] += centre
    return pts, np.vstack([side_n, np.tile([0.0, 0.0, 1.0], (len(top), 1))])


def _box_front_left_top(centre, size=(0.06, 0.05, 0.20)):
    """The faces of an upright box a camera behind and to its left sees: the front (-x), the
    left side (+y) and the top. No seen face has a seen face opposite it."""
    (sx, sy, sz), (cx, cy) = size, centre
    u = np.arange(-0.5, 0.5, SPACING / max(size))  # face coordinates, fractions of the edge
    a, b = np.meshgrid(u, u)
    a, b = a.ravel(), b.ravel()
    ones = np.ones_like(a)
    front = np.c_[cx - sx / 2 * ones, cy + sy * a, TABLE + sz * (b + 0.5)]
    left = np.c_[cx + sx * a, cy + sy / 2 * ones, TABLE + sz * (b + 0.5)]
    top = np.c_[cx + sx * a, cy + sy * b, TABLE + sz * ones]
    pts = np.vstack([front, left, top])
    normals = np.repeat([[-1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]], len(a), axis=0)
    return pts, normals


def _perception(centre, shape=_cylinder, **kw) -> Perception:
    """An object (a cylinder) on a table, segmented, marked at its top."""
    centre = np.asarray(centre)
    obj, obj_n = shape(centre, **kw)
    return table_perception(
        obj, obj_n, centre, TABLE, lambda xy: np.linalg.norm(xy - centre, axis=1) <= 0.035
    )


@pytest.mark.parametrize("strategy", ["gpd", "vertical", "overhead"])
def test_every_strategy_gives_reachable_scored_clustered_grasps(strategy):
    found = find_grasps(_perception((1.55, -0.3)), dims.UR5_READY_Q, strategy=strategy)
    assert isinstance(found, GraspSet), found
    assert found.strategy == strategy
    assert set(found.timings) == {"detect", "filter", "select"}
    grasps = found.ordered()
    assert grasps
    for g in grasps:
        assert g.ik is not None and g.scores is not None
        assert np.allclose(tcp_pose(g.ik), g.pose, atol=1e-6)  # the IK reaches the pose
        assert 0.055 <= g.width <= 0.085  # the 6 cm cylinder, straight or slanting across
    # The best is the best of those whose pads meet the can about their middle.
    centred = [g for g in grasps if g.pads_centred]
    best = found.clusters.best
    assert best is not None and best.score == max(g.score for g in centred or grasps)
    if strategy == "gpd":
        assert centred and len(centred) < len(grasps)
    for members in found.clusters.clusters:  # the 2 cm bound, within every cluster
        p = np.array([found.clusters.grasps[i].position for i in members])
        assert np.max(np.linalg.norm(p[:, None] - p[None], axis=2)) <= 0.02 + 1e-9


def test_an_object_out_of_reach_is_an_ik_plan_failure():
    found = find_grasps(_perception((2.6, 0.0)), dims.UR5_READY_Q)
    assert not isinstance(found, GraspSet)
    assert found.kind == "ik_plan" and "cannot take any" in found.message


def test_a_too_wide_object_has_no_vertical_grasp():
    found = find_grasps(_perception((1.55, -0.3), r=0.06), dims.UR5_READY_Q, strategy="vertical")
    assert not isinstance(found, GraspSet)
    assert found.kind == "detect_grasp"


def test_a_vertical_grasp_on_a_cup_seen_from_the_front_clears_its_far_rim():
    """A 7 cm cup seen from the front and above: its top whole, only the front of its side.
    The mean of its points lies toward the cameras; the hand is centred on the top all the
    same, and each open finger keeps side_clearance from the cup on both sides."""
    centre = np.array([1.50, -0.30])
    r = 0.035
    pts, _ = _cylinder(centre, r=r, height=0.07)
    seen = pts[(pts[:, 0] < centre[0]) | (pts[:, 2] > pts[:, 2].max() - 1e-9)]
    assert seen[:, 0].mean() < centre[0] - 0.008  # the points' mean lies toward the front
    s = get_settings()
    g = vertical_grasp(seen, TABLE, s)
    assert isinstance(g, Grasp), g
    assert np.linalg.norm(g.position[:2] - centre) < 0.002
    # The cup's far and near sides along the closing axis, from the TCP.
    c = g.closing[:2] / np.linalg.norm(g.closing[:2])
    reach = np.abs((pts[:, :2] - g.position[:2]) @ c).max()
    assert reach + s.grasp.side_clearance <= dims.GRIPPER_HAND.width_max / 2


def test_an_object_seen_from_one_side_is_completed_by_symmetry():
    """A box seen only from its front, its left and above offers GPD no antipodal pair: its
    back is filled in by symmetry, and GPD then finds grasps across the real box."""
    centre = np.array([1.55, -0.3])
    p = _perception(centre, shape=_box_front_left_top)
    target = p.cloud.points[p.segmentation.indices]
    normals = p.cloud.normals[p.segmentation.indices]
    assert detect_grasps(target, normals, p.cloud.points) == []
    found = find_grasps(p, dims.UR5_READY_Q)
    assert isinstance(found, GraspSet), found
    assert found.strategy == "gpd"
    level = 0
    for g in found.ordered():
        assert 0.045 <= g.width <= 0.085  # across the 5 or the 6 cm side, or slanting
        if abs(g.pose[2, 1]) < 0.1:  # a level closing: about the real box's middle, to
            # within the 8.5 mm between finger placements and the sample's offset from it
            level += 1
            across = np.dot(g.position[:2] - centre, g.pose[:2, 1])
            assert abs(across) < 0.015, f"{across * 100:.1f} cm off the middle"
    assert level > 0
