"""Scenes: support surfaces and household objects around the scooter, described in YAML.

A scene file names the scooter's start pose, the surfaces (tables, shelves, counters, floor
areas), optional user mesh models, explicit object placements, random placement rules and
named marker points (its schema is in `schema`'s docstring). `load_scene` turns a file (or a
built-in name) into a `Scene`; `add_scene_to_spec` adds its surfaces and objects to a MuJoCo
spec.

Frames and units: world has z up and its origin on the floor; lengths in metres, masses in
kg. Angles in YAML are degrees (`yaw_deg`, about +z, counter-clockwise seen from above); the
`Scene` holds radians. A surface's local frame has its origin at the centre of its footprint
on the floor, x along its depth (`size[0]`) and y along its width (`size[1]`); its front, the
open side of a shelf, faces local -x, so yaw 0 presents it to a scooter looking along +x.

Objects rest on the top of their surface (or the given shelf level, the top one by default),
1.5 mm above it so they settle. Random rules draw `count` models (without replacement while
they last; `any` is every opaque library object that fits), a yaw, and for `coin_flip` an
upright or lying pose, and place them by rejection sampling so that footprint circles keep
`min_gap` from each other and `margin` from the surface edges (or stay inside `region`, given
in the surface's local frame as [xmin, xmax, ymin, ymax]). Lying is only for an object that
rests on its side (`objects.at_rest`): a banana's curve tips it over, so `lying: true` on a
banana is an error, and a coin flip stands it upright.
"""

from laserpick.robot.sim.scenes.errors import SceneError
from laserpick.robot.sim.scenes.load import (
    MAX_SCENE_BYTES,
    SCENE_DIR,
    builtin_scene_names,
    load_scene,
    parse_scene,
    scene_config,
)
from laserpick.robot.sim.scenes.mjcf import add_scene_to_spec, add_surface
from laserpick.robot.sim.scenes.placement import REST_CLEARANCE
from laserpick.robot.sim.scenes.scene import Placement, Scene
from laserpick.robot.sim.scenes.surfaces import SCOOTER_FOOTPRINT, Surface

__all__ = [
    "MAX_SCENE_BYTES",
    "REST_CLEARANCE",
    "SCENE_DIR",
    "SCOOTER_FOOTPRINT",
    "Placement",
    "Scene",
    "SceneError",
    "Surface",
    "add_scene_to_spec",
    "add_surface",
    "builtin_scene_names",
    "load_scene",
    "parse_scene",
    "scene_config",
]
