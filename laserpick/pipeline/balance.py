"""Whether a grasp holds an object across its middle.

Held off its middle, an object's weight turns it about the line between the fingers, and
rubber pads let it creep round that line: a TV remote held 8 cm from its middle opened the
fingers 1.6 mm over half a minute of driving and fell. The lever of the weight about that
line is what a hold is judged by, as the object hangs at the grasp and as it hangs carried
with the hand pointing down (tucked in beside the scooter, over the basket); the middle is
what the cameras saw (`GraspSet.middle`), as no sensor sees the centre of mass.

Frames: `base` (z up), metres.
"""

from __future__ import annotations

import numpy as np

__all__ = ["carried_lever", "hold_lever", "holds_across_middle", "off_middle"]


def hold_lever(pose: np.ndarray, middle: np.ndarray) -> float:
    """How far (m) a grasp at `pose` (4 x 4 TCP pose, `base`) holds an object off its middle
    `middle` (m, `base`), as gravity sees it: the lever arm of the object's weight about the
    line between the fingers. With c the closing axis and d the middle's offset from the
    TCP, the weight's torque about c is m g (c_x d_y - c_y d_x): the level distance from the
    middle to the upright plane through that line when the fingers close level, and none
    when they close straight up and down."""
    c, d = pose[:3, 1], np.asarray(middle, float) - pose[:3, 3]
    return abs(float(c[0] * d[1] - c[1] * d[0]))


def carried_lever(pose: np.ndarray, middle: np.ndarray) -> float:
    """How far (m) a grasp at `pose` (4 x 4 TCP pose, `base`) holds an object off its middle
    `middle` (m, `base`) once the hand points straight down, as it carries the object tucked
    in and over the basket: the weight then pulls along the approach, and its lever about
    the line between the fingers is the middle's offset across the fingers' width (the
    pose's first axis). A jar taken from the side by its cap hangs level at the grasp (no
    lever) and 4 cm off that line when tucked: a pill bottle and a spice jar turned in the
    pads on the way to the place, the fingers closing from 3.8 to 1.0 cm round them, and
    were set down 3 cm off the mark, or fell over."""
    return abs(float(pose[:3, 0] @ (np.asarray(middle, float) - pose[:3, 3])))


def holds_across_middle(pose: np.ndarray, middle: np.ndarray | None, limit: float) -> bool:
    """Whether a grasp at `pose` holds the object within `limit` (m, `balance_lever`) of its
    `middle` as it hangs at the grasp (`hold_lever`); True with no middle or no limit (0)."""
    return middle is None or limit <= 0 or hold_lever(pose, middle) <= limit


def off_middle(pose: np.ndarray, middle: np.ndarray | None, limit: float) -> tuple[bool, bool]:
    """Whether a grasp at `pose` holds the object farther than `limit` (m) off its `middle`
    as it hangs at the grasp (`hold_lever`), and as it hangs carried (`carried_lever`): a
    key that orders grasps across the middle both ways first, then those across it at the
    grasp (an object that turns in the pads while lifted is lost at once; carried, it may
    still be set down). (False, False) with no middle or no limit (0)."""
    if middle is None or limit <= 0:
        return False, False
    return hold_lever(pose, middle) > limit, carried_lever(pose, middle) > limit
