"""Holding an object across its middle (`pipeline.balance`): the lever a hold is judged by,
the order grasps are offered in, and the completed GPD pass where every reachable grasp
holds the object far off its middle."""

from __future__ import annotations

import math

import numpy as np
import pytest
from table_clouds import table_perception

from laserpick.description import dims
from laserpick.pipeline.balance import hold_lever, holds_across_middle
from laserpick.pipeline.grasp_choice import GraspSet, find_grasps
from laserpick.pipeline.perceive import Perception
from laserpick.pipeline.selection import group
from laserpick.settings import Settings
from laserpick.types import Grasp, GraspScores

TABLE = 0.31  #: m, the kitchen's low table
SPACING = 0.003  #: m between the synthetic cloud's points
#: A TV remote's box (m): 18 cm long, 5 cm wide, 2.2 cm thick, lying along x.
REMOTE = np.array([0.18, 0.05, 0.022])


def test_a_holds_lever_is_the_weights_arm_about_the_line_between_the_fingers() -> None:
    """Hand-worked: fingers closing along y at the origin; the weight 5 cm ahead (x) turns
    the object about them with a 5 cm arm, wherever it lies along that line or below it."""
    pose = np.eye(4)  # closing axis: the pose's y column
    assert hold_lever(pose, np.array([0.05, 0.30, -0.02])) == pytest.approx(0.05)
    assert hold_lever(pose, np.array([0.0, 0.07, -0.04])) == pytest.approx(0.0)
    diagonal = np.eye(4)
    diagonal[:3, 1] = [math.sqrt(0.5), math.sqrt(0.5), 0.0]
    assert hold_lever(diagonal, np.array([0.1, 0.1, 0.0])) == pytest.approx(0.0)
    assert hold_lever(diagonal, np.array([0.1, 0.0, 0.0])) == pytest.approx(0.1 * math.sqrt(0.5))
    upright = np.eye(4)
    upright[:3, 1] = [0.0, 0.0, 1.0]  # fingers above and below: the weight pulls along them
    assert hold_lever(upright, np.array([0.05, 0.05, 0.0])) == pytest.approx(0.0)
    assert holds_across_middle(pose, np.array([0.02, 0.0, 0.0]), 0.02)
    assert not holds_across_middle(pose, np.array([0.03, 0.0, 0.0]), 0.02)
    assert holds_across_middle(pose, np.array([0.03, 0.0, 0.0]), 0.0)  # 0: off


def _grasp(x: float, score: float, centred: bool = True) -> Grasp:
    pose = np.eye(4)
    pose[:3, 3] = [x, 0.0, 0.5]
    scores = GraspScores(Cw=score, Cj=1.0, Ca=1.0, Cs=1.0, Cp=1.0)
    return Grasp(pose=pose, width=0.05, scores=scores, pads_centred=centred)


def test_grasps_across_the_middle_are_offered_before_better_scored_ones_off_it() -> None:
    """Three grasps along an object whose middle is at x = 1.0: the best-scored 6 cm off it
    comes after the one across it; pads met off their middle still come last."""
    middle = np.array([1.0, 0.0, 0.5])
    off, across, edge = _grasp(1.06, 0.9), _grasp(1.005, 0.5), _grasp(0.94, 0.95, centred=False)
    s = Settings().grasp
    ordered = group([off, across, edge], s, middle)
    first = [ordered.grasps[m[0]] for m in ordered.clusters]
    assert [g.position[0] for g in first] == [1.005, 1.06, 0.94]
    unjudged = group([off, across, edge], s)  # no middle: by score, as 004
    assert [unjudged.grasps[m[0]].position[0] for m in unjudged.clusters] == [1.06, 1.005, 0.94]


def _remote_seen_from_the_left(centre: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A remote lying along x on the table, as cameras behind and to its left see it: its
    top, its left side (+y) and its near end (-x) whole, and of its right side (-y) only the
    3 cm nearest them. GPD finds an antipodal pair across it only there."""
    (lx, ly, lz), (cx, cy) = REMOTE, centre
    xs = np.arange(-lx / 2, lx / 2, SPACING)
    ys = np.arange(-ly / 2, ly / 2, SPACING)
    zs = TABLE + np.arange(SPACING / 2, lz, SPACING)
    top = np.array([[cx + x, cy + y, TABLE + lz] for x in xs for y in ys])
    left = np.array([[cx + x, cy + ly / 2, z] for x in xs for z in zs])
    right = np.array([[cx + x, cy - ly / 2, z] for x in xs if x < -lx / 2 + 0.03 for z in zs])
    end = np.array([[cx - lx / 2, cy + y, z] for y in ys for z in zs])
    pts = np.vstack([top, left, right, end])
    normals = np.repeat(
        [[0, 0, 1.0], [0, 1.0, 0], [0, -1.0, 0], [-1.0, 0, 0]],
        [len(top), len(left), len(right), len(end)],
        axis=0,
    )
    return pts, normals


def _remote_perception(centre: np.ndarray) -> Perception:
    obj, obj_n = _remote_seen_from_the_left(centre)
    return table_perception(
        obj,
        obj_n,
        centre,
        TABLE,
        lambda xy: np.all(np.abs(xy - centre) < REMOTE[:2] / 2 + 0.005, axis=1),
    )


def test_a_remote_seen_across_only_at_its_end_is_offered_a_grasp_across_its_middle() -> None:
    """GPD sees both sides of the remote only at its near end: every grasp it finds holds
    the remote 7-8 cm off its middle. The pass on the remote completed by symmetry then runs
    too, and the grasp offered first holds it across the middle. With the rule off
    (`balance_lever` 0) the best grasp is one at the end."""
    centre = np.array([1.50, -0.30])
    middle = np.array([*centre, TABLE + REMOTE[2] / 2])
    rng = np.random.default_rng
    found = find_grasps(_remote_perception(centre), dims.UR5_READY_Q, rng=rng(0))
    assert isinstance(found, GraspSet), found
    assert hold_lever(found.ordered()[0].pose, middle) <= 0.02
    off = Settings()
    off.grasp.balance_lever = 0.0
    unjudged = find_grasps(_remote_perception(centre), dims.UR5_READY_Q, settings=off, rng=rng(0))
    assert isinstance(unjudged, GraspSet), unjudged
    assert min(hold_lever(g.pose, middle) for g in unjudged.ordered()) > 0.04
