"""Ground truth for scoring the pipeline in tests and benchmarks (never for the pipeline).

The simulator knows which geom each depth pixel saw. These helpers carry that label onto the
fused cloud's points through their (camera, pixel) provenance, and name the object each
point belongs to, so a test can compare a segmentation with the true object points.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from laserpick.robot.sim.robot import SimRobot
from laserpick.robot.sim.scenes import Scene, load_scene
from laserpick.types import DepthFrame, FusedCloud


@dataclass
class Captured:
    """A settled headless scene, one capture of it, and its per-pixel truth."""

    robot: SimRobot
    frames: list[DepthFrame]
    labels: list[np.ndarray]  #: per frame, (H, W) geom id or -1

    @property
    def scene(self) -> Scene:
        return self.robot.sim.scene  # type: ignore[return-value]

    def point_bodies(self, cloud: FusedCloud) -> np.ndarray:
        """MuJoCo body id seen by each cloud point (-1 where the pixel saw nothing)."""
        flat = np.stack([lab.reshape(-1) for lab in self.labels])
        geom = flat[cloud.camera.astype(np.int64), cloud.pixel.astype(np.int64)]
        body = np.full(len(geom), -1, np.int64)
        ok = geom >= 0
        body[ok] = self.robot.model.geom_bodyid[geom[ok]]
        return body

    def object_points(self, cloud: FusedCloud, instance: str) -> np.ndarray:
        """Boolean mask of the cloud points that lie on object `instance`."""
        return self.point_bodies(cloud) == self.robot.sim.info.object_bodies[instance]

    def visible_top(self, cloud: FusedCloud, instance: str) -> np.ndarray | None:
        """Where a person would aim at `instance`: the middle (median) of the cloud points on
        it within 5 mm of its highest seen point, in `base` (m). None if no camera saw it."""
        pts = cloud.points[self.object_points(cloud, instance)]
        if len(pts) == 0:
            return None
        return np.median(pts[pts[:, 2] > pts[:, 2].max() - 0.005], axis=0)

    def object_pose(self, instance: str) -> tuple[np.ndarray, np.ndarray]:
        """True position (m) and quaternion (w, x, y, z) of an object, in `world`."""
        b = self.robot.sim.info.object_bodies[instance]
        s = self.robot.sim.snapshot()
        return s.xpos[b].copy(), s.xquat[b].copy()

    def close(self) -> None:
        self.robot.close()


def capture(scene: str | Scene, seed: int | None = None, settle: float = 0.5) -> Captured:
    """Load `scene` headless, let the objects settle for `settle` s, and capture once."""
    if isinstance(scene, str):
        scene = load_scene(scene, seed=seed)
    robot = SimRobot(scene, realtime=False)
    robot.sim.settle(settle)
    frames, labels = robot.capture_with_labels()
    return Captured(robot, frames, labels)


def iou(a: np.ndarray, b: np.ndarray) -> float:
    """Intersection over union of two boolean masks."""
    union = np.count_nonzero(a | b)
    return np.count_nonzero(a & b) / union if union else 0.0
