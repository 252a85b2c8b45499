"""The session's captures: the last fused cloud and when and where it was taken, reused while
fresh, and what is read from it (a click's ray, the cloud for the API and the 3D view).

Frames: points in `base` (m) unless a method says `world`.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Literal

import numpy as np

from laserpick.pipeline.cloud import fuse, ray_hit
from laserpick.server.session.core import SessionCore
from laserpick.transforms import invert, planar_pose
from laserpick.types import DepthFrame, FusedCloud

log = logging.getLogger(__name__)

#: A capture older than this (s) is not reused for aiming or a clicked mark.
CAPTURE_MAX_AGE = 5.0
#: rad: an arm joint moved more than this since a capture makes it stale.
ARM_MOVED = 0.01


class CamerasUnavailable(RuntimeError):
    """The cameras gave no frames (a driver or renderer error); the message says why. Only
    the read that needed a new capture fails: the session and the arm go on."""


@dataclass(frozen=True)
class Capture:
    """One capture: the frames, their fused cloud (in `base`), the scooter's (x, y, yaw) pose,
    the monotonic time (s) when it was taken and the arm's joint angles then (rad). Replaced
    whole, so readers on other threads never see a cloud with another capture's pose."""

    frames: tuple[DepthFrame, ...]
    cloud: FusedCloud
    pose: np.ndarray
    at: float
    q: np.ndarray


class CaptureReads(SessionCore):
    """Captures, kept and reused while fresh; the cloud and the click rays read from them."""

    def _to_base(
        self, v: np.ndarray, frame: Literal["base", "world"], *, direction: bool = False
    ) -> np.ndarray:
        if v.shape != (3,) or not np.all(np.isfinite(v)):
            raise ValueError("a point or direction must be 3 finite numbers")
        if frame == "base":
            return v
        T = invert(planar_pose(*self.robot.base_pose()))
        return T[:3, :3] @ v if direction else T[:3, :3] @ v + T[:3, 3]

    @property
    def latest_cloud(self) -> tuple[FusedCloud, np.ndarray] | None:
        """The last fused cloud (in `base` at capture) and the scooter's (x, y, yaw) pose then,
        without capturing; None before the first capture. For drawing it in `world`."""
        capture = self._capture
        return None if capture is None else (capture.cloud, capture.pose)

    @property
    def projection(self) -> np.ndarray | None:
        """The projector image now lit (height x width uint8), or None when nothing is lit."""
        return self._projection

    def _remember(self, frames: Sequence[DepthFrame], cloud: FusedCloud) -> Capture:
        robot = self.robot
        capture = Capture(
            tuple(frames), cloud, robot.base_pose(), time.monotonic(), robot.joint_state().q
        )
        self._capture = capture
        return capture

    def capture_now(self) -> Capture:
        """A new capture, fused and remembered. CamerasUnavailable when the cameras fail."""
        try:
            frames = self.robot.capture()
        except Exception as exc:
            raise CamerasUnavailable(f"The cameras gave no frames: {exc}") from exc
        return self._remember(frames, fuse(frames, self.settings.perception))

    def capture_or_none(self) -> Capture | None:
        """A new capture, or None if the cameras fail (logged)."""
        try:
            return self.capture_now()
        except Exception:
            log.exception("No capture; going on without one.")
            return None

    def _fresh_capture(self) -> Capture | None:
        """The last capture, if neither the scooter nor the arm has moved since and it is
        under CAPTURE_MAX_AGE old (people move things). The arm's own points are left out
        by where it stands now: in a capture taken with it elsewhere, the arm would stand
        in its own way."""
        capture = self._capture
        if capture is None or time.monotonic() - capture.at > CAPTURE_MAX_AGE:
            return None
        if np.max(np.abs(capture.pose - self.robot.base_pose())) > 1e-3:
            return None
        if np.max(np.abs(capture.q - self.robot.joint_state().q)) > ARM_MOVED:
            return None
        return capture

    def expire_capture(self) -> None:
        """Reuse the last capture no more, as if it were over CAPTURE_MAX_AGE old (someone
        moved things): the next read of the cloud captures anew. It is still drawn."""
        capture = self._capture
        if capture is not None:
            self._capture = replace(capture, at=-np.inf)

    def cloud(self) -> FusedCloud:
        """A fused cloud in `base` under CAPTURE_MAX_AGE old: the last, or a new capture
        (CamerasUnavailable when that fails)."""
        fresh = self._fresh_capture()
        if fresh is not None:
            return fresh.cloud
        return self.capture_now().cloud

    def ray_point(
        self, origin: np.ndarray, direction: np.ndarray, frame: Literal["base", "world"]
    ) -> np.ndarray:
        """Where a ray (a click in the 3D view) first meets the fused cloud (m, `base`).
        ValueError when the ray misses everything, CamerasUnavailable when there is no fresh
        capture and the cameras fail."""
        o = self._to_base(np.asarray(origin, dtype=float), frame)
        d = self._to_base(np.asarray(direction, dtype=float), frame, direction=True)
        hit = ray_hit(self.cloud().points, o, d, radius=self.settings.server.cloud_voxel)
        if hit is None:
            raise ValueError("the ray meets no point of the cloud")
        return hit
