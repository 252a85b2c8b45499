"""The scooter's shell in `base`: deck, seat, tiller, wheels, sensor posts, basket, pedestal."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from laserpick.description import dims
from laserpick.description.shapes import (
    HOUSINGS,
    PEDESTAL_FOOT,
    PEDESTAL_RADIUS,
    POST_BACK,
    POST_RADIUS,
    PROJECTOR_HOUSING_RAISE,
)
from laserpick.robot.sim.model.geoms import (
    DARK_RGBA,
    SCOOTER_AFFINITY,
    SCOOTER_RGBA,
    SCOOTER_TYPE,
    G,
    add_geom,
    quat_list,
)
from laserpick.robot.sim.model.names import SCOOTER_COLLISION_PREFIX
from laserpick.robot.sim.objects import GROUP_ROBOT
from laserpick.transforms import rotx


def _shell(body: mujoco.MjsBody, name: str, kind, size, pos, rgba=SCOOTER_RGBA, quat=None, **kw):
    """A massless geom of the scooter's shell, in `base`."""
    g = add_geom(
        body,
        SCOOTER_COLLISION_PREFIX + name,
        kind,
        size,
        pos,
        rgba=list(rgba),
        group=GROUP_ROBOT,
        contype=SCOOTER_TYPE,
        conaffinity=SCOOTER_AFFINITY,
        mass=0.0,
        **kw,
    )
    if quat is not None:
        g.quat = list(quat)
    return g


def _shell_capsule(body: mujoco.MjsBody, name: str, a, b, radius: float, rgba=DARK_RGBA) -> None:
    """A shell capsule from point a to point b in `base` (m)."""
    _shell(body, name, G.mjGEOM_CAPSULE, (radius,), (0, 0, 0), rgba, fromto=[*a, *b])


def add_scooter_shell(body: mujoco.MjsBody) -> None:
    """Deck, seat, tiller, handlebars, wheels, sensor posts and the basket, in `base`."""
    _add_deck_and_seat(body)
    _add_tiller(body)
    _add_wheels(body)
    _add_sensor_posts(body)
    _add_basket(body)
    _add_arm_pedestal(body)


def _add_deck_and_seat(body: mujoco.MjsBody) -> None:
    """The deck, and the seat on it: a post, a cushion and a backrest."""
    x0 = -dims.SCOOTER_REAR_OVERHANG
    length = dims.SCOOTER_LENGTH - 0.12  # the basket overhangs the deck's front edge
    deck_z = dims.SCOOTER_DECK_HEIGHT - dims.SCOOTER_DECK_THICKNESS / 2
    _shell(
        body,
        "deck",
        G.mjGEOM_BOX,
        (length / 2, dims.SCOOTER_WIDTH / 2, dims.SCOOTER_DECK_THICKNESS / 2),
        (x0 + length / 2, 0, deck_z),
    )
    _shell(body, "seat_post", G.mjGEOM_CYLINDER, (0.035, 0.12), (dims.SEAT_X, 0, 0.42), DARK_RGBA)
    _shell(
        body,
        "seat",
        G.mjGEOM_BOX,
        (0.22, 0.24, 0.05),
        (dims.SEAT_X, 0, dims.SEAT_HEIGHT - 0.05),
        DARK_RGBA,
    )
    _shell(
        body,
        "seat_back",
        G.mjGEOM_BOX,
        (0.05, 0.23, 0.2),
        (dims.SEAT_X - 0.2, 0, dims.SEAT_BACK_HEIGHT - 0.2),
        DARK_RGBA,
    )


def _add_tiller(body: mujoco.MjsBody) -> None:
    """The tiller, leaning back toward the rider, and the handlebars across its top."""
    tiller_bottom = np.array([dims.TILLER_X + 0.04, 0.0, dims.SCOOTER_DECK_HEIGHT])
    tiller_top = np.array([dims.TILLER_X, 0.0, dims.HANDLEBAR_HEIGHT])
    _shell_capsule(body, "tiller", tiller_bottom, tiller_top, 0.04, SCOOTER_RGBA)
    half, bar_x = dims.HANDLEBAR_WIDTH / 2, dims.TILLER_X - 0.03
    _shell_capsule(
        body,
        "handlebar",
        (bar_x, half, dims.HANDLEBAR_HEIGHT),
        (bar_x, -half, dims.HANDLEBAR_HEIGHT),
        0.018,
    )


