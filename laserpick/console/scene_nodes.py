"""What the 3D view's drawings share: a coloured mesh node, and frames that follow poses.

A pose is sent to the browser only once it moved `POSE_STEP_M` or `POSE_STEP_RAD` from the
pose last sent: every message makes the browser draw a frame, and a click waits behind it.

Units: metres; quaternions (w, x, y, z); RGBA in [0, 1].
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence

import numpy as np
import viser

__all__ = ["POSE_STEP_M", "POSE_STEP_RAD", "PoseFollower", "add_mesh", "node_safe"]

#: A moving node's pose is sent again once it is this far (m, rad) from the pose last sent.
#: Resting objects creep by micrometres and thousandths of a degree per step; sent at the
#: update rate, that kept the browser redrawing an idle scene (every frame, at about 150 ms
#: a frame in software WebGL) and a click waited behind those frames.
POSE_STEP_M = 0.0005
POSE_STEP_RAD = math.radians(0.25)


def node_safe(name: str) -> str:
    """`name` as one level of viser's scene tree: '/' would nest nodes, so it goes."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name)


def add_mesh(
    scene: viser.SceneApi,
    name: str,
    rgba: Sequence[float],
    vertices: np.ndarray,
    faces: np.ndarray,
    *,
    lite: bool,
    receive_shadow: bool | float = True,
) -> viser.MeshHandle:
    """A mesh node of one colour, posed by its parent frame. `lite`: toon shading and no
    shadows, for a browser without a GPU. A translucent colour is drawn from both sides."""
    opacity = None if rgba[3] >= 0.999 else float(rgba[3])
    return scene.add_mesh_simple(
        name,
        vertices=np.asarray(vertices, dtype=np.float32),
        faces=np.asarray(faces, dtype=np.uint32),
        color=tuple(round(255 * c) for c in rgba[:3]),
        opacity=opacity,
        side="double" if opacity is not None else "front",
        material="toon3" if lite else "standard",
        cast_shadow=opacity is None and not lite,
        receive_shadow=False if lite else receive_shadow,
    )


class PoseFollower:
    """Frames that follow poses: `send` moves those whose pose changed by a step or more."""

    def __init__(
        self, frames: Sequence[viser.FrameHandle], position: np.ndarray, wxyz: np.ndarray
    ) -> None:
        self.frames = list(frames)
        self._sent_pos = np.array(position, dtype=float).reshape(-1, 3)
        self._sent_quat = np.array(wxyz, dtype=float).reshape(-1, 4)

    def moved(self, position: np.ndarray, wxyz: np.ndarray) -> np.ndarray:
        """Which frames are POSE_STEP_M or POSE_STEP_RAD from the pose last sent."""
        shift = np.linalg.norm(position - self._sent_pos, axis=1)
        dot = np.clip(np.abs(np.sum(wxyz * self._sent_quat, axis=1)), 0.0, 1.0)
        return (shift > POSE_STEP_M) | (2.0 * np.arccos(dot) > POSE_STEP_RAD)

    def send(self, position: np.ndarray, wxyz: np.ndarray, *, force: bool = False) -> int:
        """Move the frames that moved (all of them with `force`) to position (N, 3) m and
        wxyz (N, 4); how many were sent. Call inside `server.atomic()` to send one burst."""
        moved = np.ones(len(self.frames), bool) if force else self.moved(position, wxyz)
        for k in np.flatnonzero(moved):
            self.frames[k].position = position[k]
            self.frames[k].wxyz = wxyz[k]
        self._sent_pos[moved] = position[moved]
        self._sent_quat[moved] = wxyz[moved]
        return int(moved.sum())
