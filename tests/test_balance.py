"""Holding an object across its middle (`pipeline.balance`): the lever a hold is judged by,
the order grasps are offered in, and the completed GPD pass where every reachable grasp
holds the object far off its middle."""

from __future__ import annotations

import math

import numpy as np
import pytest
from table_clouds import table_perception

from laserpick.description import dims
from laserpick.pipeline.balance import carried_lever, hold_lever, holds_across_middle, off_middle
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


def test_a_hold_is_judged_also_as_the_hand_carries_it_pointing_down() -> None:
    """Hand-worked: a jar standing at the origin, 10 cm tall, its middle 5 cm up, taken from
    the side (approach along x, fingers closing along y, the hand's first axis straight
    down). By its cap, 4 cm above the middle, it hangs level at the grasp, and 4 cm off the
    line between the fingers once the hand points down: across its middle only at the
    grasp. By its middle it is across it both ways; and from above, the two levers are
    one."""
    middle = np.array([0.0, 0.0, 0.05])
    side = np.eye(4)
    side[:3, :3] = np.column_stack([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
    side[:3, 3] = [0.0, 0.0, 0.09]
    assert hold_lever(side, middle) == pytest.approx(0.0)
    assert carried_lever(side, middle) == pytest.approx(0.04)
    assert off_middle(side, middle, 0.02) == (False, True)
    side[:3, 3] = [0.0, 0.0, 0.055]
    assert off_middle(side, middle, 0.02) == (False, False)
    assert off_middle(side, None, 0.02) == off_middle(side, middle, 0.0) == (False, False)
    top = np.eye(4)
    top[:3, :3] = np.diag([1.0, -1.0, -1.0])  # approach straight down, fingers along y
    top[:3, 3] = [0.03, 0.01, 0.1]
    assert carried_lever(top, middle) == pytest.approx(hold_lever(top, middle)) == 0.03


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


def _side_grasp(x: float, z: float, score: float) -> Grasp:
    """A grasp from the side at (x, 0, z): approach along +x, fingers closing along y, the
    hand's first axis straight down."""
    pose = np.eye(4)
    pose[:3, :3] = np.column_stack([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
    pose[:3, 3] = [x, 0.0, z]
    scores = GraspScores(Cw=score, Cj=1.0, Ca=1.0, Cs=1.0, Cp=1.0)
    return Grasp(pose=pose, width=0.04, scores=scores)


def test_grasps_held_across_the_middle_also_carried_come_before_those_held_by_an_end() -> None:
    """A jar standing with its middle at (1.0, 0, 0.55), taken from the side: by its cap
    (4 cm above the middle, best scored) it hangs level at the grasp but turns once
    carried, so a grasp across its middle comes first; a grasp 5 cm in front of the middle,
    off it already at the grasp, comes after both."""
    middle = np.array([1.0, 0.0, 0.55])
    by_cap, across, in_front = (
        _side_grasp(1.0, 0.59, 0.9),
        _side_grasp(1.0, 0.555, 0.5),
        _side_grasp(0.95, 0.55, 0.95),
    )
    ordered = group([in_front, by_cap, across], Settings().grasp, middle)
    offered = [tuple(ordered.grasps[i].position) for m in ordered.clusters for i in m]
    assert offered == [tuple(g.position) for g in (across, by_cap, in_front)]


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
