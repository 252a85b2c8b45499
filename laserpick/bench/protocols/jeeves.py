"""jeeves (003 section V): one object per trial (ten models in turn) on each of the `jeeves`
table's six locations, the scooter 40 cm back; the centroid approach, then a top grasp."""

from __future__ import annotations

import math

import yaml

from laserpick.bench.attempts import Attempt
from laserpick.bench.protocols.isolation import isolation
from laserpick.bench.protocols.trials import Options, limit, scripted_operator
from laserpick.robot.sim.scenes import Scene, parse_scene, scene_config

#: The ten objects of the Jeeves protocol, one per trial in turn: 003 used ten household
#: objects; these are ours that fit a vertical grasp and stand at every location of the
#: 0.40 m table (a location is 5 cm from the table's front and side edges).
JEEVES_MODELS = (
    "soda_can",
    "mug",
    "pill_bottle",
    "spice_jar",
    "juice_bottle",
    "yogurt_cup",
    "glass_cup",
    "vitamin_bottle",
    "ball",
    "spray_bottle",
)
JEEVES_BACK = 0.40  #: m the scooter starts behind its working spot (003's approach)


def scene_config_backed(name: str, back: float) -> dict:
    """A built-in scene's configuration with the scooter starting `back` m farther back
    along its heading; edit it further, then `parse_scene(yaml.safe_dump(config))`."""
    config = scene_config(name)
    start = config["scooter"]
    yaw = math.radians(start.get("yaw_deg", 0.0))
    start["x"] = start.get("x", 0.0) - back * math.cos(yaw)
    start["y"] = start.get("y", 0.0) - back * math.sin(yaw)
    return config


def jeeves_scene(model: str, location: str, back: float = JEEVES_BACK) -> Scene:
    """The `jeeves` table with `model` on `location` and the scooter `back` m farther away
    than in the scene file."""
    config = scene_config_backed("jeeves", back)
    config["objects"] = [{"name": model, "model": model, "at": location}]
    return parse_scene(yaml.safe_dump(config, sort_keys=False))


def jeeves(trial: int, seed: int, opt: Options) -> list[Attempt]:
    """One jeeves trial: the trial's model on each of the six table locations."""
    if opt.scene:
        return isolation(trial, seed, opt)
    model = JEEVES_MODELS[trial % len(JEEVES_MODELS)]
    out = []
    for k, location in enumerate(limit([f"loc{i}" for i in range(1, 7)], opt)):
        with scripted_operator(jeeves_scene(model, location), trial, seed * 10 + k, opt) as op:
            rec = op.new_attempt(model, opt.selection, opt.strategy)
            # Each location is a task of its own (each runs on a fresh operator, whose
            # count of tasks starts again at 1).
            rec.task, rec.surface = k + 1, location
            out.append(op.pick_and_drop(rec))
    return out
