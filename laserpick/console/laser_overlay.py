"""The laser pointer's beams in the 3D view, and their dots where they meet the cloud.

What a real robot knows: its pointer's beams (`robot.laser.beams_base()`) and the fused
cloud its sensors made. A beam is drawn from the pointer to the first point of the drawn
(thinned) cloud it passes within `BEAM_HIT_RADIUS` of, with a dot there, or `BEAM_LENGTH`
long when it meets none. The thinned cloud has a tenth of the points: a beam moved by a
key is followed in a few milliseconds.

Frames: beams are in `base` now, the cloud in `base` at its capture pose; both are drawn in
`world`. Metres.
"""

from __future__ import annotations

import numpy as np
import viser

from laserpick.console.cloud_overlay import CLOUD_VOXEL
from laserpick.console.overlay import CONSOLE_ROOT, OverlayNodes, to_world
from laserpick.pipeline.cloud import ray_hit, voxel_first
from laserpick.server.session import Session
from laserpick.transforms import invert, planar_pose
from laserpick.types import FusedCloud

__all__ = ["BEAM_HIT_RADIUS", "BEAM_LENGTH", "LaserOverlay", "beam_segments"]

LASER_RED = (235, 20, 20)
DOT_RED = (255, 40, 40)
#: A beam meets the cloud at its first point within this distance (m) of it: the drawn
#: cloud's spacing.
BEAM_HIT_RADIUS = CLOUD_VOXEL
#: Length (m) of a beam drawn where it meets no point of the cloud.
BEAM_LENGTH = 3.0


def beam_segments(
    beams: list[tuple[np.ndarray, np.ndarray]],
    base_pose: np.ndarray,
    cloud: tuple[np.ndarray, np.ndarray] | None,
) -> tuple[np.ndarray, list[np.ndarray]]:
    """The beams (origin m, unit direction, in `base` at `base_pose` (x, y, yaw)) as segments
    (B, 2, 3) in `world`, each ending where it meets `cloud` (points (N, 3) m in `base` at
    its capture pose, and that pose) or `BEAM_LENGTH` on; and the dots where they meet it
    (m, `world`)."""
    segments, dots = [], []
    to_cloud = np.eye(4)
    if cloud is not None:
        to_cloud = invert(planar_pose(*cloud[1])) @ planar_pose(*base_pose)
    R, t = to_cloud[:3, :3], to_cloud[:3, 3]
    for origin, direction in beams:
        start = to_world(origin, base_pose)
        along = to_world(direction, np.array([0.0, 0.0, base_pose[2]]))
        end = start + BEAM_LENGTH * along
        if cloud is not None:
            hit = ray_hit(cloud[0], R @ origin + t, R @ direction, BEAM_HIT_RADIUS)
            if hit is not None:
                end = to_world(hit, cloud[1])
                dots.append(end)
        segments.append([start, end])
    return np.array(segments), dots


class LaserOverlay:
    """Draws the session's laser: nodes "laser" (the beams) and "spots" (their dots)."""

    def __init__(self, server: viser.ViserServer, nodes: OverlayNodes) -> None:
        self.server, self.nodes = server, nodes
        self._inputs: tuple[FusedCloud | None, bytes] | None = None
        self._key: tuple[float, ...] | None = None
        self._thin_of: FusedCloud | None = None  #: the cloud `_thin` was thinned from
        self._thin = np.zeros((0, 3))

    def draw(self, session: Session) -> None:
        robot = session.robot
        beams = robot.laser.beams_base()
        if not beams:
            self.nodes.set("laser", None)
            self.nodes.set("spots", None)
            self._inputs = self._key = None
            return
        pose = robot.base_pose()
        latest = session.latest_cloud
        # The cloud search runs only when the beams, the scooter or the cloud changed.
        aim = np.concatenate([*(np.ravel(part) for beam in beams for part in beam), pose])
        inputs = (None if latest is None else latest[0], np.round(aim, 5).tobytes())
        last = self._inputs
        if last is not None and last[0] is inputs[0] and last[1] == inputs[1]:
            return
        self._inputs = inputs
        cloud = None
        if latest is not None:
            if latest[0] is not self._thin_of:
                points = latest[0].points
                self._thin = points[voxel_first(points, CLOUD_VOXEL)].astype(np.float64)
                self._thin_of = latest[0]
            cloud = (self._thin, latest[1])
        segments, dots = beam_segments(beams, pose, cloud)
        # Redraw only when the beam moved by a millimetre: each redraw makes the browser draw
        # a frame, and a click waits behind it (bench/click_latency.py).
        key = tuple(np.round(np.concatenate([np.ravel(segments), np.ravel(dots)]), 3))
        if key == self._key:
            return
        self._key = key
        self.nodes.set(
            "laser",
            self.server.scene.add_line_segments(
                f"{CONSOLE_ROOT}/laser",
                segments,
                LASER_RED,
                thickness=2.0,
                thickness_units="screen",
            ),
        )
        if not dots:
            self.nodes.set("spots", None)
            return
        self.nodes.set(
            "spots",
            self.server.scene.add_point_cloud(
                f"{CONSOLE_ROOT}/spots",
                points=np.array(dots, np.float32),
                colors=DOT_RED,
                point_size=0.02,
                point_shape="circle",
            ),
        )
