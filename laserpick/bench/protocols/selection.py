"""selection (004 section 8.4): two objects side by side; one attempt with automatic and one
with manual selection, each from the same start."""

from __future__ import annotations

import math

import numpy as np

from laserpick.bench.attempts import Attempt
from laserpick.bench.protocols.trials import (
    Options,
    instances,
    protocol_scene,
    scripted_operator,
)
from laserpick.robot.sim.objects import LIBRARY, footprint_half_extents, rest_pose
from laserpick.robot.sim.scenes import Scene, parse_scene, scene_config

#: The models of the two-object selection trials: the `isolation` set less the tall cereal
#: box, which would hide its neighbour from every camera.
PAIR_MODELS = [m for m in scene_config("isolation")["random"][0]["models"] if m != "cereal_box"]
_PAIR = """
name: pair
description: two objects side by side (004 section 8.4)
scooter: {{x: 0.0, y: 0.0, yaw_deg: 0.0}}
surfaces:
  - {{name: table, kind: table, xy: [1.60, -0.15], yaw_deg: 0, size: [0.6, 1.0], height: 0.46}}
objects:
  - {{name: {a}, model: {a}, on: table, xy: [{ax:.4f}, {ay:.4f}], yaw_deg: {ayaw:.1f}}}
  - {{name: {b}, model: {b}, on: table, xy: [{bx:.4f}, {by:.4f}], yaw_deg: {byaw:.1f}}}
"""
PAIR_FIRST_XY = np.array([1.50, -0.36])  #: m, world: the first object, in front of the arm
PAIR_GAP = (0.0, 0.01)  #: m between the two objects, drawn uniformly: touching to 1 cm apart


def _reach(name: str, yaw: float, d: np.ndarray) -> float:
    """How far (m) the object's footprint (as the scene checks overlaps) reaches along the
    world direction `d` (unit, 2D) from its centre, at `yaw` (rad)."""
    model = LIBRARY[name]
    half = footprint_half_extents(model, rest_pose(model))
    c, s = math.cos(yaw), math.sin(yaw)
    return float(half[0] * abs(c * d[0] + s * d[1]) + half[1] * abs(-s * d[0] + c * d[1]))


def pair_scene(rng: np.random.Generator) -> Scene:
    """Two random models at random yaws, the second beside the first (+y), 0-1 cm apart."""
    a, b = (str(m) for m in rng.choice(PAIR_MODELS, size=2, replace=False))
    ya, yb = rng.uniform(0, 2 * math.pi, 2)
    d = np.array([0.0, 1.0])
    xy_b = PAIR_FIRST_XY + d * (_reach(a, ya, d) + _reach(b, yb, -d) + rng.uniform(*PAIR_GAP))
    text = _PAIR.format(
        a=a,
        b=b,
        ax=PAIR_FIRST_XY[0],
        ay=PAIR_FIRST_XY[1],
        ayaw=math.degrees(ya),
        bx=xy_b[0],
        by=xy_b[1],
        byaw=math.degrees(yb),
    )
    return parse_scene(text)


def selection(trial: int, seed: int, opt: Options) -> list[Attempt]:
    """One selection trial: the same target picked with automatic and manual selection."""
    rng = np.random.default_rng(seed)
    scene = protocol_scene("", seed, opt) if opt.scene else pair_scene(rng)
    target = str(rng.choice(instances(scene)))
    out = []
    for mode in ("auto", "manual"):
        with scripted_operator(scene, trial, seed, opt) as op:  # the same start for both modes
            out.append(op.pick_and_drop(op.new_attempt(target, mode, opt.strategy)))
    return out
