"""Grasp selection against hand-worked values of paper 004's eqs. 3-7, the 0.02 m cluster
bound, and stepping through clusters."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from laserpick.description import dims
from laserpick.pipeline import selection as sel
from laserpick.settings import GraspSettings
from laserpick.types import Grasp

S = GraspSettings()
HAND = dims.GRIPPER_HAND


def _pose(approach, closing, p=(1.5, 0.0, 0.5)) -> np.ndarray:
    a, c = np.asarray(approach, float), np.asarray(closing, float)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([np.cross(c, a), c, a])
    T[:3, 3] = p
    return T


def test_joint_distance_max_is_the_largest_wrapped_distance():
    assert S.joint_distance_max == pytest.approx(math.pi * math.sqrt(6), abs=1e-3)


@pytest.mark.parametrize(
    ("width", "expected"),
    [
        (0.040, 1.0),  # mid-stroke: 0.040 from 0 and 0.045 from 0.085, both beyond W_d
        (0.015, 1.0),  # exactly W_d from W_min
        (0.010, 1 - (0.015 - 0.010) / 0.015),  # 1/3 inside the margin: 2/3
        (0.080, 1 - (0.015 - 0.005) / 0.015),  # 5 mm from W_max: 1/3
        (0.085, 0.0),  # at the stroke's end
        (0.0, 0.0),
    ],
)
def test_width_factor_eq3(width, expected):
    assert sel.width_factor(width, S) == pytest.approx(expected)


def test_joint_factor_eq4():
    q = np.zeros(6)
    g = np.array([0.3, 0.4, 0.0, 0.0, 0.0, 0.0])  # distance 0.5 rad
    assert sel.joint_factor(q, g, S) == pytest.approx(1 - 0.5 / S.joint_distance_max)
    assert sel.joint_factor(q, q, S) == 1.0
    assert sel.joint_factor(q, np.full(6, 10.0), S) == 0.0  # clipped at 0


def test_approach_factor_eq5_in_an_x_forward_frame():
    down = np.array([0.0, 0.0, -1.0])
    assert sel.approach_factor(down, np.array([1.0, 0.0, 0.0])) == 1.0  # top grasp
    vertical_axis = np.array([0.0, 0.0, 1.0])
    # Side grasp straight from the front (along +x in `base`): 0.5 + 0.5 * 1.
    assert sel.approach_factor(np.array([1.0, 0.0, 0.0]), vertical_axis) == 1.0
    # Side grasp from the left (along -y): the paper's y-forward would call it frontal; ours
    # does not: 0.5 + 0.5 * 0.
    assert sel.approach_factor(np.array([0.0, -1.0, 0.0]), vertical_axis) == 0.5
    diag = np.array([math.cos(math.radians(60)), math.sin(math.radians(60)), 0.0])
    assert sel.approach_factor(diag, vertical_axis) == pytest.approx(0.75)


def test_sample_factor_eq6():
    g_b = np.array([1.0, 0.0, 0.5])
    sample = np.array([[1.02, 0.0, 0.5], [1.2, 0.0, 0.5]])  # nearest 0.02 m away
    assert sel.sample_factor(g_b, sample) == pytest.approx(1 - 0.02 / 0.05)
    assert sel.sample_factor(g_b, sample + [1.0, 0, 0]) == 0.0  # beyond l
    assert sel.sample_factor(g_b, np.zeros((0, 3))) == 0.0


def test_g_b_is_the_hands_bottom_between_the_finger_roots():
    # A top grasp (approach straight down) with its TCP at z 0.5: the fingertips are
    # pad_depth / 2 below it, the finger roots finger_length above the tips.
    g = Grasp(pose=_pose([0, 0, -1], [0, 1, 0]), width=0.05)
    tips_z = 0.5 - HAND.pad_depth / 2
    assert sel.hand_bottom(g.pose) == pytest.approx([1.5, 0.0, tips_z + HAND.finger_length])


def test_cs_prefers_the_hand_a_can_fills_to_pads_on_its_top_edge():
    """Eq. 6 at the hand's bottom: a top grasp whose pads reach 3 cm down a 6.6 cm can
    scores above one whose pads only reach its top edge."""
    rng = np.random.default_rng(3)
    a = rng.uniform(0, 2 * math.pi, 2000)
    z = rng.uniform(0.46, 0.582, 2000)
    side = np.c_[1.5 + 0.033 * np.cos(a), 0.033 * np.sin(a), z]
    r = 0.033 * np.sqrt(rng.uniform(0, 1, 500))
    b = rng.uniform(0, 2 * math.pi, 500)
    top = np.c_[1.5 + r * np.cos(b), r * np.sin(b), np.full(500, 0.582)]
    can = np.vstack([side, top])
    rim = Grasp(pose=_pose([0, 0, -1], [0, 1, 0], p=(1.5, 0.0, 0.582)), width=0.066)
    deep = Grasp(pose=_pose([0, 0, -1], [0, 1, 0], p=(1.5, 0.0, 0.552)), width=0.066)
    cs = [sel.sample_factor(sel.hand_bottom(g.pose), can) for g in (rim, deep)]
    # The rim grasp's bottom stands 3.9 cm above the top: Cs = 1 - 0.039 / 0.05.
    assert cs[0] == pytest.approx(
        1 - (HAND.finger_length - HAND.pad_depth / 2) / HAND.finger_length, abs=0.01
    )
    assert cs[1] > cs[0] + 0.5


def test_mark_factor_eq7():
    g_b = np.array([1.0, 0.0, 0.5])
    assert sel.mark_factor(g_b, g_b + [0.04, 0, 0], S) == 1.0  # inside th
    assert sel.mark_factor(g_b, g_b + [0.15, 0, 0], S) == pytest.approx(math.exp(-1.0))


def test_score_multiplies_the_factors_and_needs_ik():
    g = Grasp(pose=_pose([0, 0, -1], [0, 1, 0]), width=0.010, ik=np.full(6, 0.1))
    g_b = sel.hand_bottom(g.pose)
    scored = sel.score(g, q_now=np.zeros(6), sample=g_b[None, :], mark=g_b)
    f = scored.scores
    assert f is not None
    assert f.Cw == pytest.approx(2 / 3)
    assert f.Cs == 1.0 and f.Cp == 1.0 and f.Ca == 1.0
    assert scored.score == pytest.approx(f.Cw * f.Cj * f.Ca * f.Cs * f.Cp)
    with pytest.raises(ValueError, match="IK"):
        sel.score(Grasp(pose=g.pose, width=0.01), q_now=np.zeros(6), sample=g.pose, mark=g.position)


def test_clusters_never_span_more_than_2cm():
    rng = np.random.default_rng(5)
    pts = rng.uniform(0, 0.1, size=(300, 3))
    labels = sel.cluster_positions(pts, 0.02)
    for c in np.unique(labels):
        members = pts[labels == c]
        if len(members) > 1:
            d = np.linalg.norm(members[:, None] - members[None], axis=-1)
            assert d.max() <= 0.02 + 1e-12
    # Two tight groups 10 cm apart give exactly two clusters.
    a = np.array([[0, 0, 0], [0.005, 0, 0], [0, 0.01, 0]])
    labels = sel.cluster_positions(np.vstack([a, a + [0.1, 0, 0]]), 0.02)
    assert len(set(labels[:3])) == 1 and len(set(labels[3:])) == 1 and labels[0] != labels[3]


def _scored(p, total_like: float) -> Grasp:
    # A grasp whose only imperfect factor is Cj, so its score is easy to set.
    g = Grasp(pose=_pose([0, 0, -1], [0, 1, 0], p), width=0.04, ik=np.zeros(6))
    q_now = np.array([(1 - total_like) * S.joint_distance_max, 0, 0, 0, 0, 0])
    g_b = sel.hand_bottom(g.pose)
    return sel.score(g, q_now=q_now, sample=g_b[None, :], mark=g_b)


def test_group_orders_clusters_and_candidates_by_score_and_the_cursor_steps():
    grasps = [
        _scored((1.5, 0.0, 0.5), 0.6),
        _scored((1.5, 0.005, 0.5), 0.9),  # same cluster as the first, better
        _scored((1.6, 0.0, 0.5), 0.7),  # its own cluster
        _scored((1.7, 0.0, 0.5), 0.95),  # best overall
    ]
    groups = sel.group(grasps)
    assert len(groups.clusters) == 3
    assert groups.best is not None and groups.best.score == pytest.approx(0.95)
    firsts = [groups.grasps[m[0]].score for m in groups.clusters]
    assert firsts == sorted(firsts, reverse=True)
    cur = sel.GraspCursor(groups)
    assert cur.current.score == pytest.approx(0.95)
    assert cur.next().score == pytest.approx(0.9)
    assert cur.describe() == "cluster 2 of 3, candidate 1 of 2"
    assert cur.next_candidate().score == pytest.approx(0.6)
    assert cur.next_candidate().score == pytest.approx(0.9)  # wraps within the cluster
    assert cur.prev().score == pytest.approx(0.95)
    assert cur.prev().score == pytest.approx(0.7)  # wraps over clusters
    assert all(g.cluster >= 0 for g in groups.grasps)
    with pytest.raises(IndexError, match="cluster 3"):
        cur.select(3)
    with pytest.raises(ValueError):
        sel.GraspCursor(sel.group([]))


def test_group_offers_grasps_whose_pads_meet_the_object_off_their_middle_last():
    """Within a cluster and across clusters, a grasp whose pads meet the object toward their
    edge (`pads_centred` False) comes after every centred one, whatever its score."""
    grasps = [
        replace(_scored((1.5, 0.0, 0.5), 0.9), pads_centred=False),
        _scored((1.5, 0.005, 0.5), 0.6),  # same cluster as the first: centred, worse
        replace(_scored((1.6, 0.0, 0.5), 0.95), pads_centred=False),  # its own cluster
        _scored((1.7, 0.0, 0.5), 0.5),  # its own cluster, centred
    ]
    groups = sel.group(grasps)
    order = [groups.grasps[i] for m in groups.clusters for i in m]
    assert [round(g.score, 2) for g in order] == [0.6, 0.9, 0.5, 0.95]
    assert groups.best is not None and groups.best.score == pytest.approx(0.6)
