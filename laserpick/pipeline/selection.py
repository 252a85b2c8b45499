"""Grasp selection: paper 004's objective for automatic choice (section 7.1), and position
clusters the user can step through for manual choice (section 7.2).

Frames: grasps and points in `base` (x forward, y left, z up). The paper's eq. 5 reads the
approach vector's y component because its world frame has y forward; ours has x forward, so
we read x.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from scipy.cluster.hierarchy import fcluster, linkage

from laserpick.description.dims import GRIPPER_HAND
from laserpick.pipeline.balance import holds_across_middle
from laserpick.settings import GraspSettings, get_settings
from laserpick.types import Grasp, GraspScores


def width_factor(width: float, s: GraspSettings) -> float:
    """Cw, eq. 3: 1 unless the width is within W_d of the stroke's ends, falling to 0 there."""
    if s.width_margin == 0:
        return 1.0
    gap = min(abs(width - s.width_min), abs(width - GRIPPER_HAND.width_max))
    return 1.0 - max(0.0, s.width_margin - gap) / s.width_margin


def joint_factor(q_now: np.ndarray, q_grasp: np.ndarray, s: GraspSettings) -> float:
    """Cj, eq. 4: falls linearly with the joint-space distance (rad) from here to the grasp."""
    return max(0.0, 1.0 - float(np.linalg.norm(q_now - q_grasp)) / s.joint_distance_max)


def approach_factor(approach: np.ndarray, axis: np.ndarray) -> float:
    """Ca, eq. 5: side grasps (hand axis near vertical) score 0.5 to 1 by how much they come
    from the front; all others, top grasps among them, score 1."""
    if abs(axis[2]) > 0.8:
        return 0.5 + 0.5 * abs(float(approach[0]))  # paper: G_a[1], its y is our x
    return 1.0


def hand_bottom(pose: np.ndarray) -> np.ndarray:
    """G_b of eqs. 6 and 7, "a fixed point relative to the grasp position": GPD's grasp
    bottom, the middle of the hand's base between the finger roots (m, the frame of `pose`).
    It lies finger_length behind the fingertips, which are pad_depth / 2 ahead of the TCP.

    Taken at the TCP, Cs prefers the grasps whose pads just reach an object's top edge, from
    which a can slides out while it is carried. At the bottom, Cs prefers the hand the object
    fills, as 004 means it to ("decreases the possibility that the object will
    slide away")."""
    back = GRIPPER_HAND.finger_length - GRIPPER_HAND.pad_depth / 2
    return pose[:3, 3] - back * pose[:3, 2]


def sample_factor(g_b: np.ndarray, sample: np.ndarray) -> float:
    """Cs, eq. 6: 1 where the hand's bottom `g_b` (m, `hand_bottom`) is at the segmented
    cloud `sample`, 0 a finger length or more away from it."""
    if len(sample) == 0:
        return 0.0
    d = float(np.min(np.linalg.norm(sample - g_b, axis=1)))
    return 1.0 - min(GRIPPER_HAND.finger_length, d) / GRIPPER_HAND.finger_length


def mark_factor(g_b: np.ndarray, mark: np.ndarray, s: GraspSettings) -> float:
    """Cp, eq. 7: exp(-10 * max(0, |p - G_b| - th)), distances in metres; `g_b` the hand's
    bottom (`hand_bottom`), `mark` the laser point p."""
    return math.exp(-10.0 * max(0.0, float(np.linalg.norm(mark - g_b)) - s.mark_distance))


def score(
    grasp: Grasp,
    *,
    q_now: np.ndarray,
    sample: np.ndarray,
    mark: np.ndarray,
    settings: GraspSettings | None = None,
) -> Grasp:
    """The grasp with its five factors filled in. Needs `grasp.ik` (Cj is a joint distance)."""
    s = settings or get_settings().grasp
    if grasp.ik is None:
        raise ValueError("score() needs a grasp with an IK solution (Cj is a joint distance)")
    g_b = hand_bottom(grasp.pose)
    scores = GraspScores(
        Cw=width_factor(grasp.width, s),
        Cj=joint_factor(q_now, grasp.ik, s),
        Ca=approach_factor(grasp.approach, grasp.axis),
        Cs=sample_factor(g_b, sample),
        Cp=mark_factor(g_b, mark, s),
    )
    return replace(grasp, scores=scores)


