"""`find_grasps`: detection, the filter, scoring and clustering joined up, on synthetic clouds
in `base` (a table at the isolation scene's height with one object on it)."""

from __future__ import annotations

import numpy as np
import pytest

from laserpick.description import dims
from laserpick.description.kinematics import tcp_pose
from laserpick.pipeline.grasping import GraspSet, find_grasps
from laserpick.pipeline.perceive import Perception
from laserpick.pipeline.types import FusedCloud, LaserMark, Segmentation, SupportSurface

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


def _perception(centre, **kw) -> Perception:
    """A cylinder on a table, segmented, marked at its top."""
    obj, obj_n = _cylinder(np.asarray(centre), **kw)
    g = np.arange(-0.3, 0.3, 0.006)
    x, y = np.meshgrid(g, g)
    table = np.column_stack([x.ravel() + centre[0], y.ravel() + centre[1], np.full(x.size, TABLE)])
    table = table[np.linalg.norm(table[:, :2] - centre, axis=1) > 0.035]
    pts = np.vstack([obj, table]).astype(np.float32)
    normals = np.vstack([obj_n, np.tile([0.0, 0.0, 1.0], (len(table), 1))]).astype(np.float32)
    n = len(pts)
    cloud = FusedCloud(pts, normals, np.zeros(n, np.uint8), np.arange(n, dtype=np.int32), ("c",))
    surface = SupportSurface(TABLE, np.array([0.0, 0.0, 1.0, -TABLE]))
    seg = Segmentation(np.arange(len(obj)), "cluster", surface)
    top = np.array([centre[0], centre[1], obj[:, 2].max()])
    return Perception(cloud, LaserMark(top, "confirmed", 0, "direct"), seg, None)


@pytest.mark.parametrize("strategy", ["gpd", "vertical", "overhead"])
def test_every_strategy_gives_reachable_scored_clustered_grasps(strategy):
    found = find_grasps(_perception((1.55, -0.3)), dims.UR5_READY_Q, strategy=strategy)
    assert isinstance(found, GraspSet), found
    assert found.strategy == strategy
    assert set(found.timings) == {"detect", "filter", "select"}
    grasps = found.ordered()
    assert grasps
    scores = [g.score for g in grasps]
    for g in grasps:
        assert g.ik is not None and g.scores is not None
        assert np.allclose(tcp_pose(g.ik), g.pose, atol=1e-6)  # the IK reaches the pose
        assert 0.055 <= g.width <= 0.085  # the 6 cm cylinder, straight or slanting across
    best = found.clusters.best
    assert best is not None and best.score == max(scores)
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
