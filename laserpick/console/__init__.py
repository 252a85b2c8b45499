"""The console: the viser 3D view of the robot, an in-process client of the session.

`SceneViewer` draws the robot from its description and its reported state, and the world
layer a simulated robot offers (`WorldLayer`); `OperatorConsole` draws the session over it
(the fused cloud, the projector's light, the laser, the grasps) with a panel of controls
for the clients its door (`ViewDoor`) lets in: the API's door, so the view moves nothing for
a browser that was never let in.
`view_page` serves viser's client page with our script ahead of it; `headless_chromium`
starts the browser the tests and benchmarks use.

The names below are imported on first use, so that `laserpick.console.headless_chromium`
and `view_page` stay light to import.
"""

from __future__ import annotations

import importlib
from typing import Any

__all__ = [
    "OperatorConsole",
    "RobotNodes",
    "SceneViewer",
    "ViewDoor",
    "WorldBody",
    "WorldLayer",
    "WorldMesh",
    "WorldNodes",
    "default_view_pixel",
    "lit_by",
    "projector_pixels",
    "to_world",
]

_HOME = {
    "OperatorConsole": "operator_console",
    "RobotNodes": "robot_view",
    "SceneViewer": "viewer",
    "ViewDoor": "view_door",
    "WorldBody": "world_layer",
    "WorldLayer": "world_layer",
    "WorldMesh": "world_layer",
    "WorldNodes": "world_layer",
    "default_view_pixel": "default_camera",
    "lit_by": "cloud_overlay",
    "projector_pixels": "cloud_overlay",
    "to_world": "overlay",
}


def __getattr__(name: str) -> Any:
    if name not in _HOME:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{_HOME[name]}"), name)
