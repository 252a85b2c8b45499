"""What the robot looks like: its parts, the solids each is drawn with, and where each part is
for a joint state; what a URDF's `<visual>` elements and links would carry.

The parts are the scooter (its shell, posts, sensor and projector housings, basket and the
arm's pedestal), the arm's mount, the six UR5 links, the gripper and its two fingers. Each
part has a frame; its shapes are posed in it. `part_poses(q, width)` is the forward
kinematics of the parts: every part's frame in `base` for joint angles q and a gripper
opening. A 3D view draws the robot from these alone, for any robot that reports its joints.

The simulator builds its robot's geoms from these parts (it adds only what simulation needs:
masses, contact bits, friction), and the link shapes are the planner's collision capsules
(`shapes.LINK_CAPSULES`, `shapes.HOUSING_CAPSULES`).

Frames: the scooter's shapes are in `base`; the arm mount's in the UR5 base frame; link i's
in its body frame (`shapes.body_frames`); the gripper's in the flange frame (z approach,
y closing); each finger's in a frame shifted from the flange along y by half the opening.
Metres and radians throughout; colours are RGBA in [0, 1].
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from laserpick.description import dims
from laserpick.description.kinematics import T_BASE_UR5
from laserpick.description.shapes import (
    HOUSING_CAPSULES,
    HOUSINGS,
    LINK_CAPSULES,
    PEDESTAL_FOOT,
    PEDESTAL_RADIUS,
    POST_BACK,
    POST_RADIUS,
    PROJECTOR_HOUSING_RAISE,
    body_frames,
)
from laserpick.transforms import make_transform, rotx, turn_between

__all__ = [
    "ARM_RGBA",
    "BASKET_RGBA",
    "DARK_RGBA",
    "JOINT_RGBA",
    "PAD_RGBA",
    "PARTS",
    "SCOOTER_RGBA",
    "Part",
    "Shape",
    "finger",
    "part_poses",
]

ARM_RGBA = (0.62, 0.66, 0.72, 1.0)  #: the UR5's links and the gripper's fingers
JOINT_RGBA = (0.20, 0.45, 0.75, 1.0)  #: the UR5's joint housings
SCOOTER_RGBA = (0.75, 0.12, 0.12, 1.0)  #: the scooter's deck and tiller
DARK_RGBA = (0.12, 0.12, 0.13, 1.0)  #: seat, wheels, posts, housings, the gripper's body
PAD_RGBA = (0.05, 0.05, 0.05, 1.0)  #: the gripper's rubber pads
BASKET_RGBA = (0.15, 0.15, 0.16, 1.0)

Kind = Literal["box", "sphere", "capsule", "cylinder"]
RGBA = tuple[float, float, float, float]


@dataclass(frozen=True)
class Shape:
    """One solid of a part. `size`: a box's half extents; a sphere's (radius,); a capsule's
    or a cylinder's (radius, half length) along its own z axis (a capsule's length without
    its caps). `pose`: 4x4, the solid's frame in its part's frame (m). `fromto`: a capsule
    given by its axis' end points, (ax, ay, az, bx, by, bz) in the part's frame (m), from
    which its pose and half length follow; None for every other solid."""

    name: str
    kind: Kind
    size: tuple[float, ...]
    pose: np.ndarray
    rgba: RGBA
    fromto: tuple[float, ...] | None = None


@dataclass(frozen=True)
class Part:
    """A rigid part of the robot: its name (the simulator's body of that name) and shapes."""

    name: str
    shapes: tuple[Shape, ...]


def _at(pos, R: np.ndarray | None = None) -> np.ndarray:
    return make_transform(R, np.asarray(pos, dtype=float))


def _z_to(direction: np.ndarray) -> np.ndarray:
    """A rotation taking +z onto `direction` (unit), the shortest way."""
    return turn_between(np.array([0.0, 0.0, 1.0]), direction)


def _capsule(name: str, a, b, radius: float, rgba: RGBA) -> Shape:
    """A capsule whose axis runs from point a to point b (m, the part's frame)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    length = float(np.linalg.norm(b - a))
    R = _z_to((b - a) / length)
    ends = tuple(float(v) for v in (*a, *b))
    return Shape(name, "capsule", (radius, length / 2), _at((a + b) / 2, R), rgba, ends)


def _box(name: str, half, pos, rgba: RGBA, R: np.ndarray | None = None) -> Shape:
    return Shape(name, "box", tuple(float(h) for h in half), _at(pos, R), rgba)


# --- the scooter, in `base` ---------------------------------------------------------------------


def _seat_and_tiller() -> list[Shape]:
    tiller_bottom = (dims.TILLER_X + dims.TILLER_FOOT_AHEAD, 0.0, dims.SCOOTER_DECK_HEIGHT)
    tiller_top = (dims.TILLER_X, 0.0, dims.HANDLEBAR_HEIGHT)
    half, bar_x, bar_z = dims.HANDLEBAR_WIDTH / 2, dims.TILLER_X - 0.03, dims.HANDLEBAR_HEIGHT
    return [
        Shape(
            "scooter/seat_post", "cylinder", (0.035, 0.12), _at((dims.SEAT_X, 0, 0.42)), DARK_RGBA
        ),
        _box(
            "scooter/seat", (0.22, 0.24, 0.05), (dims.SEAT_X, 0, dims.SEAT_HEIGHT - 0.05), DARK_RGBA
        ),
        _box(
            "scooter/seat_back",
            (0.05, 0.23, 0.2),
            (dims.SEAT_X - 0.2, 0, dims.SEAT_BACK_HEIGHT - 0.2),
            DARK_RGBA,
        ),
        _capsule("scooter/tiller", tiller_bottom, tiller_top, dims.TILLER_RADIUS, SCOOTER_RGBA),
        _capsule(
            "scooter/handlebar", (bar_x, half, bar_z), (bar_x, -half, bar_z), 0.018, DARK_RGBA
        ),
    ]


def _wheels() -> list[Shape]:
    size = (dims.WHEEL_RADIUS, dims.WHEEL_WIDTH / 2)
    axle = rotx(math.pi / 2)
    wheels = [
        Shape(
            f"scooter/wheel_{side}",
            "cylinder",
            size,
            _at((0, sign * dims.WHEEL_TRACK / 2, dims.WHEEL_RADIUS), axle),
            DARK_RGBA,
        )
        for side, sign in (("left", 1), ("right", -1))
    ]
    caster = Shape(
        "scooter/caster",
        "sphere",
        (dims.CASTER_RADIUS,),
        _at((dims.CASTER_X, 0, dims.CASTER_RADIUS)),
        DARK_RGBA,
    )
    return [*wheels, caster]


def _posts_and_housings() -> list[Shape]:
    shapes = [_box(f"scooter/{h.name}", h.half, h.centre, DARK_RGBA, h.R) for h in HOUSINGS]
    x = dims.SENSOR_X - POST_BACK
    for side, y, top in (
        ("left", dims.SENSOR_GROUP_SPACING / 2, dims.SENSOR_HIGH_HEIGHT),
        ("right", -dims.SENSOR_GROUP_SPACING / 2, dims.SENSOR_LOW_HEIGHT),
    ):
        foot, head = (x, y, dims.SCOOTER_DECK_HEIGHT), (x, y, top - 0.02)
        shapes.append(_capsule(f"scooter/post_{side}", foot, head, POST_RADIUS, DARK_RGBA))
    # The projector's bracket, from the tall post to the projector's housing at its height.
    px, py, pz = dims.PROJECTOR_POS
    z = pz + PROJECTOR_HOUSING_RAISE
    post = (x, dims.SENSOR_GROUP_SPACING / 2, z)
    shapes.append(_capsule("scooter/projector_bracket", post, (px, py, z), 0.012, DARK_RGBA))
    return shapes


def _basket() -> list[Shape]:
    """A floor and four walls, open at the top."""
    c, inner, w = dims.BASKET_CENTER, dims.BASKET_INNER, dims.BASKET_WALL
    hx, hy, hz = inner / 2
    floor_t = dims.BASKET_FLOOR_THICKNESS
    shapes = [
        _box(
            "scooter/basket_floor",
            (hx + w, hy + w, floor_t / 2),
            c + np.array([0.0, 0.0, -hz - floor_t / 2]),
            BASKET_RGBA,
        )
    ]
    for name, pos, half in (
        ("basket_front", (hx + w / 2, 0, 0), (w / 2, hy + w, hz)),
        ("basket_back", (-hx - w / 2, 0, 0), (w / 2, hy + w, hz)),
        ("basket_left", (0, hy + w / 2, 0), (hx, w / 2, hz)),
        ("basket_right", (0, -hy - w / 2, 0), (hx, w / 2, hz)),
    ):
        shapes.append(_box(f"scooter/{name}", half, c + np.array(pos), BASKET_RGBA))
    return shapes


def _scooter() -> tuple[Shape, ...]:
    x0 = -dims.SCOOTER_REAR_OVERHANG
    length = dims.SCOOTER_LENGTH - 0.12  # the basket overhangs the deck's front edge
    deck = _box(
        "scooter/deck",
        (length / 2, dims.SCOOTER_WIDTH / 2, dims.SCOOTER_DECK_THICKNESS / 2),
        (x0 + length / 2, 0, dims.SCOOTER_DECK_HEIGHT - dims.SCOOTER_DECK_THICKNESS / 2),
        SCOOTER_RGBA,
    )
    mx, my, mz = dims.ARM_MOUNT_POS
    pedestal = Shape(
        "scooter/arm_pedestal",
        "cylinder",
        (PEDESTAL_RADIUS, (mz - PEDESTAL_FOOT) / 2),
        _at((mx, my, (mz + PEDESTAL_FOOT) / 2)),
        DARK_RGBA,
    )
    bracket_half, bracket_at = ((mx - 0.9) / 2 + 0.05, 0.05, 0.04), ((mx + 0.9) / 2, my, 0.19)
    bracket = _box("scooter/arm_bracket", bracket_half, bracket_at, DARK_RGBA)
    parts = [deck, *_seat_and_tiller(), *_wheels(), *_posts_and_housings(), *_basket()]
    return (*parts, pedestal, bracket)


# --- the arm and the gripper ----------------------------------------------------------------------


def _link(i: int) -> tuple[Shape, ...]:
    """Link i+1's capsules and its joint's housing, in its body frame."""
    shapes = []
    for k, (p0, p1, radius) in enumerate(LINK_CAPSULES[i]):
        if np.allclose(p0, p1):
            p1 = (p1[0], p1[1], p1[2] + 1e-3)
        shapes.append(_capsule(f"ur5/link{i + 1}/c{k}", p0, p1, radius, ARM_RGBA))
    _, end, radius = HOUSING_CAPSULES[i]  # centred on the body's origin, along z
    name = f"ur5/link{i + 1}/joint"
    if end[2] > 0:
        shapes.append(Shape(name, "capsule", (radius, end[2]), np.eye(4), JOINT_RGBA))
    else:
        shapes.append(Shape(name, "sphere", (radius,), np.eye(4), JOINT_RGBA))
    return tuple(shapes)


def _gripper() -> tuple[Shape, ...]:
    L = dims.GRIPPER_BASE_LENGTH
    body = (dims.GRIPPER_BODY_DEPTH / 2, dims.GRIPPER_BODY_WIDTH / 2, L / 2 - 0.01)
    return (
        _box("gripper/housing", body, (0, 0, L / 2 + 0.01), DARK_RGBA),
        Shape("gripper/coupling", "cylinder", (0.038, 0.006), _at((0, 0, 0.006)), ARM_RGBA),
    )


def finger(side: Literal["left", "right"], travel: float = 0.0) -> Part:
    """The finger on `side` (left: +y): its plate and its pad, posed so that the pad's face
    lies `travel` (m) out from its frame's origin along the closing axis. `PARTS` holds them
    at travel 0, in the frame `part_poses` gives the finger (the flange frame moved out by half
    the opening); in the flange frame itself, travel `dims.GRIPPER_STROKE` / 2 is the finger
    fully open."""
    sign = 1.0 if side == "left" else -1.0
    L, F = dims.GRIPPER_BASE_LENGTH, dims.GRIPPER_FINGER_LENGTH
    plate_t, pad_t = dims.GRIPPER_FINGER_THICKNESS, dims.GRIPPER_PAD_THICKNESS
    plate = (dims.GRIPPER_FINGER_WIDTH / 2, plate_t / 2, F / 2)
    pad = (dims.GRIPPER_PAD_WIDTH / 2, pad_t / 2, dims.GRIPPER_PAD_DEPTH / 2)
    plate_at = (0, sign * (travel + pad_t + plate_t / 2), L + F / 2)
    pad_at = (0, sign * (travel + pad_t / 2), L + F - dims.GRIPPER_PAD_DEPTH / 2)
    plate_box = _box(f"gripper/finger_{side}", plate, plate_at, ARM_RGBA)
    return Part(f"finger_{side}", (plate_box, _box(f"gripper/pad_{side}", pad, pad_at, PAD_RGBA)))


#: The robot's parts in the order `part_poses` gives their frames.
PARTS: tuple[Part, ...] = (
    Part("scooter", _scooter()),
    Part(
        "ur5/base",
        (_capsule("ur5/base/c", (0, 0, 0), (0, 0, 0.03), dims.UR5_LINK_RADII[0], DARK_RGBA),),
    ),
    *(Part(f"ur5/link{i + 1}", _link(i)) for i in range(6)),
    Part("gripper", _gripper()),
    finger("left"),
    finger("right"),
)


def part_poses(q: np.ndarray, width: float) -> np.ndarray:
    """Each part's frame in `base` (len(PARTS), 4, 4) for UR5 joint angles q (6,) rad and
    the gripper opened `width` (m) between its pads."""
    links = body_frames(q)[0]  # six link frames, then the flange
    flange = links[6]
    half = 0.5 * float(width)
    fingers = [flange @ _at((0.0, sign * half, 0.0)) for sign in (1.0, -1.0)]
    return np.stack([np.eye(4), T_BASE_UR5, *links[:6], flange, *fingers])
