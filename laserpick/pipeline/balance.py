"""Whether a grasp holds an object across its middle.

Held off its middle, an object's weight turns it about the line between the fingers, and
rubber pads let it creep round that line: a TV remote held 8 cm from its middle opened the
fingers 1.6 mm over half a minute of driving and fell. The lever of the weight about that
line is what a hold is judged by; the middle is what the cameras saw (`GraspSet.middle`),
as no sensor sees the centre of mass.

Frames: `base` (z up), metres.
"""

from __future__ import annotations

import numpy as np

__all__ = ["hold_lever", "holds_across_middle"]


def hold_lever(pose: np.ndarray, middle: np.ndarray) -> float:
    """How far (m) a grasp at `pose` (4 x 4 TCP pose, `base`) holds an object off its middle
    `middle` (m, `base`), as gravity sees it: the lever arm of the object's weight about the
    line between the fingers. With c the closing axis and d the middle's offset from the
    TCP, the weight's torque about c is m g (c_x d_y - c_y d_x): the level distance from the
    middle to the upright plane through that line when the fingers close level, and none
    when they close straight up and down."""
    c, d = pose[:3, 1], np.asarray(middle, float) - pose[:3, 3]
    return abs(float(c[0] * d[1] - c[1] * d[0]))


def holds_across_middle(pose: np.ndarray, middle: np.ndarray | None, limit: float) -> bool:
    """Whether a grasp at `pose` holds the object within `limit` (m, `balance_lever`) of its
    `middle` (`hold_lever`); True with no middle or no limit (0)."""
    return middle is None or limit <= 0 or hold_lever(pose, middle) <= limit
