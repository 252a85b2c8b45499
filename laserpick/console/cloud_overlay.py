"""The fused cloud in the 3D view, dark, and the points the projector lights, bright.

The projector's image is projected back onto the cloud, so the lit target glows as it does
in the room. Each point's projector pixel is computed once per cloud, as the cloud arrives;
a highlight is then a lookup, not a projection of 200k points just when the user waits.

Frames: the cloud is in `base` at its capture pose; it is drawn in `world`. Metres.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import viser

from laserpick.console.overlay import CONSOLE_ROOT, OverlayNodes, to_world
from laserpick.pipeline.cloud import voxel_first
from laserpick.server.session import Session
from laserpick.types import FusedCloud, Projector

__all__ = ["CLOUD_VOXEL", "CloudOverlay", "lit_by", "projector_pixels"]

#: Cloud points drawn: one per voxel of this edge (m).
CLOUD_VOXEL = 0.012
CLOUD_POINT_SIZE = 0.008
LIT_POINT_SIZE = 0.012
LIT_VOXEL = 0.005
DARK = np.array([70, 74, 82], np.uint8)  #: unlit cloud points
LIT = np.array([255, 236, 120], np.uint8)  #: points the projector lights


def projector_pixels(projector: Projector, points: np.ndarray) -> np.ndarray:
    """The flat index (N,) into the projector image of the pixel each point (N, 3) (m,
    `base`) falls on; -1 for a point outside the image or behind the projector. It depends
    only on the points: the projector is fixed to the scooter, the cloud is in `base`."""
    uv, front = projector.project(points)
    px = np.round(uv).astype(np.int64)
    w, h = projector.width, projector.height
    inside = front & (px[:, 0] >= 0) & (px[:, 0] < w) & (px[:, 1] >= 0) & (px[:, 1] < h)
    return np.where(inside, px[:, 1] * w + px[:, 0], -1)


def lit_by(image: np.ndarray, pixels: np.ndarray) -> np.ndarray:
    """Mask of the points whose projector pixels (N,) (`projector_pixels`) the image
    (height x width) lights (pixel > 0)."""
    return (pixels >= 0) & (image.ravel()[np.maximum(pixels, 0)] > 0)


class CloudOverlay:
    """Draws the session's latest cloud and its highlight, each only when it changed.

    Nodes: "cloud" (dark), "lit" (the highlight shown) and "lit-ahead" (a highlight the
    session foresaw, sent ahead hidden: the confirm then shows it, a few bytes instead of
    its points).
    """

    def __init__(self, server: viser.ViserServer, nodes: OverlayNodes) -> None:
        self.server, self.nodes = server, nodes
        self.show_cloud = True
        self._cloud_key: tuple[int, int] | None = None
        self._lit_key: tuple[int, int] | None = None
        #: The foreseen highlight sent ahead, hidden ("lit-ahead"), and its number of points.
        self._ahead_key: tuple[int, int] | None = None
        self._ahead_points = 0
        self._sent_ahead = 0
        #: The projector pixel of each point of the cloud `_pixels_of`; the cloud itself is
        #: kept, not its id, which a new cloud may reuse once it is freed.
        self._pixels: np.ndarray | None = None
        self._pixels_of: FusedCloud | None = None

    def set_visible(self, show: bool) -> None:
        """Show or hide the dark cloud (the highlight shows either way)."""
        self.show_cloud = show
        node = self.nodes.get("cloud")
        if node is not None:
            node.visible = show

    def draw(self, session: Session, on_lit: Callable[[int], None]) -> None:
        """The lit points first (the highlight is what the user waits for), then the dark
        cloud under them. `on_lit(points)` is called once a new highlight is shown."""
        latest = session.latest_cloud
        image = session.projection
        if latest is None:
            for key in ("cloud", "lit", "lit-ahead"):
                self.nodes.set(key, None)
            self._cloud_key = self._lit_key = self._ahead_key = None
            return
        cloud, pose = latest
        if self._pixels_of is not cloud:
            # Once per cloud, as it arrives (a click aims in it).
            self._pixels = projector_pixels(session.projector, cloud.points)
            self._pixels_of = cloud
        lit_key = (id(cloud), id(image))
        if lit_key != self._lit_key:
            self._lit_key = lit_key
            if image is not None and lit_key == self._ahead_key:
                ahead = self.nodes.pop("lit-ahead")
                ahead.visible = True
                self.nodes.set("lit", ahead)
                self._ahead_key = None
                sent = self._ahead_points
            else:
                handle, sent = self._lit_cloud("lit", cloud, image, pose, visible=True)
                self.nodes.set("lit", handle)
            if sent:
                on_lit(sent)
        self._draw_ahead(session.foreseen, cloud, image, pose)
        cloud_key = (id(cloud), 0)
        if cloud_key != self._cloud_key:
            self._cloud_key = cloud_key
            points = cloud.points[voxel_first(cloud.points, CLOUD_VOXEL)]
            self.nodes.set(
                "cloud",
                self.server.scene.add_point_cloud(
                    f"{CONSOLE_ROOT}/cloud",
                    points=to_world(points, pose).astype(np.float32),
                    colors=DARK,
                    point_size=CLOUD_POINT_SIZE,
                    point_shape="rounded",
                    visible=self.show_cloud,
                ),
            )

    def _draw_ahead(
        self,
        foreseen: tuple[FusedCloud, np.ndarray] | None,
        cloud: FusedCloud,
        image: np.ndarray | None,
        pose: np.ndarray,
    ) -> None:
        """Send the highlight the session foresaw in this cloud ahead, hidden."""
        ahead_key = None
        if foreseen is not None and foreseen[0] is cloud and foreseen[1] is not image:
            ahead_key = (id(cloud), id(foreseen[1]))
        if ahead_key == self._ahead_key:
            return
        self._ahead_key = ahead_key
        self._sent_ahead += 1  # a path of its own: shown, it is the "lit" node
        handle, self._ahead_points = (
            self._lit_cloud(f"lit-{self._sent_ahead}", cloud, foreseen[1], pose, visible=False)
            if foreseen is not None and ahead_key is not None
            else (None, 0)
        )
        self.nodes.set("lit-ahead", handle)

    def _lit_cloud(
        self,
        name: str,
        cloud: FusedCloud,
        image: np.ndarray | None,
        pose: np.ndarray,
        *,
        visible: bool,
    ) -> tuple[viser.SceneNodeHandle | None, int]:
        """The points of `cloud` that the projector `image` lights, as a bright point cloud
        node `name` (None when it lights none), and how many points it has."""
        assert self._pixels is not None and self._pixels_of is cloud
        lit = cloud.points[lit_by(image, self._pixels)] if image is not None else None
        if lit is None or not len(lit):
            return None, 0
        points = to_world(lit[voxel_first(lit, LIT_VOXEL)], pose).astype(np.float32)
        # Larger and bright, and drawn whether or not the cloud is: the projector's light
        # on the object shows either way.
        handle = self.server.scene.add_point_cloud(
            f"{CONSOLE_ROOT}/{name}",
            points=points,
            colors=LIT,
            point_size=LIT_POINT_SIZE,
            point_shape="circle",
            point_shading="flat",
            visible=visible,
        )
        return handle, len(points)
