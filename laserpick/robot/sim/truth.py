"""Simulator truth, for scoring and for playing the operator; never for the pipeline.

`SimTruth` reads where each object is, which object a point or a grasp belongs to, whether an
object lies in the basket, and does what an experimenter does by hand (empties the basket,
moves a stuck arm home). `Captured` carries the simulator's per-pixel geom labels onto a fused
cloud's points through their (camera, pixel) provenance. The bench, the tests and the server's
optional `/sim` routes read these; the pipeline and the session never do.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import mujoco
import numpy as np

from laserpick.description import dims
from laserpick.description.kinematics import tcp_pose
from laserpick.robot.sim.robot import SimRobot
from laserpick.robot.sim.scenes import Scene, load_scene
from laserpick.transforms import invert, matrix_from_quat, planar_pose
from laserpick.types import DepthFrame, FusedCloud

__all__ = ["OUT_OF_PLAY", "Captured", "SimTruth", "capture", "inside_basket", "on_scooter"]

#: Where (world x, y, m) `take_out` puts an object out of the scene: on the floor, out of
#: the way.
OUT_OF_PLAY = np.array([-5.0, 0.0])


@dataclass
class SimTruth:
    """Ground-truth readings and judgements on a running `SimRobot`."""

    robot: SimRobot

    def _T_world_base(self) -> np.ndarray:
        return planar_pose(*self.robot.sim.snapshot().base_pose)

    def _T_base_world(self) -> np.ndarray:
        return invert(self._T_world_base())

    def instances(self) -> list[str]:
        """The scene's object instances."""
        return [p.instance for p in self.robot.sim.scene.placements]  # type: ignore[union-attr]

    def world_position(self, instance: str) -> np.ndarray:
        """The object's origin in `world` (m): the centre of its bottom face when upright."""
        return self.robot.sim.snapshot().xpos[self.robot.sim.info.object_bodies[instance]].copy()

    def centre_of_mass(self, instance: str) -> np.ndarray:
        """The object's centre of mass in `base` (m) now."""
        body = self.robot.sim.info.object_bodies[instance]
        return self.to_base(self._posed().xipos[body])

    def footprint_middle(self, instance: str) -> np.ndarray:
        """Where the object stands, as it rests now: the middle of its footprint (the level
        middle of its bounds, `object_points`) at its lowest point, as a point fixed in the
        object (m, its own frame), for `body_point` to follow. Upright and round, that is
        its origin; lying on its side, the middle of its length, where its origin (the
        middle of its bottom face) is at one end."""
        world = self.object_points(instance, frame="world")
        lo, hi = world.min(axis=0), world.max(axis=0)
        middle = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]])
        R = matrix_from_quat(self.world_quat(instance))
        return R.T @ (middle - self.world_position(instance))

    def body_point(self, instance: str, local: np.ndarray) -> np.ndarray:
        """A point fixed in the object (`local`, m, its own frame) in `base` (m) now."""
        R = matrix_from_quat(self.world_quat(instance))
        return self.to_base(self.world_position(instance) + R @ local)

    def world_quat(self, instance: str) -> np.ndarray:
        """The object's orientation in `world` (w, x, y, z)."""
        b = self.robot.sim.info.object_bodies[instance]
        return self.robot.sim.snapshot().xquat[b].copy()

    def take_out(self, instance: str) -> None:
        """Lift the object out of the scene (to the floor 5 m behind the scooter), as a helper
        empties the basket between trials: objects in the basket stand in the laser's way."""

        def move(m: mujoco.MjModel, d: mujoco.MjData) -> None:
            j = m.joint(f"obj/{instance}")
            d.qpos[j.qposadr[0] : j.qposadr[0] + 3] = [*OUT_OF_PLAY, 0.5]
            d.qvel[j.dofadr[0] : j.dofadr[0] + 6] = 0.0

        self.robot.sim.call(move)
        self.robot.sleep(0.1)  # headless, the call lands at the next step: take it now

    def taken_out(self, instance: str) -> bool:
        """Whether `take_out` put the object out of the scene."""
        return bool(np.linalg.norm(self.world_position(instance)[:2] - OUT_OF_PLAY) < 1.0)

    def dot_on(self, instance: str) -> bool:
        """Whether the aiming beam's dot lies on `instance` now: what the user sees."""
        m = self.robot.model
        hits = self.robot.laser.cast_hits(m, self._posed())
        body = self.robot.sim.info.object_bodies[instance]
        return bool(hits) and hits[0] is not None and int(m.geom_bodyid[hits[0].geom]) == body

    def to_base(self, world: np.ndarray) -> np.ndarray:
        """A `world` point (m) in `base` now."""
        return (self._T_base_world() @ np.append(world, 1.0))[:3]

    def to_world(self, base: np.ndarray) -> np.ndarray:
        """A `base` point (m) in `world` now."""
        return (self._T_world_base() @ np.append(base, 1.0))[:3]

    def position(self, instance: str) -> np.ndarray:
        """The object's origin in `base` (m)."""
        return self.to_base(self.world_position(instance))

    def _posed(self) -> mujoco.MjData:
        """A copy of the simulation's state with its kinematics computed, to read geoms from."""
        d = mujoco.MjData(self.robot.model)
        d.qpos[:] = self.robot.sim.snapshot().qpos
        mujoco.mj_kinematics(self.robot.model, d)
        return d

    def object_points(
        self,
        instance: str,
        posed: mujoco.MjData | None = None,
        frame: Literal["base", "world"] = "base",
    ) -> np.ndarray:
        """Points filling the object's bounds (m, in `frame`): its meshes' vertices, and a 7 x
        7 x 7 grid over each primitive geom's box. Enough to say which object a grasp closes
        on. posed: the state to read (default: now)."""
        m = self.robot.model
        d = posed if posed is not None else self._posed()
        b = self.robot.sim.info.object_bodies[instance]
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
        if frame == "world":
            return world
        return (self._T_base_world() @ np.c_[world, np.ones(len(world))].T).T[:, :3]

    def all_object_points(self, frame: Literal["base", "world"] = "base") -> dict[str, np.ndarray]:
        """`object_points` of every object (m, in `frame`), now: take it before a pick moves
        them."""
        posed = self._posed()
        return {name: self.object_points(name, posed, frame) for name in self.instances()}

    def object_at(
        self, position: np.ndarray, points: dict[str, np.ndarray] | None = None
    ) -> str | None:
        """The object nearest `position` (m, `base`; a grasp's TCP), within 4 cm, or None.
        points: the objects' points as they stood before the grasp (default: as they stand
        now)."""
        points = points if points is not None else self.all_object_points()
        best, best_d = None, 0.04
        for name, pts in points.items():
            d = float(np.min(np.linalg.norm(pts - position, axis=1)))
            if d < best_d:
                best, best_d = name, d
        return best

    def near_hand(self, instance: str, within: float = 0.08) -> bool:
        """Whether the object's points lie within `within` m of the gripper's TCP."""
        tcp = tcp_pose(self.robot.joint_state().q)[:3, 3]
        pts = self.object_points(instance)
        return bool(np.min(np.linalg.norm(pts - tcp, axis=1)) < within)

    def move_arm_home(self) -> None:
        """The experimenter moves a stuck arm home by hand (the simulator sets the joints)."""
        robot = self.robot

        def home(m: mujoco.MjModel, d: mujoco.MjData) -> None:
            d.qpos[robot.sim.info.arm_qpos] = dims.UR5_HOME_Q
            d.qvel[robot.sim.info.arm_dof] = 0.0

        robot.sim.call(home)
        robot.sim.halt()
        robot.sleep(0.5)

    def free_joint(self, instance: str) -> np.ndarray:
        """The object's free-joint position (x, y, z, qw, qx, qy, qz) in `world`, to put it
        back later with `put_back`."""
        j = self.robot.model.joint(f"obj/{instance}")
        a = j.qposadr[0]
        return self.robot.sim.snapshot().qpos[a : a + 7].copy()

    def put_back(self, instance: str, qpos: np.ndarray) -> None:
        """Set the object down again where `free_joint` found it, at rest."""

        def move(m: mujoco.MjModel, d: mujoco.MjData) -> None:
            j = m.joint(f"obj/{instance}")
            d.qpos[j.qposadr[0] : j.qposadr[0] + 7] = qpos
            d.qvel[j.dofadr[0] : j.dofadr[0] + 6] = 0.0

        self.robot.sim.call(move)
        self.robot.sleep(0.3)

    def in_basket(self, instance: str) -> bool:
        """Whether the object lies in the basket: its centre of mass within the walls, above
        the floor and below the rim (`inside_basket`)."""
        return inside_basket(self.centre_of_mass(instance))


