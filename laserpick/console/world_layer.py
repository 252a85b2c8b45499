"""The world around the robot, as a layer that a robot may offer the 3D view.

A real robot knows its own body (drawn from its description, `robot_view`) and what its
sensors see (the fused cloud, drawn by the operator console); it offers no layer. A
simulator knows the room too: the floor, the furniture and the objects, and it can pause.
`WorldLayer` is what the view asks of such a layer (the simulator's is
`SimWorld`, passed in by the CLI for a simulated robot); `WorldNodes` draws one.

Frames and units: poses in `world` (z up), metres; quaternions (w, x, y, z); RGBA in [0, 1].
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np
import viser

from laserpick.console.scene_nodes import PoseFollower, add_mesh, node_safe

__all__ = ["WORLD_ROOT", "WorldBody", "WorldLayer", "WorldMesh", "WorldNodes"]

WORLD_ROOT = "/laserpick/world"


class WorldMesh(Protocol):
    """Triangles of one colour in their body's frame."""

    @property
    def rgba(self) -> tuple[float, float, float, float]: ...

    @property
    def vertices(self) -> np.ndarray:
        """(V, 3) m."""
        ...

    @property
    def faces(self) -> np.ndarray:
        """(F, 3) vertex indices."""
        ...


class WorldBody(Protocol):
    """A rigid body of the world: it moves (an object) or not (furniture, the ground)."""

    @property
    def name(self) -> str: ...

    @property
    def moving(self) -> bool: ...

    @property
    def ground(self) -> bool:
        """The floor's body: it takes shadows faintly."""
        ...

    @property
    def meshes(self) -> Sequence[WorldMesh]: ...


class WorldLayer(Protocol):
    """The world a simulator offers the 3D view, and its run control."""

    def bodies(self) -> Sequence[WorldBody]:
        """The bodies to draw; the same list every call."""
        ...

    def poses(self) -> tuple[np.ndarray, np.ndarray]:
        """Positions (N, 3) m and orientations (N, 4) (w, x, y, z) in `world` of
        `bodies()`, in their order, now."""
        ...

    @property
    def paused(self) -> bool: ...

    def pause(self) -> None: ...

    def resume(self) -> None: ...


class WorldNodes:
    """A `WorldLayer`'s bodies in a viser scene: one frame each, its meshes under it; the
    moving bodies' frames follow `layer.poses()`."""

    def __init__(self, scene: viser.SceneApi, layer: WorldLayer, *, lite: bool) -> None:
        self.layer = layer
        position, wxyz = layer.poses()
        self._frames: dict[str, viser.FrameHandle] = {}
        moving: list[int] = []
        for k, body in enumerate(layer.bodies()):
            name = f"{WORLD_ROOT}/{k:03d}_{node_safe(body.name)}"
            frame = scene.add_frame(name, show_axes=False, position=position[k], wxyz=wxyz[k])
            shadow = 0.3 if body.ground else True
            for j, mesh in enumerate(body.meshes):
                add_mesh(
                    scene,
                    f"{name}/m{j}",
                    mesh.rgba,
                    mesh.vertices,
                    mesh.faces,
                    lite=lite,
                    receive_shadow=shadow,
                )
            self._frames[body.name] = frame
            if body.moving:
                moving.append(k)
        self._moving = np.array(moving, dtype=np.int64)
        frames = list(self._frames.values())
        self._follower = PoseFollower(
            [frames[k] for k in moving], position[self._moving], wxyz[self._moving]
        )

    @property
    def moving(self) -> list[str]:
        """Names of the bodies whose poses are followed."""
        names = list(self._frames)
        return [names[k] for k in self._moving]

    @property
    def still(self) -> list[str]:
        """Names of the bodies drawn once where they stand."""
        moving = set(self.moving)
        return [name for name in self._frames if name not in moving]

    def frame(self, body: str) -> viser.FrameHandle:
        """The frame drawing `body` (KeyError if it is not drawn)."""
        return self._frames[body]

    def update(self, *, force: bool = False) -> int:
        """Move the moving bodies to the layer's poses now; how many poses were sent."""
        position, wxyz = self.layer.poses()
        return self._follower.send(position[self._moving], wxyz[self._moving], force=force)

    def remove(self) -> None:
        """Take every body out of the scene."""
        for frame in self._frames.values():
            frame.remove()  # its meshes go with it
        self._frames.clear()
