"""Collision geometry of the robot for planning: the UR5's link capsules, the gripper's, and
keep-out boxes around the scooter and its rider.

The same tables build the MuJoCo model (robot/sim/model/) and the planner's sphere model and
keep-out boxes (pipeline/collision/), so what the planner avoids is what the simulator
collides: the link capsules, the joint housings around each joint, and the boxes of the
cameras and the projector on the scooter's posts.

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
from laserpick.transforms import roty, rotz

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
#: The joint housings: a ball, or a short capsule along the joint's axis, around each link's
#: joint at its body frame's origin (from, to, radius; m). A little wider than the link
#: tubes, they reach past the tubes' ends, where the wrist's housing would otherwise meet the
#: projector unplanned.
HOUSING_CAPSULES: tuple[Segment, ...] = tuple(
    ((0.0, 0.0, -reach), (0.0, 0.0, reach), r)
    for r, reach in (
        (radius * 1.08, max(0.0, (0.06 if i < 3 else 0.045) - radius * 1.08))
        for i, radius in enumerate(dims.UR5_LINK_RADII[1:])
    )
)

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


#: The rotation of an axis-aligned box.
IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


@dataclass(frozen=True)
class Box:
    """A keep-out box: lower and upper corners (m) along its own axes, the columns of the
    rotation `turn` (identity: axis-aligned in `base`); a point p of `base` lies in it where
    lo <= turn.T @ p <= hi. `spares`: the arm's bodies (0 = link1 ... 6 = the hand) not
    checked against it, as the first link standing on the arm's pedestal."""

    name: str
    lo: tuple[float, float, float]
    hi: tuple[float, float, float]
    spares: tuple[int, ...] = ()
    turn: tuple[tuple[float, float, float], ...] = IDENTITY


@dataclass(frozen=True)
class Housing:
    """A box-shaped part on the scooter's posts, in `base`: its centre (m), its half extents
    in its own frame (m) and that frame's rotation."""

    name: str
    centre: tuple[float, float, float]
    half: tuple[float, float, float]
    R: np.ndarray

    def keepout(self, pad: float) -> Box:
        """The keep-out box of it, `pad` (m) larger on every side."""
        middle = self.R.T @ np.asarray(self.centre)
        half = np.asarray(self.half) + pad
        turn = tuple(tuple(float(v) for v in row) for row in self.R)
        return Box(self.name, tuple(middle - half), tuple(middle + half), turn=turn)


#: A depth sensor's housing (half extents, m, in the sensor's frame: x along its view) and
#: how far behind the lens its centre sits (m), so that no camera sees its own box.
SENSOR_HOUSING_HALF = (0.015, 0.06, 0.015)
SENSOR_HOUSING_BEHIND = 0.02
#: The projector's housing (half extents, m) and its centre's height over the lens (m).
PROJECTOR_HOUSING_HALF = (0.06, 0.09, 0.035)
PROJECTOR_HOUSING_RAISE = 0.03
#: The sensor posts' radius (m): poles at x = SENSOR_X - POST_BACK, y = +-spacing / 2.
POST_RADIUS = 0.015
POST_BACK = 0.1
#: The arm's pedestal: a column (radius, m) from the bracket at this height (m) up to the
#: arm's mount.
PEDESTAL_RADIUS = 0.07
PEDESTAL_FOOT = 0.15
#: Clearance (m) the keep-out boxes add around the posts, the pedestal, the housings and the
#: steering column.
HOUSING_PAD = 0.005
#: How far forward (m, `base` x) the arm keeps from the rider's hands on the handlebars.
TILLER_FRONT = dims.TILLER_X + 0.09


def _housings() -> tuple[Housing, ...]:
    out = []
    for mount in dims.CAMERA_MOUNTS:
        R = rotz(mount.yaw) @ roty(mount.pitch_down)
        centre = np.asarray(mount.pos) - R[:, 0] * SENSOR_HOUSING_BEHIND
        out.append(Housing(f"sensor_{mount.name}", tuple(centre), SENSOR_HOUSING_HALF, R))
    px, py, pz = dims.PROJECTOR_POS
    out.append(
        Housing(
            "projector",
            (px, py, pz + PROJECTOR_HOUSING_RAISE),
            PROJECTOR_HOUSING_HALF,
            rotz(dims.PROJECTOR_YAW),
        )
    )
    return tuple(out)


#: The five depth sensors' housings and the projector's.
HOUSINGS: tuple[Housing, ...] = _housings()


