"""The referee of the grasping experiments (004 section 8), and how the scripted user drives.

The referee reads the simulator's truth: where each object is, which object a grasp would
close on, whether an object ended up in the basket, and where a person would aim at one. It
also does what the experimenter does by hand (empties the basket, moves a stuck arm home).
None of it is ever shown to the pipeline; the scripted user (`picking.ScriptedOperator`) uses
it only to look at the world the way a person would.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import mujoco
import numpy as np

from laserpick.bench.truth import Captured
from laserpick.description import dims
from laserpick.description.kinematics import tcp_pose
from laserpick.pipeline.cloud import fuse
from laserpick.robot.scenes import Surface, scene_config
from laserpick.robot.sim_robot import SimRobot
from laserpick.transforms import invert, planar_pose

#: Hand tremor: the aim's angular noise, standard deviation (rad). About 5 mm at 1 m, a
#: steady hand resting on the scooter's armrest. Ours; 004 does not measure it.
TREMOR_STD = math.radians(0.3)
#: m behind a surface's front edge that the user parks to work at (the isolation table's
#: objects stand 5-45 cm behind its edge at 1.30 m).
PARK_SPOT_DEPTH = 0.25


@dataclass
class Referee:
    """Ground-truth judgements on a running `SimRobot`."""

    robot: SimRobot

    def _T_base_world(self) -> np.ndarray:
        return invert(planar_pose(*self.robot.sim.snapshot().base_pose))

    def instances(self) -> list[str]:
        """The scene's object instances."""
        return [p.instance for p in self.robot.sim.scene.placements]  # type: ignore[union-attr]

    def world_position(self, instance: str) -> np.ndarray:
        """The object's origin in `world` (m): the centre of its bottom face when upright."""
        return self.robot.sim.snapshot().xpos[self.robot.sim.info.object_bodies[instance]].copy()

    def world_quat(self, instance: str) -> np.ndarray:
        """The object's orientation in `world` (w, x, y, z)."""
        b = self.robot.sim.info.object_bodies[instance]
        return self.robot.sim.snapshot().xquat[b].copy()

    def take_out(self, instance: str) -> None:
        """Lift the object out of the scene (to the floor 5 m behind the scooter), as a helper
        empties the basket between trials: objects in the basket stand in the laser's way."""

        def move(m: mujoco.MjModel, d: mujoco.MjData) -> None:
            j = m.joint(f"obj/{instance}")
            d.qpos[j.qposadr[0] : j.qposadr[0] + 3] = [-5.0, 0.0, 0.5]
            d.qvel[j.dofadr[0] : j.dofadr[0] + 6] = 0.0

        self.robot.sim.call(move)
        self.robot.sleep(0.1)  # headless, the call lands at the next step: take it now

    def to_base(self, world: np.ndarray) -> np.ndarray:
        """A `world` point (m) in `base` now."""
        return (self._T_base_world() @ np.append(world, 1.0))[:3]

    def position(self, instance: str) -> np.ndarray:
        """The object's origin in `base` (m)."""
        return (self._T_base_world() @ np.append(self.world_position(instance), 1.0))[:3]

    def _posed(self) -> mujoco.MjData:
        """A copy of the simulation's state with its kinematics computed, to read geoms from."""
        d = mujoco.MjData(self.robot.model)
        d.qpos[:] = self.robot.sim.snapshot().qpos
        mujoco.mj_kinematics(self.robot.model, d)
        return d

    def object_points(self, instance: str, posed: mujoco.MjData | None = None) -> np.ndarray:
        """Points filling the object's bounds (m, `base`): its meshes' vertices, and a 7 x 7 x
        7 grid over each primitive geom's box. Enough to say which object a grasp closes on.
        posed: the state to read (default: now)."""
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
        return (self._T_base_world() @ np.c_[world, np.ones(len(world))].T).T[:, :3]

    def all_object_points(self) -> dict[str, np.ndarray]:
        """`object_points` of every object, now: take it before a pick moves them."""
        posed = self._posed()
        return {name: self.object_points(name, posed) for name in self.instances()}

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
        """Whether the object's origin lies inside the basket: within its walls, above its
        floor and below its rim (with a little slack for a tall object leaning there)."""
        p = self.position(instance)
        lo = dims.BASKET_CENTER - dims.BASKET_INNER / 2
        hi = dims.BASKET_CENTER + dims.BASKET_INNER / 2
        return bool(np.all(p >= lo - [0.0, 0.0, 0.02]) and np.all(p <= hi + [0.0, 0.0, 0.05]))

    def aim_point(self, instance: str) -> np.ndarray | None:
        """Where a person would aim: the middle of the object's visible top (m, `base`), from
        the cameras' view labelled by the simulator; None if no camera sees it."""
        frames, labels = self.robot.capture_with_labels()
        captured = Captured(self.robot, frames, labels)
        return captured.visible_top(fuse(frames), instance)