def cluster_positions(positions: np.ndarray, max_distance: float) -> np.ndarray:
    """Cluster labels (0..k-1) such that no two members of a cluster lie more than
    `max_distance` (m) apart: hierarchical clustering with complete linkage, cut there."""
    n = len(positions)
    if n == 0:
        return np.zeros(0, np.int64)
    if n == 1:
        return np.zeros(1, np.int64)
    Z = linkage(np.asarray(positions, float), method="complete")
    return fcluster(Z, t=max_distance, criterion="distance").astype(np.int64) - 1


@dataclass(frozen=True)
class GraspClusters:
    """Scored grasps grouped by position, best cluster first, best grasp first within each
    (`group` says what best is).

    clusters[i] lists indices into `grasps`.
    """

    grasps: tuple[Grasp, ...]
    clusters: tuple[tuple[int, ...], ...]

    @property
    def best(self) -> Grasp | None:
        return self.grasps[self.clusters[0][0]] if self.clusters else None


def group(
    grasps: Sequence[Grasp],
    settings: GraspSettings | None = None,
    middle: np.ndarray | None = None,
) -> GraspClusters:
    """Cluster grasps by position (004 section 7.2) and order everything by score, those
    whose pads meet the object about their middle first (`Grasp.pads_centred`), and among
    them those that hold the object across its `middle` (m, `base`; `holds_across_middle`):
    the grasps in each cluster, and the clusters by their first grasp.

    Ours: 004 orders by score alone. But C does not see where along the pads the object
    lies, nor where along the object the hand holds it: a can met only toward the pads'
    edges spins out of the hand when the scooter turns, and a remote held near one end
    turns in the pads and falls. Such grasps are still offered, after the others: they are
    often the only ones an object has."""
    s = settings or get_settings().grasp
    if not grasps:
        return GraspClusters((), ())
    labels = cluster_positions(np.array([g.position for g in grasps]), s.cluster_distance)
    members: dict[int, list[int]] = {}
    for i, label in enumerate(labels):
        members.setdefault(int(label), []).append(i)

    def rank(i: int) -> tuple[bool, bool, float]:
        g = grasps[i]
        across = holds_across_middle(g.pose, middle, s.balance_lever)
        return not g.pads_centred, not across, -g.score

    ordered = [sorted(m, key=rank) for m in members.values()]
    ordered.sort(key=lambda m: rank(m[0]))
    tagged = list(grasps)
    for c, m in enumerate(ordered):
        for i in m:
            tagged[i] = replace(tagged[i], cluster=c)
    return GraspClusters(tuple(tagged), tuple(tuple(m) for m in ordered))


class GraspCursor:
    """Where the user is while stepping through grasps: a cluster and a candidate in it.

    `next`/`prev` step through clusters (wrapping); `next_candidate`/`prev_candidate` step
    within the current cluster. Starts on the best grasp of the best cluster.
    """

    def __init__(self, clusters: GraspClusters) -> None:
        if not clusters.clusters:
            raise ValueError("there are no grasps to choose from")
        self.clusters = clusters
        self.cluster = 0
        self.candidate = 0

    @property
    def current(self) -> Grasp:
        return self.clusters.grasps[self.clusters.clusters[self.cluster][self.candidate]]

    def _members(self) -> tuple[int, ...]:
        return self.clusters.clusters[self.cluster]

    def next(self) -> Grasp:
        self.cluster = (self.cluster + 1) % len(self.clusters.clusters)
        self.candidate = 0
        return self.current

    def prev(self) -> Grasp:
        self.cluster = (self.cluster - 1) % len(self.clusters.clusters)
        self.candidate = 0
        return self.current

    def next_candidate(self) -> Grasp:
        self.candidate = (self.candidate + 1) % len(self._members())
        return self.current

    def prev_candidate(self) -> Grasp:
        self.candidate = (self.candidate - 1) % len(self._members())
        return self.current

    def select(self, cluster: int, candidate: int = 0) -> Grasp:
        """Jump to a cluster and candidate (0-based); IndexError names what is out of range."""
        if not 0 <= cluster < len(self.clusters.clusters):
            raise IndexError(f"cluster {cluster} out of range 0..{len(self.clusters.clusters) - 1}")
        members = self.clusters.clusters[cluster]
        if not 0 <= candidate < len(members):
            raise IndexError(f"candidate {candidate} out of range 0..{len(members) - 1}")
        self.cluster, self.candidate = cluster, candidate
        return self.current

    def describe(self) -> str:
        """E.g. "cluster 2 of 3, candidate 1 of 4" (1-based, for people)."""
        return (
            f"cluster {self.cluster + 1} of {len(self.clusters.clusters)}, "
            f"candidate {self.candidate + 1} of {len(self._members())}"
        )
