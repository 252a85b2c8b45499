"""The scripted operator and the referee of the grasping experiments (004 section 8).

The operator looks at the scene as a person would (the simulator's truth tells it where each
object is), aims the laser at an object's visible top with hand-tremor noise, and confirms.
The referee says which object a grasp would close on and whether an object ended up in the
basket. Neither is ever shown to the pipeline.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from laserpick.bench.truth import Captured
from laserpick.description import dims
from laserpick.pipeline.cloud import fuse
from laserpick.pipeline.types import DepthFrame, Grasp
from laserpick.robot.sim_robot import SimRobot
from laserpick.transforms import invert, planar_pose

#: Hand tremor: the aim's angular noise, standard deviation (rad). About 5 mm at 1 m, a
#: steady hand resting on the scooter's armrest. Ours; 004 does not measure it.
TREMOR_STD = math.radians(0.3)


@dataclass
class Referee:
    """Ground-truth judgements on a running `SimRobot`."""

    robot: SimRobot

    def _T_base_world(self) -> np.ndarray:
        return invert(planar_pose(*self.robot.sim.snapshot().base_pose))

    def position(self, instance: str) -> np.ndarray:
        """The object's centre of mass in `base` (m)."""
        b = self.robot.sim.info.object_bodies[instance]
        p = self.robot.sim.snapshot().xpos[b]
        return (self._T_base_world() @ np.append(p, 1.0))[:3]

    def object_points(self, instance: str) -> np.ndarray:
        """Points filling the object's bounds (m, `base`): its meshes' vertices, and a 7 x 7 x
        7 grid over each primitive geom's box. Enough to say which object a grasp closes on."""
        m = self.robot.model
        b = self.robot.sim.info.object_bodies[instance]
        d = mujoco.MjData(m)
        d.qpos[:] = self.robot.sim.snapshot().qpos
        mujoco.mj_kinematics(m, d)
        pts = []
        for g in np.flatnonzero(m.geom_bodyid == b):
            if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH:
                mesh = m.geom_dataid[g]
                a, k = m.mesh_vertadr[mesh], m.mesh_vertnum[mesh]
                local = m.mesh_vert[a : a + k]
            else:
                centre, half = m.geom_aabb[g, :3], m.geom_aabb[g, 3:]
                grid = np.linspace(-1.0, 1.0, 7)
                local = centre + np.array(np.meshgrid(grid, grid, grid)).reshape(3, -1).T * half
            pts.append(local @ d.geom_xmat[g].reshape(3, 3).T + d.geom_xpos[g])
        world = np.vstack(pts)
        return (self._T_base_world() @ np.c_[world, np.ones(len(world))].T).T[:, :3]

    def grasped_object(self, grasp: Grasp, instances: list[str]) -> str | None:
        """The object nearest the grasp's TCP (within 4 cm), or None."""
        best, best_d = None, 0.04
        for name in instances:
            d = float(np.min(np.linalg.norm(self.object_points(name) - grasp.position, axis=1)))
            if d < best_d:
                best, best_d = name, d
        return best

    def in_basket(self, instance: str) -> bool:
        """Whether the object's centre lies inside the basket's walls."""
        p = self.position(instance)
        lo = dims.BASKET_CENTER - dims.BASKET_INNER / 2
        hi = dims.BASKET_CENTER + dims.BASKET_INNER / 2
        return bool(np.all(p[:2] >= lo[:2]) and np.all(p[:2] <= hi[:2]) and p[2] <= hi[2] + 0.05)

    def aim_point(self, instance: str) -> np.ndarray | None:
        """Where a person would aim: the middle of the object's visible top (m, `base`), from
        the cameras' view labelled by the simulator; None if no camera sees it."""
        frames, labels = self.robot.capture_with_labels()
        captured = Captured(self.robot, frames, labels)
        return captured.visible_top(fuse(frames), instance)


def aim_with_tremor(robot: SimRobot, point: np.ndarray, rng: np.random.Generator) -> None:
    """Aim the laser at `point` (`base`, m) with tremor noise on yaw and pitch, and confirm."""
    st = robot.laser.aim_at(point)
    robot.laser.aim(st.yaw + rng.normal(0.0, TREMOR_STD), st.pitch + rng.normal(0.0, TREMOR_STD))
    robot.laser.confirm()


def mark_and_capture(
    robot: SimRobot, point: np.ndarray, rng: np.random.Generator
) -> list[DepthFrame]:
    """The operator marks `point`; the robot captures its five frames with the dots in them."""
    aim_with_tremor(robot, point, rng)
    frames = robot.capture()
    robot.laser.off()
    return frames
