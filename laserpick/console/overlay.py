"""What the operator console's overlays share: their nodes by key, and `base` into `world`.

Frames: the session works in `base` (x forward, y left, z up); the scene is drawn in `world`
(z up), metres.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping

import numpy as np
import viser

from laserpick.transforms import planar_pose

__all__ = ["CONSOLE_ROOT", "OverlayNodes", "to_world"]

#: Where the console's nodes hang in viser's scene tree.
CONSOLE_ROOT = "/laserpick/console"


def to_world(points_base: np.ndarray, base_pose: np.ndarray) -> np.ndarray:
    """Points (..., 3) from `base` at the scooter pose (x, y, yaw) into `world`."""
    T = planar_pose(*base_pose)
    return points_base @ T[:3, :3].T + T[:3, 3]


class OverlayNodes(Mapping[str, viser.SceneNodeHandle]):
    """The overlays' scene nodes by key ("cloud", "lit", "laser", ...), each replaced as a
    whole; read like a dict."""

    def __init__(self) -> None:
        self._nodes: dict[str, viser.SceneNodeHandle] = {}

    def __getitem__(self, key: str) -> viser.SceneNodeHandle:
        return self._nodes[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._nodes)

    def __len__(self) -> int:
        return len(self._nodes)

    def pop(self, key: str) -> viser.SceneNodeHandle:
        """Take the node under `key` out of the registry (it stays in the scene)."""
        return self._nodes.pop(key)

    def set(self, key: str, handle: viser.SceneNodeHandle | None) -> None:
        """Put `handle` under `key` (None: nothing), removing the node it replaces."""
        # Adding a node under a name in use replaces the old one, so only a node that is not
        # replaced by one of its name needs removing.
        old = self._nodes.pop(key, None)
        if handle is not None:
            self._nodes[key] = handle
        if old is not None and (handle is None or old.name != handle.name):
            old.remove()
