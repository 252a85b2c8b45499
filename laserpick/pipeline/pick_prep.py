"""The parts of a pick that need no search (paper 004 section 7.4): the hand's fit at the
grasp, the pre-grasp, the straight approach, the re-grip and the lift, checked against the
cloud; and the timed plan they make with a transit (`plan.transit_path`).

Frames: TCP poses in `base` (m); joint angles in rad.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from laserpick.description import dims
from laserpick.description.kinematics import ik_tcp, nearest_turns, tcp_pose
from laserpick.description.shapes import GRIPPER_CAPSULES
from laserpick.pipeline.collision import CollisionChecker, held_clear_of_arm
from laserpick.pipeline.lines import cartesian_line
from laserpick.pipeline.motion_limits import timed
from laserpick.pipeline.reach import lifted_pose, pregrasp_pose
from laserpick.pipeline.smoothing import ClearFn
from laserpick.settings import MotionSettings
from laserpick.types import Failure, Trajectory

__all__ = [
    "HAND_CONTACT_TOLERANCE",
    "PickPlan",
    "PickPrep",
    "between_the_fingers",
    "hand_fits",
    "prepare_pick",
    "straight_lift",
]

#: How far (m) the hand's spheres may overlap surrounding points at the grasp: the finger
#: spheres' rounded ends reach the fingertips, which stop 2-3 mm above the support, and the
#: support's points scatter by a few millimetres.
HAND_CONTACT_TOLERANCE = 0.004
#: The gripper housing's capsule radius (m), the first of `GRIPPER_CAPSULES`.
HOUSING_RADIUS = GRIPPER_CAPSULES[0][2]


@dataclass(frozen=True)
class PickPlan:
    """The motions of one pick, executed in order with gripper commands between them.

    transit: from the arm's current pose to the pre-grasp (open hand); approach: the straight,
    guarded line to the grasp; regrip: the straight 2 cm lift before closing again; lift: the
    straight lift to `lift` above the grasp. Each ends at rest.
    """

    transit: Trajectory
    approach: Trajectory
    regrip: Trajectory
    lift: Trajectory
    q_grasp: np.ndarray
    q_lifted: np.ndarray


def straight_lift(
    q_from: np.ndarray,
    T_grasp: np.ndarray,
    surroundings: CollisionChecker,
    s: MotionSettings,
    payload: np.ndarray | None = None,
) -> np.ndarray | None:
    """The straight lift from q_from to `lift` above the grasp pose T_grasp, or to `lift_low`
    where the full lift is blocked (a shelf's board above), or to `lift_least` where that is
    too: joint waypoints, or None if none is clear of the surroundings for the arm.

    payload: the object as it will be held (points, m, TCP frame), which must keep clear of
    the arm's upper links all the way (`held_clear_of_arm`): lifting from far out, the arm
    straightens and its forearm comes down over the hand, and what it holds."""
    for height in sorted({s.lift, s.lift_low, s.lift_least}, reverse=True):
        lift = cartesian_line(q_from, lifted_pose(T_grasp, height), s.cartesian_step)
        if lift is None or not surroundings.all_clear(lift, hand=False):
            continue
        if payload is None or held_clear_of_arm(lift, payload, surroundings.margin).all():
            return lift
    return None


def between_the_fingers(points: np.ndarray, T_grasp: np.ndarray) -> np.ndarray:
    """(N,) mask of `points` (m, `base`) in the open gripper's closing region at the TCP
    pose T_grasp: between the fingers' inner faces (across the stroke), from the finger
    roots to the tips, as far along the hand axis as the housing's capsule reaches."""
    if len(points) == 0:
        return np.zeros(0, bool)
    local = (points - T_grasp[:3, 3]) @ T_grasp[:3, :3]
    tip = dims.GRIPPER_PAD_DEPTH / 2  # the TCP is midway along the pads, behind the tips
    root = tip - dims.GRIPPER_FINGER_LENGTH
    return (
        (np.abs(local[:, 0]) <= HOUSING_RADIUS)
        & (np.abs(local[:, 1]) < dims.GRIPPER_STROKE / 2)
        & (local[:, 2] >= root)
        & (local[:, 2] <= tip)
    )


def hand_fits(q_grasp: np.ndarray, T_grasp: np.ndarray, surroundings: CollisionChecker) -> bool:
    """Whether the hand at its grasp (joint angles q_grasp (6,) rad, TCP pose T_grasp in
    `base`) keeps out of the `surroundings`, but for HAND_CONTACT_TOLERANCE and what stands
    between the open fingers: that is what they close on, parts of the object the
    segmentation left out (a tissue packet's side face). The housing's spheres reach down
    between the fingers, where the real housing does not."""
    beside = surroundings.without(between_the_fingers(surroundings.points, T_grasp))
    return bool(beside.clearance_ok(q_grasp, hand=True, margin=-HAND_CONTACT_TOLERANCE)[0])


@dataclass(frozen=True)
class PickPrep:
    """The parts of a pick that need no search (`prepare_pick`): the grasp's posture q_grasp
    (6,) rad and pre-grasp q_pre (6,) rad, and the joint waypoints (K, 6) rad of the
    straight approach, the 2 cm re-grip lift and the lift."""

    q_grasp: np.ndarray
    q_pre: np.ndarray
    approach: np.ndarray
    up: np.ndarray
    lift: np.ndarray

    def planned(self, transit: tuple[np.ndarray, list[ClearFn]], s: MotionSettings) -> PickPlan:
        """The pick, timed, with the transit's waypoints and the checks of its segments
        (`transit_path`)."""
        return PickPlan(
            transit=timed(transit[0], s, clear=transit[1]),
            approach=timed(self.approach, s, tcp_speed=s.approach_speed),
            regrip=timed(self.up, s, tcp_speed=s.approach_speed),
            lift=timed(self.lift, s, tcp_speed=s.lift_speed),
            q_grasp=self.q_grasp,
            q_lifted=self.lift[-1],
        )


def prepare_pick(
    q_grasp: np.ndarray,
    q_from: np.ndarray,
    world: CollisionChecker,
    surroundings: CollisionChecker,
    s: MotionSettings,
    check_hand: bool = True,
    payload: np.ndarray | None = None,
) -> PickPrep | Failure:
    """The search-free part of a pick (`plan.plan_pick`) for the grasp whose IK solution is
    q_grasp, its wrists turned the short way from q_from (rad: where the transit's last leg
    starts, `way_to`): the hand's fit at the grasp, the pre-grasp, the straight approach and
    the lift, or the failure that says which could not be had."""
    # The grasp's posture as the leg to it turns the wrists least: IK took the angles nearest
    # the ready pose, and a grasp on the other elbow branch, reached from the unstow pose,
    # turned a wrist 6 rad on the way, through space no camera saw (a bottle on a high table:
    # found on 1 of 4 draws and a 25 s motion, against 4 of 4 and 10-13 s).
    q_grasp = nearest_turns(q_grasp, q_from)
    T_grasp = tcp_pose(q_grasp)
    if check_hand and not hand_fits(q_grasp, T_grasp, surroundings):
        return Failure("ik_plan", "The hand would hit something beside the object.")
    pre = ik_tcp(pregrasp_pose(T_grasp, s.approach_distance), q_grasp)
    if len(pre) == 0:
        return Failure("ik_plan", "The arm cannot reach the pose before this grasp.")
    approach = cartesian_line(pre[0], T_grasp, s.cartesian_step)
    if approach is None or not world.all_clear(approach, hand=False):
        return Failure("ik_plan", "The straight approach to this grasp is blocked.")
    approach[-1] = q_grasp
    up = cartesian_line(q_grasp, lifted_pose(T_grasp, s.regrip_lift), s.cartesian_step)
    lift = None if up is None else straight_lift(up[-1], T_grasp, surroundings, s, payload)
    if up is None or lift is None:
        return Failure("ik_plan", "The arm cannot lift straight up from this grasp.")
    return PickPrep(q_grasp, pre[0], approach, up, lift)
