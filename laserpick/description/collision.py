"""Collision geometry of the robot for planning: the UR5's link capsules, the gripper's, and
keep-out boxes around the scooter and its rider.

The same capsule table builds the MuJoCo model (robot/model.py) and the planner's sphere
model (pipeline/collision.py), so what the planner avoids is what the simulator collides.

Frames: link capsules are given in the frame of MuJoCo body `link{i+1}`, which is DH frame i
turned by q_{i+1} about its z axis; gripper capsules in the flange frame (z = approach);
keep-out boxes in `base`. Metres throughout.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from laserpick.description import dims
from laserpick.description.kinematics import T_BASE_UR5

#: Physical offsets along the shoulder and elbow joint axes (m): the UR5's shoulder and elbow
#: sit to the side of the DH line, and the DH d4 is their net sum.
SHOULDER_OFFSET = 0.13585
ELBOW_OFFSET = 0.1197

Segment = tuple[tuple[float, float, float], tuple[float, float, float], float]


def _link_capsules() -> tuple[tuple[Segment, ...], ...]:
    d, a, r = dims.UR5_D, dims.UR5_A, dims.UR5_LINK_RADII
    so, eo = SHOULDER_OFFSET, ELBOW_OFFSET
    return (
        (((0, 0, 0.0), (0, 0, d[0]), r[1]),),
        (((0, 0, 0.0), (0, 0, so), r[2]), ((0, 0, so), (a[1], 0, so), r[2])),
        (((0, 0, so - eo), (a[2], 0, so - eo), r[3]),),
        (((0, 0, so - eo), (0, 0, d[3]), r[4]),),
        (((0, 0, 0.0), (0, 0, d[4]), r[5]),),
        (((0, 0, 0.0), (0, 0, d[5] - 0.005), r[6]),),
    )


#: Capsules (from, to, radius) of each of the six links, in that link's body frame (m).
LINK_CAPSULES: tuple[tuple[Segment, ...], ...] = _link_capsules()

_FINGER_Y = dims.GRIPPER_STROKE / 2 + dims.GRIPPER_PAD_THICKNESS  # pad/plate seam, open
_FINGER_R = 0.010  # two capsules side by side cover the 24 x 16 mm plate-and-pad section
_ROOT, _TIP = dims.GRIPPER_BASE_LENGTH, dims.GRIPPER_BASE_LENGTH + dims.GRIPPER_FINGER_LENGTH
#: The gripper in the flange frame (m): its housing, and each open finger with its pad.
GRIPPER_CAPSULES: tuple[Segment, ...] = (
    ((0, 0, 0.02), (0, 0, _ROOT - 0.01), 0.05),
    *(
        ((x, y, _ROOT + _FINGER_R), (x, y, _TIP - _FINGER_R), _FINGER_R)
        for y in (_FINGER_Y, -_FINGER_Y)
        for x in (-0.006, 0.006)
    ),
)


@dataclass(frozen=True)
class Box:
    """An axis-aligned keep-out box in `base`: lower and upper corners (m)."""

    name: str
    lo: tuple[float, float, float]
    hi: tuple[float, float, float]


def _keepout() -> tuple[Box, ...]:
    deck_top = dims.SCOOTER_DECK_HEIGHT
    x_rear = -dims.SCOOTER_REAR_OVERHANG
    half_w = dims.SCOOTER_WIDTH / 2
    w = dims.BASKET_WALL + 0.005
    bx0, by0, bz0 = dims.BASKET_CENTER - dims.BASKET_INNER / 2 - w
    bx1, by1, bz1 = dims.BASKET_CENTER + dims.BASKET_INNER / 2 + w
    post_x = dims.SENSOR_X - 0.1
    post_y = dims.SENSOR_GROUP_SPACING / 2
    head_lo = dims.SENSOR_LOW_HEIGHT + 0.03  # top of the low sensors' housings
    head_hi = dims.SENSOR_HIGH_HEIGHT + 0.03
    cam_x0, cam_x1 = dims.SENSOR_X - 0.045, dims.SENSOR_X + 0.01  # housings behind the lenses
    cam_z0 = dims.SENSOR_LOW_HEIGHT - 0.06 - 0.025  # under the lower (55 deg) sensor
    return (
        # The deck and everything on it up to the deck's top.
        Box("deck", (x_rear, -half_w, 0.0), (dims.CASTER_X + 0.1, half_w, deck_top)),
        # The rider, seated: a generous column from the seat back to in front of the knees.
        Box("rider", (x_rear - 0.1, -0.36, deck_top), (0.72, 0.36, 1.75)),
        # Tiller and handlebars.
        Box(
            "tiller",
            (dims.TILLER_X - 0.08, -dims.HANDLEBAR_WIDTH / 2 - 0.03, deck_top),
            (dims.TILLER_X + 0.09, dims.HANDLEBAR_WIDTH / 2 + 0.03, dims.HANDLEBAR_HEIGHT + 0.04),
        ),
        # The basket: its floor and four walls, open at the top for a drop.
        Box(
            "basket_floor",
            (bx0, by0, bz0 - dims.BASKET_FLOOR_THICKNESS),
            (bx1, by1, bz0 + w),
        ),
        Box("basket_front", (bx1 - w, by0, bz0), (bx1, by1, bz1)),
        Box("basket_back", (bx0, by0, bz0), (bx0 + w, by1, bz1)),
        Box("basket_left", (bx0, by1 - w, bz0), (bx1, by1, bz1)),
        Box("basket_right", (bx0, by0, bz0), (bx1, by0 + w, bz1)),
        # The sensor posts: thin poles, the cameras' heads near their tops, and the projector.
        Box(
            "pole_left",
            (post_x - 0.03, post_y - 0.03, deck_top),
            (post_x + 0.03, post_y + 0.03, head_hi),
        ),
        Box(
            "pole_right",
            (post_x - 0.03, -post_y - 0.03, deck_top),
            (post_x + 0.03, -post_y + 0.03, head_lo),
        ),
        # The camera housings near the posts' tops (the high sensor on the left one).
        Box("heads_left", (cam_x0, post_y - 0.07, cam_z0), (cam_x1, post_y + 0.07, head_lo)),
        Box(
            "high_left",
            (cam_x0 - 0.1, post_y - 0.07, head_hi - 0.1),
            (cam_x1, post_y + 0.07, head_hi),
        ),
        Box("heads_right", (cam_x0, -post_y - 0.07, cam_z0), (cam_x1, -post_y + 0.07, head_lo)),
        Box(
            "projector",
            (dims.PROJECTOR_POS[0] - 0.1, dims.PROJECTOR_POS[1] - 0.12, dims.PROJECTOR_POS[2]),
            (dims.PROJECTOR_POS[0] + 0.1, post_y + 0.02, dims.PROJECTOR_POS[2] + 0.08),
        ),
    )


#: Where the arm must never be, in `base`.
KEEPOUT_BOXES: tuple[Box, ...] = _keepout()
#: The floor: no sphere may dip below this height (m).
FLOOR_CLEARANCE = 0.02


def body_frames(q: np.ndarray) -> np.ndarray:
    """Frames of the six link bodies and the flange in `base`, batched:
    q (B, 6) -> (B, 7, 4, 4). Link i's body frame is DH frame i turned by q_{i+1}."""
    q = np.atleast_2d(np.asarray(q, float))
    B = len(q)
    out = np.empty((B, 7, 4, 4))
    T = np.broadcast_to(T_BASE_UR5, (B, 4, 4)).copy()
    for i in range(6):
        ct, st = np.cos(q[:, i]), np.sin(q[:, i])
        Rz = np.zeros((B, 4, 4))
        Rz[:, 0, 0], Rz[:, 0, 1], Rz[:, 1, 0], Rz[:, 1, 1] = ct, -st, st, ct
        Rz[:, 2, 2] = Rz[:, 3, 3] = 1.0
        body = T @ Rz
        out[:, i] = body
        # Into DH frame i+1: translate d along z, a along x, then twist alpha about x.
        ca, sa = math.cos(dims.UR5_ALPHA[i]), math.sin(dims.UR5_ALPHA[i])
        step = np.array(
            [
                [1.0, 0.0, 0.0, dims.UR5_A[i]],
                [0.0, ca, -sa, 0.0],
                [0.0, sa, ca, dims.UR5_D[i]],
                [0.0, 0.0, 0.0, 1.0],
            ]
        )
        T = body @ step
    out[:, 6] = T
    return out