def _add_wheels(body: mujoco.MjsBody) -> None:
    """Rear drive wheels on the axle (x = 0) and a front caster."""
    # Visual and collision only: the base's planar joints, not wheel contacts, carry the scooter.
    wheel_q = quat_list(rotx(math.pi / 2))
    for side, sign in (("left", 1), ("right", -1)):
        _shell(
            body,
            f"wheel_{side}",
            G.mjGEOM_CYLINDER,
            (dims.WHEEL_RADIUS, dims.WHEEL_WIDTH / 2),
            (0, sign * dims.WHEEL_TRACK / 2, dims.WHEEL_RADIUS),
            DARK_RGBA,
            quat=wheel_q,
        )
    _shell(
        body,
        "caster",
        G.mjGEOM_SPHERE,
        (dims.CASTER_RADIUS,),
        (dims.CASTER_X, 0, dims.CASTER_RADIUS),
        DARK_RGBA,
    )


def _add_sensor_posts(body: mujoco.MjsBody) -> None:
    """The sensors' housings and the two uprights that carry them."""
    # The cameras' and the projector's housings, as the planner's keep-out boxes know them.
    for h in HOUSINGS:
        _shell(body, h.name, G.mjGEOM_BOX, h.half, h.centre, DARK_RGBA, quat=quat_list(h.R))
    # Two uprights carrying the four low sensors, the left one taller for the fifth sensor.
    for side, y, top in (
        ("left", dims.SENSOR_GROUP_SPACING / 2, dims.SENSOR_HIGH_HEIGHT),
        ("right", -dims.SENSOR_GROUP_SPACING / 2, dims.SENSOR_LOW_HEIGHT),
    ):
        x = dims.SENSOR_X - POST_BACK
        _shell_capsule(
            body, f"post_{side}", (x, y, dims.SCOOTER_DECK_HEIGHT), (x, y, top - 0.02), POST_RADIUS
        )
    # The projector's bracket, from the tall post to the projector's housing at its height.
    px, py, pz = dims.PROJECTOR_POS
    bracket_z = pz + PROJECTOR_HOUSING_RAISE
    _shell_capsule(
        body,
        "projector_bracket",
        (dims.SENSOR_X - POST_BACK, dims.SENSOR_GROUP_SPACING / 2, bracket_z),
        (px, py, bracket_z),
        0.012,
    )


def _add_basket(body: mujoco.MjsBody) -> None:
    """The basket: a floor and four walls, open at the top."""
    c, inner, w = dims.BASKET_CENTER, dims.BASKET_INNER, dims.BASKET_WALL
    hx, hy, hz = inner / 2
    basket_rgba = (0.15, 0.15, 0.16, 1.0)
    _shell(
        body,
        "basket_floor",
        G.mjGEOM_BOX,
        (hx + w, hy + w, dims.BASKET_FLOOR_THICKNESS / 2),
        c + np.array([0.0, 0.0, -hz - dims.BASKET_FLOOR_THICKNESS / 2]),
        basket_rgba,
    )
    for name, pos, size in (
        ("basket_front", (hx + w / 2, 0, 0), (w / 2, hy + w, hz)),
        ("basket_back", (-hx - w / 2, 0, 0), (w / 2, hy + w, hz)),
        ("basket_left", (0, hy + w / 2, 0), (hx, w / 2, hz)),
        ("basket_right", (0, -hy - w / 2, 0), (hx, w / 2, hz)),
    ):
        _shell(body, name, G.mjGEOM_BOX, size, c + np.array(pos), basket_rgba)


def _add_arm_pedestal(body: mujoco.MjsBody) -> None:
    """The arm's pedestal on the front of the deck, and its bracket."""
    mx, my, mz = dims.ARM_MOUNT_POS
    _shell(
        body,
        "arm_pedestal",
        G.mjGEOM_CYLINDER,
        (PEDESTAL_RADIUS, (mz - PEDESTAL_FOOT) / 2),
        (mx, my, (mz + PEDESTAL_FOOT) / 2),
        DARK_RGBA,
    )
    _shell(
        body,
        "arm_bracket",
        G.mjGEOM_BOX,
        ((mx - 0.9) / 2 + 0.05, 0.05, 0.04),
        ((mx + 0.9) / 2, my, 0.19),
        DARK_RGBA,
    )
