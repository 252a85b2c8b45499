"""Where the scooter should park for the arm to take what it cannot from here: farther back,
or to a side.

At a bookshelf parked close, the forearm comes down onto the board above the object for
every posture of every grasp; from farther back it comes in level. When the reachability
filter leaves no grasp, the same grasps are tried as they would lie after backing up
straight by each of BACK_UP_STEPS: the grasps and the seen cloud move forward by that much
in `base` (the scooter and its rider, which the checker models in `base`, stay). The first
step from which some grasp has a collision-free posture is what the robot asks for. Only
postures are checked, against what the cameras saw from here; the view from there decides
the grasps after the drive.

Where the only ways to the grasps pass through space no camera saw (`first_plan`), the
robot asks the user to park to a side instead, with the object nearer the middle of the
cameras' view (`park_aside_advice`).

Frames: `base` (x forward, the scooter's heading), metres.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from laserpick.pipeline.collision import CollisionChecker
from laserpick.pipeline.reach import reachable
from laserpick.settings import MotionSettings
from laserpick.types import Failure, Grasp

__all__ = [
    "ADVICE_GRASPS",
    "ASIDE_STEP",
    "BACK_UP_STEPS",
    "IN_VIEW_Y",
    "UNSEEN_WAYS",
    "back_up_advice",
    "backed_up_grasps",
    "park_aside_advice",
    "park_aside_sentence",
    "unseen_ways_failure",
]

#: Said after a pick's planning failure when some way to its grasps passed only through space
#: no camera saw: the arm keeps to seen space, so the user knows why it did not go.
UNSEEN_WAYS = (
    "; the only ways found pass where the cameras could not see, and the arm keeps to where"
    " they saw"
)

#: How far back (m) the robot considers asking the user to park, nearest first: a person
#: backs a scooter up by a hand's breadth or two, not across the room. The least that serves
#: is asked for, to 5 cm: each step back takes the object farther from the arm, and a
#: cereal box on the bookshelf's middle board that 10 cm took out of reach was taken from 5.
BACK_UP_STEPS = (0.05, 0.10, 0.15, 0.20)
#: At most this many of the grasps (evenly sampled) are tried from each step, which filters
#: them again: a step that suits any grasp suits many.
ADVICE_GRASPS = 60
#: m (`base` y) where a high object stands in the most cameras' view: the low pairs look
#: inward from either post, the high camera from the left one, and beside the arm (y -0.30),
#: above the right-hand cameras' upper edge, none looks.
IN_VIEW_Y = -0.10
#: m the robot asks the user to park aside, toward IN_VIEW_Y: on the kitchen's 108 cm table
#: the first try at a juice bottle straight before the arm found only ways through unseen
#: space on 10 of 20 sweep seeds; the next try, parked 20 cm to the arm's left, took it on
#: 6 of them, the one after (10 cm farther back too) on 3 more. Not worked out from the
#: way: the blind points lie where the cameras' rays read nothing in range, and which of
#: them a re-park brings into view, no frustum tells (15 and 25 cm re-parks failed where
#: 20 cm served, on one traced juice bottle).
ASIDE_STEP = 0.20


def backed_up_grasps(grasps: Sequence[Grasp], back: float) -> list[Grasp]:
    """`grasps` as they lie after the scooter backs up `back` (m): `back` farther forward in
    `base`, with no posture chosen yet."""
    out = []
    for g in grasps:
        pose = g.pose.copy()
        pose[0, 3] += back
        out.append(replace(g, pose=pose, ik=None, ik_failure=None))
    return out


def back_up_advice(
    grasps: Sequence[Grasp],
    world: CollisionChecker,
    q_ref: np.ndarray,
    motion: MotionSettings,
    steps: Sequence[float] = BACK_UP_STEPS,
) -> float | None:
    """The least of `steps` (m) the scooter should back up for the arm to take one of
    `grasps` (from the filter, none reachable here) without touching what `world` holds, as
    the reachability filter judges from q_ref (6,) rad; None when no step serves."""
    if not grasps:
        return None
    sample = list(grasps[:: max(1, -(-len(grasps) // ADVICE_GRASPS))])
    for back in steps:
        there = CollisionChecker(
            world.points + np.array([back, 0.0, 0.0]), margin=world.margin, filtered=True
        )
        moved = backed_up_grasps(sample, back)
        found = reachable(moved, there, q_ref, motion.approach_distance, motion.lift_least)
        if any(g.ik is not None for g in found):
            return back
    return None


def park_aside_advice(middle: np.ndarray) -> float | None:
    """How far (m) to its left (negative: right) the scooter should park for the object
    whose middle is at `middle` (m, `base`) to stand nearer IN_VIEW_Y: ASIDE_STEP toward
    it (parked `d` to its left, a point at y lies at y - d); None where it stands within
    half a step of it already. Asked for where the only ways to the object's grasps pass
    where no camera saw; the view from there decides the grasps after the drive."""
    off = float(middle[1]) - IN_VIEW_Y
    if not np.isfinite(off) or abs(off) < ASIDE_STEP / 2:
        return None
    return math.copysign(ASIDE_STEP, off)


def unseen_ways_failure(failure: Failure, middle: np.ndarray) -> Failure:
    """`failure` (no way found) said again with why (`UNSEEN_WAYS`), carrying how far to
    park to a side for the object, whose middle is at `middle` (m, `base`), to stand nearer
    the middle of the cameras' view (`park_aside_advice`, `Failure.park_left`; the pick says
    it with `park_aside_sentence`)."""
    msg = f"{failure.message.rstrip('.')}{UNSEEN_WAYS}"
    return Failure("ik_plan", msg, park_left=park_aside_advice(middle))


def park_aside_sentence(left: float) -> str:
    """What the robot asks where it would have the scooter park `left` m to its left
    (negative: right): a sentence to follow the failure's."""
    side = "left" if left > 0 else "right"
    return (
        f" Park about {round(abs(left) * 100)} cm farther to your {side} and mark it again:"
        " there it stands nearer the middle of the cameras' view."
    )