def _tiller(deck_top: float, basket_back: tuple[float, float], rim: float) -> tuple[Box, ...]:
    """The tiller's and the handlebars' keep-out boxes. The rider's hands are on the
    handlebars: the arm keeps 12 cm ahead of them (x to `TILLER_FRONT`) over the basket's rim
    (`rim`, m) and beside the basket, and behind its back wall (`basket_back`: the back
    wall's outer x and the right wall's outer y, m). Inside the basket, only the steering
    column itself (a box along its lean): as one box, the tiller took the back 6 cm of the
    basket's 20, and a cereal box held in the hand fitted nowhere inside."""
    lo_x, hi_y = dims.TILLER_X - 0.08, dims.HANDLEBAR_WIDTH / 2 + 0.03
    back_x, right_y = basket_back
    top = dims.HANDLEBAR_HEIGHT + 0.04
    foot = np.array([dims.TILLER_X + dims.TILLER_FOOT_AHEAD, 0.0, deck_top])
    head = np.array([dims.TILLER_X, 0.0, dims.HANDLEBAR_HEIGHT])
    axis = head - foot
    R = roty(math.atan2(axis[0], axis[2]))  # the box's z along the column
    middle = R.T @ ((foot + head) / 2)
    half = np.array([dims.TILLER_RADIUS, dims.TILLER_RADIUS, np.linalg.norm(axis) / 2])
    half += HOUSING_PAD
    turn = tuple(tuple(float(v) for v in row) for row in R)
    return (
        Box("tiller", (lo_x, -hi_y, deck_top), (back_x, hi_y, top)),
        Box("tiller_over_basket", (back_x, -hi_y, rim), (TILLER_FRONT, hi_y, top)),
        Box("tiller_beside_basket", (back_x, -hi_y, deck_top), (TILLER_FRONT, right_y, rim)),
        Box("tiller_column", tuple(middle - half), tuple(middle + half), turn=turn),
    )


def _keepout() -> tuple[Box, ...]:
    deck_top = dims.SCOOTER_DECK_HEIGHT
    x_rear = -dims.SCOOTER_REAR_OVERHANG
    half_w = dims.SCOOTER_WIDTH / 2
    w = dims.BASKET_WALL + 0.005
    bx0, by0, bz0 = dims.BASKET_CENTER - dims.BASKET_INNER / 2 - w
    bx1, by1, bz1 = dims.BASKET_CENTER + dims.BASKET_INNER / 2 + w
    post_x = dims.SENSOR_X - POST_BACK
    post_y = dims.SENSOR_GROUP_SPACING / 2
    pole = POST_RADIUS + HOUSING_PAD
    mx, my, mz = dims.ARM_MOUNT_POS
    pedestal = PEDESTAL_RADIUS + HOUSING_PAD
    bracket_z = dims.PROJECTOR_POS[2] + PROJECTOR_HOUSING_RAISE  # the projector's bracket
    head_lo = dims.SENSOR_LOW_HEIGHT + 0.03  # top of the low sensors' housings
    head_hi = dims.SENSOR_HIGH_HEIGHT + 0.03
    return (
        # The deck and everything on it up to the deck's top.
        Box("deck", (x_rear, -half_w, 0.0), (dims.CASTER_X + 0.1, half_w, deck_top)),
        # The rider, seated: a generous column from the seat back to in front of the knees.
        Box("rider", (x_rear - 0.1, -0.36, deck_top), (0.72, 0.36, 1.75)),
        *_tiller(deck_top, (bx0, by0), bz1),
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
        # The arm's pedestal: the first link turns on its top.
        Box(
            "arm_pedestal",
            (mx - pedestal, my - pedestal, PEDESTAL_FOOT),
            (mx + pedestal, my + pedestal, mz),
            spares=(0,),
        ),
        # The sensor posts: thin poles up to the cameras' heads.
        Box(
            "pole_left",
            (post_x - pole, post_y - pole, deck_top - pole),
            (post_x + pole, post_y + pole, head_hi),
        ),
        Box(
            "pole_right",
            (post_x - pole, -post_y - pole, deck_top - pole),
            (post_x + pole, -post_y + pole, head_lo),
        ),
        # The projector's bracket from the left post to over the scooter's middle.
        Box(
            "projector_bracket",
            (post_x - 0.03, dims.PROJECTOR_POS[1] - 0.03, bracket_z - 0.03),
            (post_x + 0.03, post_y, bracket_z + 0.03),
        ),
        # Each camera's housing and the projector's, padded.
        *(h.keepout(HOUSING_PAD) for h in HOUSINGS),
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
