"""Postures that lay a held object into the basket: its own outline placed inside the
opening, low, with the hand turned the ways that can fit it there. Frames: points in the
TCP frame or `base` (m), as each function says; joint angles in rad.
"""

from __future__ import annotations

import functools
import itertools
from collections.abc import Sequence

import numpy as np

from laserpick.description import dims
from laserpick.description.kinematics import ik_tcp
from laserpick.pipeline.collision import PAYLOAD_POINT_RADIUS, CollisionChecker
from laserpick.transforms import roty, rotz

__all__ = ["hand_down_turns", "hand_turns", "laid_in_candidates", "scooter_only", "squared_turns"]

#: The hand pointing down: the TCP's approach axis along -z of `base`.
DOWN = np.diag([1.0, -1.0, -1.0])


@functools.cache
def scooter_only(margin: float = 0.01) -> CollisionChecker:
    """A checker with no cloud: the arm against the scooter, its rider and itself, keeping
    `margin` (m) of clearance."""
    return CollisionChecker(np.zeros((0, 3)), margin=margin)


def hand_turns(yaws: Sequence[float], tilts: Sequence[float]) -> list[np.ndarray]:
    """Hand orientations (3, 3; TCP to `base`): pointing down, tilted up by each of `tilts`
    (deg) and turned about the vertical by each of `yaws` (deg); yaw-major order."""
    turns = itertools.product(np.radians(yaws), np.radians(tilts))
    return [rotz(yaw) @ roty(tilt) @ DOWN for yaw, tilt in turns]


def hand_down_turns() -> list[np.ndarray]:
    """Hand orientations (3, 3; TCP to `base`): pointing down or tilted up to 30 deg, turned
    any way about the vertical in 30 deg steps."""
    return hand_turns(np.arange(0, 360, 30), (0, 15, 30))


def squared_turns(held: np.ndarray) -> list[np.ndarray]:
    """Hand orientations (3, 3; TCP to `base`) that line the held object's own axes up with
    the basket's, every way round (24): its principal axes, of its points `held` (P, 3; TCP
    frame, m), along `base`'s x, y and z. A box the hand holds askew stands in the fewest
    centimetres of the opening squared with it: a cereal box gripped 7.5 deg off its side
    took 12 cm of the opening's 15 for its 6 cm with the hand pointing down."""
    if len(held) < 3:
        return []
    centred = held - held.mean(axis=0)
    _, axes = np.linalg.eigh(centred.T @ centred)  # columns: the object's axes, TCP frame
    out = []
    for order in itertools.permutations(range(3)):
        for signs in itertools.product((1.0, -1.0), repeat=3):
            B = np.zeros((3, 3))
            B[list(order), range(3)] = signs  # object axis i -> base axis order[i]
            if np.linalg.det(B) * np.linalg.det(axes) > 0:  # a turn, not a mirror
                out.append(B @ axes.T)
    return out


def laid_in_candidates(
    held: np.ndarray, q_ref: np.ndarray, lows: Sequence[float], margin: float
) -> list[np.ndarray]:
    """Joint configurations (rad) that lay the held object (`held`, its points (P, 3) in
    the TCP frame, m: as carried and as it falls) into the basket, low: its lowest point
    `lows` (m) over the basket's floor, its outline within the opening and `margin` (m, the
    clearance the check keeps) off the walls, at the middle and at either side of the room
    it has there. The hand points down or tilted (`hand_down_turns`), or squares the object
    with the basket (`squared_turns`). Only turns whose outline fits the opening are tried,
    and only configurations clear of the scooter are kept (the object itself is checked
    when they are ranked).

    The fixed grid of `drop_candidates` places the hand, not the object: a cereal box held
    1.4 cm off its middle reached 3 mm past the opening from every posture of the grid that
    turned it the right way, and was let go across the rims from higher up instead."""
    if len(held) == 0:
        return []
    half = dims.BASKET_INNER[:2] / 2 - max(margin + PAYLOAD_POINT_RADIUS, 0.01)
    lo, hi = dims.BASKET_CENTER[:2] - half, dims.BASKET_CENTER[:2] + half
    floor = dims.BASKET_FLOOR
    free = scooter_only()
    out: list[np.ndarray] = []
    for R in [*hand_down_turns(), *squared_turns(held)]:
        turned = held @ R.T
        low, high = turned.min(axis=0), turned.max(axis=0)
        room = (hi - lo) - (high - low)[:2]
        if (room < 0).any():
            continue
        # In whole cm, rounded down: a spot never reaches past the room it has.
        spots = itertools.product(*(np.unique(np.floor([0, 50 * r, 100 * r]) / 100) for r in room))
        for (sx, sy), above in itertools.product(spots, lows):
            T = np.eye(4)
            T[:3, :3] = R
            T[:3, 3] = [lo[0] + sx - low[0], lo[1] + sy - low[1], floor + above - low[2]]
            Q = ik_tcp(T, q_ref)
            out += [q for q, ok in zip(Q, free.clearance_ok(Q), strict=True) if ok]
    return out
