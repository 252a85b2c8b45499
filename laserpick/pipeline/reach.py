"""The reachability filter (paper 004 section 7): keep the grasps the arm can take without
touching the cloud, the scooter or its rider.

For each grasp, every analytic IK solution of the grasp pose is tried, nearest the reference
configuration first; the pre-grasp pose `approach_distance` back along the approach axis and
the pose `lift` straight above the grasp must then be solvable on the same branch, and all
three configurations must be collision-free. The hand itself is not checked at the grasp
(grasp detection did that exactly) nor lifted (it holds the object there); it is at the
pre-grasp. Frames: `base`, metres, radians.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from laserpick.description.dims import UR5_Q_MAX
from laserpick.description.kinematics import ik_tcp, wrap
from laserpick.pipeline.collision import CollisionChecker
from laserpick.types import Grasp

#: Largest joint change (rad) between a grasp's and its pre-grasp's solutions: more means the
#: IK branch flipped, and the straight approach between them would not be straight.
BRANCH_JUMP = 1.0


def flipped(pose: np.ndarray) -> np.ndarray:
    """The same grasp with the fingers swapped: a half turn about the approach axis."""
    out = pose.copy()
    out[:3, :2] *= -1.0
    return out


def pregrasp_pose(pose: np.ndarray, distance: float) -> np.ndarray:
    """The TCP pose `distance` (m) back along the approach axis from `pose`."""
    out = pose.copy()
    out[:3, 3] -= distance * pose[:3, 2]
    return out


def lifted_pose(pose: np.ndarray, height: float) -> np.ndarray:
    """The TCP pose `height` (m) straight above `pose` (`base` z is up)."""
    out = pose.copy()
    out[2, 3] += height
    return out


COLLIDES = "every arm posture for this grasp collides with something"
CANNOT_LIFT = "the arm would meet something above it as it lifts this grasp"


Option = tuple[np.ndarray, np.ndarray] | None  #: (joint solution, grasp pose), None: collides


def _on_branch(pose: np.ndarray, q: np.ndarray) -> np.ndarray | None:
    """The IK solution (6,) rad of TCP `pose` nearest q, if it lies on q's branch."""
    Q = ik_tcp(pose, q)
    return Q[0] if len(Q) and np.max(np.abs(Q[0] - q)) < BRANCH_JUMP else None


def _liftable(
    options: Sequence[tuple[np.ndarray, np.ndarray]], lift: float, checker: CollisionChecker
) -> np.ndarray:
    """(B,) whether the arm at each (joint solution, grasp pose) can rise `lift` (m) straight
    up: the lifted pose solves on the same IK branch, and the arm is clear there. The hand is
    not checked: it holds the object, whose own points it meets."""
    up = [_on_branch(lifted_pose(pose, lift), q) for q, pose in options]
    out = np.array([u is not None for u in up])
    if out.any():
        out[out] = checker.clearance_ok(np.array([u for u in up if u is not None]), hand=False)
    return out


def _clear_options(
    options: list[list[Option]],
    chosen: dict[int, Option],
    checker: CollisionChecker,
    failure: dict[int, str],
) -> list[list[Option]]:
    """Options from the second rank on, with None where the arm collides at the grasp."""
    index = [(i, r) for i, o in enumerate(options) if i not in chosen for r in range(1, len(o))]
    if not index:
        return options
    ok = checker.clearance_ok(np.array([options[i][r][0] for i, r in index]), hand=False)
    out = [list(o) for o in options]
    for (i, r), good in zip(index, ok, strict=True):
        if not good:
            out[i][r] = None
            failure[i] = COLLIDES
    return out


def _ik_options(pose: np.ndarray, q_ref: np.ndarray) -> list[Option]:
    """The IK options (joint solution, grasp pose) of TCP `pose`, with its fingers as they are
    and swapped, nearest q_ref (6,) rad first."""
    Q = ik_tcp(pose, q_ref)
    # Swapping the fingers is a half turn of the last joint, whose axis is the approach.
    Q_swap = Q.copy()
    Q_swap[:, 5] = q_ref[5] + wrap(Q[:, 5] + np.pi - q_ref[5])
    Q_swap = Q_swap[np.abs(Q_swap[:, 5]) <= UR5_Q_MAX[5]]
    poses = [pose] * len(Q) + [flipped(pose)] * len(Q_swap)
    Q_all = np.vstack([Q, Q_swap])
    order = np.argsort(np.linalg.norm(Q_all - q_ref, axis=1), kind="stable")
    return [(Q_all[k], poses[k]) for k in order]


def reachable(
    grasps: Sequence[Grasp],
    checker: CollisionChecker,
    q_ref: np.ndarray,
    approach_distance: float = 0.10,
    lift: float = 0.0,
) -> list[Grasp]:
    """The grasps with `ik` set to a collision-free solution, or with `ik_failure` saying why.

    q_ref (6,) rad: where the arm starts the grasp motion (the ready pose). Each grasp is also
    tried with its fingers swapped, which turns the wrist by a half turn; the nearer wins, and
    its pose replaces the grasp's. lift (m): the least lift the pick makes
    (`MotionSettings.lift_least`); the arm must be clear there too, or the grasp is one the
    hand could close on but never raise (under a shelf's board). 0 skips the check.
    """
    options: list[list[Option]] = [_ik_options(g.pose, q_ref) for g in grasps]
    failure = {i: "the arm cannot reach this grasp" for i in range(len(grasps))}
    # Rank by rank, so that most grasps cost one pre-grasp IK and one batched collision test.
    # The hand is not checked at the grasp (grasp detection did that). After the first rank,
    # the arm at every remaining option is checked in one batch, before any more pre-grasps
    # are solved.
    chosen: dict[int, Option] = {}
    for rank in range(max((len(o) for o in options), default=0)):
        if rank == 1:
            options = _clear_options(options, chosen, checker, failure)
        todo, q_grasp, q_pre = [], [], []
        for i, o in enumerate(options):
            if i in chosen or rank >= len(o) or o[rank] is None:
                continue
            q, pose = o[rank]
            pre = _on_branch(pregrasp_pose(pose, approach_distance), q)
            if pre is not None:
                todo.append(i)
                q_grasp.append(q)
                q_pre.append(pre)
            elif failure[i] == "the arm cannot reach this grasp":
                failure[i] = "the arm cannot reach the pre-grasp pose behind this grasp"
        if not todo:
            continue
        ok = checker.clearance_ok(np.array(q_pre), hand=True)
        if rank == 0:
            ok &= checker.clearance_ok(np.array(q_grasp), hand=False)
        for i in np.array(todo)[~ok]:
            failure[i] = COLLIDES
        if lift > 0 and ok.any():
            at = np.flatnonzero(ok)
            up_ok = _liftable([options[todo[k]][rank] for k in at], lift, checker)
            for k in at[~up_ok]:
                failure[todo[k]] = CANNOT_LIFT
            ok[at] = up_ok
        for i, good in zip(todo, ok, strict=True):
            if good:
                chosen[i] = options[i][rank]
    return [
        replace(g, pose=chosen[i][1], ik=chosen[i][0], ik_failure=None)
        if i in chosen
        else replace(g, ik=None, ik_failure=failure[i])
        for i, g in enumerate(grasps)
    ]