def scene_config_backed(name: str, back: float) -> dict:
    """A built-in scene's configuration with the scooter starting `back` m farther back
    along its heading; edit it further, then `parse_scene(yaml.safe_dump(config))`."""
    config = scene_config(name)
    start = config["scooter"]
    yaw = math.radians(start.get("yaw_deg", 0.0))
    start["x"] = start.get("x", 0.0) - back * math.cos(yaw)
    start["y"] = start.get("y", 0.0) - back * math.sin(yaw)
    return config


def parking_pose(surface: Surface, local_y: float = 0.0) -> np.ndarray:
    """Where the user parks to work on `surface`: facing it, its front edge 1.30 m ahead of
    the rear axle and the spot `local_y` (m, the surface's frame) in front of the arm.
    Returns (x, y, yaw) in `world` (m, rad)."""
    yaw = surface.yaw  # the front faces the surface's local -x: face its +x
    c, s = math.cos(yaw), math.sin(yaw)
    front_x = -surface.size[0] / 2
    spot_local = np.array([front_x + PARK_SPOT_DEPTH, local_y])
    spot = np.asarray(surface.xy) + np.array(
        [c * spot_local[0] - s * spot_local[1], s * spot_local[0] + c * spot_local[1]]
    )
    reach = np.array([1.30 + PARK_SPOT_DEPTH, dims.ARM_MOUNT_POS[1]])
    origin = spot - np.array([c * reach[0] - s * reach[1], s * reach[0] + c * reach[1]])
    return np.array([origin[0], origin[1], yaw])


class Driver(Protocol):
    """What the scripted user drives with: where the scooter stands (x, y, yaw in `world`),
    and a drive command (m/s, rad/s) held for 0.1 s of robot time."""

    def base_pose(self) -> np.ndarray: ...

    def drive(self, v: float, w: float) -> None: ...


def drive_to(driver: Driver, goal: np.ndarray, *, reverse_first: float = 0.0) -> bool:
    """Drive like a careful user: back out `reverse_first` m, turn toward a point 0.8 m in
    front of the goal, drive there, turn to face the goal and creep in. Returns whether the
    scooter ended within 3 cm and 2 deg of `goal` (x, y, yaw in `world`)."""
    goal = np.asarray(goal, float)
    approach = goal[:2] - 0.8 * np.array([math.cos(goal[2]), math.sin(goal[2])])
    if reverse_first > 0:
        start = driver.base_pose()[:2].copy()
        _drive_loop(driver, lambda p: (-0.3, 0.0, np.linalg.norm(p[:2] - start) >= reverse_first))
    _go_point(driver, approach)
    _turn_to(driver, goal[2])
    _go_point(driver, goal[:2], speed=0.2)
    _turn_to(driver, goal[2])
    p = driver.base_pose()
    return bool(np.linalg.norm(p[:2] - goal[:2]) < 0.03 and abs(_wrap(p[2] - goal[2])) < 0.035)


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


def _drive_loop(driver: Driver, command, timeout: float = 60.0) -> None:
    """Drive in 0.1 s steps until command(pose) says done (or `timeout` s of robot time),
    then let go of the stick for the 1 s ramp down."""
    t = 0.0
    while t < timeout:
        v, w, done = command(driver.base_pose())
        if done:
            break
        driver.drive(v, w)
        t += 0.1
    for _ in range(10):
        driver.drive(0.0, 0.0)


def _turn_to(driver: Driver, yaw: float) -> None:
    def cmd(p):
        err = _wrap(yaw - p[2])
        return 0.0, float(np.clip(1.5 * err, -0.6, 0.6)), abs(err) < 0.01

    _drive_loop(driver, cmd)


def _go_point(driver: Driver, xy: np.ndarray, speed: float = 0.5) -> None:
    def heading(p):
        d = xy - p[:2]
        return math.atan2(d[1], d[0])

    if np.linalg.norm(xy - driver.base_pose()[:2]) > 0.02:
        _turn_to(driver, heading(driver.base_pose()))

    def cmd(p):
        d = xy - p[:2]
        dist = float(np.linalg.norm(d))
        err = _wrap(math.atan2(d[1], d[0]) - p[2])
        v = min(speed, 0.8 * dist) * max(0.0, math.cos(err))
        return v, float(np.clip(1.5 * err, -0.6, 0.6)) if dist > 0.05 else 0.0, dist < 0.01

    _drive_loop(driver, cmd)