def on_scooter(centre: np.ndarray) -> bool:
    """Whether a centre of mass (m, `base`) lies over the scooter, above the floor: behind
    the arm's mount, within the scooter's width and the basket's reach across (5 cm past
    either), and no lower than 5 cm under the deck's top. An object resting there, across
    the basket's rim or on the deck, was let go and missed; no object stands on the
    scooter otherwise (one in the hand is above it only while the arm holds it)."""
    half = max(dims.SCOOTER_WIDTH / 2, float(np.abs(dims.BASKET_CENTER[1]) + 0.2)) + 0.05
    return bool(
        -dims.SCOOTER_REAR_OVERHANG <= centre[0] <= dims.ARM_MOUNT_POS[0]
        and abs(centre[1]) <= half
        and centre[2] >= dims.SCOOTER_DECK_HEIGHT - 0.05
    )


def inside_basket(centre: np.ndarray) -> bool:
    """Whether a centre of mass (m, `base`) lies inside the basket: within its walls, at
    most 2 cm below its floor's top (contact slack) and below its rim. The object's origin,
    the middle of its bottom face, says less: a cereal box that came to rest on its top,
    standing in the basket with 9 cm out over the rim, has its origin above the rim and its
    centre of mass inside; one lying across both rims has its centre of mass above them."""
    lo = dims.BASKET_CENTER - dims.BASKET_INNER / 2
    hi = dims.BASKET_CENTER + dims.BASKET_INNER / 2
    return bool(np.all(centre >= lo - [0.0, 0.0, 0.02]) and np.all(centre <= hi))


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
