"""Where the hand will go, in the 3D view: the grasp candidates, the path to the current one,
and the place mark.

The candidates are gripper outlines coloured by score (red low, green high): other
clusters dim, the current cluster bright, the current candidate thick. The current
candidate's TCP path (pre-grasp, grasp, lift) shows before it is executed; the place mark is
a ring on the surface.

Frames: grasps and marks are in `base` at the cloud's capture pose; they are drawn in
`world`. Metres.
"""

from __future__ import annotations

import numpy as np
import viser

from laserpick.console.overlay import CONSOLE_ROOT, OverlayNodes, to_world
from laserpick.description import dims
from laserpick.pipeline.reach import pregrasp_pose
from laserpick.server.session import Session
from laserpick.types import Grasp

__all__ = ["GraspOverlay", "PlaceOverlay", "gripper_outline", "score_colour", "tcp_path"]

PATH_BLUE = (80, 170, 255)
PLACE_BLUE = (60, 200, 255)
#: Radius (m) of the ring drawn around the place mark.
PLACE_RING_RADIUS = 0.04


def score_colour(score: float, bright: bool) -> np.ndarray:
    """RGB for a grasp score in [0, 1]: red (low) to green (high); dimmed unless `bright`."""
    s = float(np.clip(score, 0.0, 1.0))
    rgb = np.array([230 * (1 - s) + 30 * s, 60 * (1 - s) + 200 * s, 50.0])
    return (rgb if bright else 0.35 * rgb + 0.65 * np.array([90, 90, 95])).astype(np.uint8)


def gripper_outline(pose: np.ndarray, width: float) -> np.ndarray:
    """Line segments (5, 2, 3) of a parallel gripper at a grasp pose (4x4, TCP frame: x hand
    axis, y closing axis, z approach), fingers opened to `width` + 1 cm (m)."""
    half = min(width + 0.01, dims.GRIPPER_STROKE) / 2
    tip, root = 0.0, -dims.GRIPPER_FINGER_LENGTH  # along the approach axis, from the TCP
    palm = root - 0.04
    local = np.array(
        [
            [[0, -half, root], [0, half, root]],  # the palm bar
            [[0, -half, root], [0, -half, tip]],  # one finger
            [[0, half, root], [0, half, tip]],  # the other
            [[0, 0, root], [0, 0, palm]],  # the wrist stem
            [[0, -half, tip], [0, -half + 0.004, tip]],  # a tick at one tip: the closing side
        ]
    )
    return local @ pose[:3, :3].T + pose[:3, 3]


def tcp_path(grasp: Grasp, lift: float = 0.10) -> np.ndarray:
    """The TCP's planned path as segments (2, 2, 3) in `base`: from the pre-grasp along the
    approach to the grasp, then straight up by `lift` (m)."""
    pre = pregrasp_pose(grasp.pose, 0.10)[:3, 3]
    at = grasp.position
    up = at + np.array([0.0, 0.0, lift])
    return np.array([[pre, at], [at, up]])


def _lines(server: viser.ViserServer, name: str, segments, colours, thickness: float):
    return server.scene.add_line_segments(
        f"{CONSOLE_ROOT}/{name}", segments, colours, thickness=thickness, thickness_units="screen"
    )


class GraspOverlay:
    """Draws the session's grasp cursor: nodes "grasps", "current" and "path"."""

    def __init__(self, server: viser.ViserServer, nodes: OverlayNodes) -> None:
        self.server, self.nodes = server, nodes
        self._key: tuple[int, int, int] | None = None

    def draw(self, session: Session) -> None:
        """Redraw when the cursor moved to another cluster or candidate, or a new set came."""
        cursor = session.task.cursor
        key = None if cursor is None else (id(cursor.clusters), cursor.cluster, cursor.candidate)
        if key == self._key:
            return
        self._key = key
        for name in ("grasps", "current", "path"):
            self.nodes.set(name, None)
        latest = session.latest_cloud
        if cursor is None or latest is None:
            return
        pose = latest[1]
        current = cursor.current
        members = set(cursor.clusters.clusters[cursor.cluster])
        segs, cols = [], []
        for i, g in enumerate(cursor.clusters.grasps):
            if g is current:
                continue
            lines = gripper_outline(g.pose, g.width)
            segs.append(lines)
            cols.append(np.broadcast_to(score_colour(g.score, i in members), lines.shape))
        if segs:
            segments = to_world(np.concatenate(segs), pose)
            self.nodes.set(
                "grasps", _lines(self.server, "grasps", segments, np.concatenate(cols), 2.0)
            )
        outline = to_world(gripper_outline(current.pose, current.width), pose)
        colour = score_colour(current.score, True)
        self.nodes.set("current", _lines(self.server, "current", outline, colour, 6.0))
        path = to_world(tcp_path(current), pose)
        self.nodes.set("path", _lines(self.server, "path", path, PATH_BLUE, 3.0))


class PlaceOverlay:
    """Draws the place mark (status "place_mark", m in `base`) as a ring: node "place"."""

    def __init__(self, server: viser.ViserServer, nodes: OverlayNodes) -> None:
        self.server, self.nodes = server, nodes
        self._key: tuple[float, ...] | None = None

    def draw(self, session: Session, status: dict) -> None:
        mark = status.get("place_mark")
        key = None if mark is None else tuple(mark)
        if key == self._key:
            return
        self._key = key
        latest = session.latest_cloud
        if mark is None or latest is None:
            self.nodes.set("place", None)
            return
        around = np.linspace(0, 2 * np.pi, 33)
        ring = (
            np.array(mark) + PLACE_RING_RADIUS * np.c_[np.cos(around), np.sin(around), np.zeros(33)]
        )
        segments = np.stack([ring[:-1], ring[1:]], axis=1)
        self.nodes.set(
            "place", _lines(self.server, "place", to_world(segments, latest[1]), PLACE_BLUE, 4.0)
        )
