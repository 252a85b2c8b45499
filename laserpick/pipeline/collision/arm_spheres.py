"""The arm and its gripper as chains of spheres, placed by the body frames of a configuration.

Spheres cover the capsules of `description/shapes.py`: a capsule of radius r as spheres at
most r apart, each grown to cover the waist between neighbours. Frames: `base`, metres.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from laserpick.description.shapes import (
    GRIPPER_CAPSULES,
    HOUSING_CAPSULES,
    LINK_CAPSULES,
    Segment,
)

#: The body a held object's spheres count as.
HAND_BODY = 6


@dataclass(frozen=True)
class SphereModel:
    """Sphere centres in their body frames and radii (m). body: 0..5 the links, 6 the flange."""

    body: np.ndarray  #: (S,) int
    centre: np.ndarray  #: (S, 3) in the body's frame
    radius: np.ndarray  #: (S,)
    hand: np.ndarray  #: (S,) bool: part of the gripper


def _segment_spheres(segment: Segment) -> tuple[np.ndarray, float]:
    a, b, r = np.asarray(segment[0], float), np.asarray(segment[1], float), segment[2]
    length = float(np.linalg.norm(b - a))
    if length == 0.0:  # a ball: a joint housing
        return a[None], r
    n = max(2, math.ceil(length / r) + 1)
    return np.linspace(a, b, n), math.hypot(r, length / (n - 1) / 2)


def sphere_model() -> SphereModel:
    """The arm's spheres, built from the shared tables of link capsules, joint housings
    and gripper capsules."""
    body, centre, radius, hand = [], [], [], []
    parts = [(i, seg, False) for i, segs in enumerate(LINK_CAPSULES) for seg in segs]
    parts += [(i, seg, False) for i, seg in enumerate(HOUSING_CAPSULES)]
    parts += [(6, seg, True) for seg in GRIPPER_CAPSULES]
    for i, seg, is_hand in parts:
        c, r = _segment_spheres(seg)
        body += [i] * len(c)
        centre.append(c)
        radius += [r] * len(c)
        hand += [is_hand] * len(c)
    return SphereModel(
        np.array(body), np.vstack(centre), np.array(radius), np.array(hand, dtype=bool)
    )


SPHERES = sphere_model()


def sphere_centres(frames: np.ndarray, model: SphereModel = SPHERES) -> np.ndarray:
    """World (`base`) centres (B, S, 3) of the spheres for body frames (B, 7, 4, 4)."""
    F = frames[:, model.body]  # (B, S, 4, 4)
    return np.einsum("bsij,sj->bsi", F[..., :3, :3], model.centre) + F[..., :3, 3]
