"""Arm control laws run inside the simulation's control tick.

* `TrajectoryTracker` plays a joint `Trajectory` into the position servos.
* `CartesianController` moves the TCP to a pose in `base` with mink differential IK on the
  arm-only model: a FrameTask on the TCP, configuration and velocity limits, and collision
  avoidance between the arm and the scooter's shell.

Both produce a joint setpoint (rad) per tick; the sim loop writes it to the servos.
"""

from __future__ import annotations

import mink
import mujoco
import numpy as np

from laserpick.description import dims
from laserpick.robot.sim.model import ARM_JOINTS, ARM_PREFIX, SCOOTER_COLLISION_PREFIX, TCP_SITE
from laserpick.transforms import rotation_angle
from laserpick.types import GripperEvent, Trajectory


class TrajectoryTracker:
    """Follows a joint trajectory against the simulation clock."""

    def __init__(self, traj: Trajectory, t_start: float) -> None:
        self.traj = traj
        self.t_start = t_start
        self._pending = list(traj.gripper)

    def setpoint(self, t: float) -> np.ndarray:
        """Joint setpoint (rad) at sim time t (s)."""
        return self.traj.sample(t - self.t_start)

    def due_events(self, t: float) -> list[GripperEvent]:
        """Gripper events whose time has come since the last call."""
        due = [e for e in self._pending if e.t <= t - self.t_start]
        self._pending = [e for e in self._pending if e.t > t - self.t_start]
        return due

    def finished(self, t: float) -> bool:
        return t - self.t_start >= self.traj.duration and not self._pending


class CartesianController:
    """Differential IK toward a TCP target with mink, on the arm-only model in `base`."""

    def __init__(self, arm_model: mujoco.MjModel, max_joint_speed: float = 1.0) -> None:
        if not 0 < max_joint_speed <= dims.UR5_QD_MAX:
            raise ValueError(f"max_joint_speed must be in (0, {dims.UR5_QD_MAX}] rad/s")
        self.model = arm_model
        self.configuration = mink.Configuration(arm_model)
        self.task = mink.FrameTask(
            TCP_SITE, "site", position_cost=1.0, orientation_cost=0.5, lm_damping=1e-3
        )
        arm_geoms = [
            g
            for g in range(arm_model.ngeom)
            if arm_model.geom(g).name.startswith((ARM_PREFIX + "link", "gripper/"))
            and not arm_model.geom(g).name.startswith(ARM_PREFIX + "link1")
        ]
        shell = [
            g
            for g in range(arm_model.ngeom)
            if arm_model.geom(g).name.startswith(SCOOTER_COLLISION_PREFIX)
        ]
        self.limits: list[mink.Limit] = [
            mink.ConfigurationLimit(arm_model),
            mink.VelocityLimit(arm_model, {name: max_joint_speed for name in ARM_JOINTS}),
        ]
        if shell:
            self.limits.append(
                mink.CollisionAvoidanceLimit(
                    arm_model,
                    [(arm_geoms, shell)],
                    minimum_distance_from_collisions=0.01,
                    collision_detection_distance=0.08,
                )
            )
        self.target: np.ndarray | None = None

    def set_target(self, T_base_tcp: np.ndarray) -> None:
        """Aim the TCP at a 4x4 pose in `base`."""
        if T_base_tcp.shape != (4, 4) or not np.all(np.isfinite(T_base_tcp)):
            raise ValueError("TCP target must be a finite 4x4 transform")
        self.target = T_base_tcp.copy()
        self.task.set_target(mink.SE3.from_matrix(T_base_tcp))

    def step(self, q: np.ndarray, dt: float) -> np.ndarray:
        """One IK step from joint angles q (rad) over dt (s); returns the next setpoint."""
        self.configuration.update(q)
        if self.target is None:
            return q.copy()
        vel = mink.solve_ik(
            self.configuration, [self.task], dt, solver="daqp", damping=1e-3, limits=self.limits
        )
        self.configuration.integrate_inplace(vel, dt)
        return self.configuration.q.copy()

    def error(self, q: np.ndarray) -> tuple[float, float]:
        """Position (m) and orientation (rad) error of the TCP at q from the target."""
        if self.target is None:
            return 0.0, 0.0
        self.configuration.update(q)
        T = self.configuration.get_transform_frame_to_world(TCP_SITE, "site").as_matrix()
        return (
            float(np.linalg.norm(T[:3, 3] - self.target[:3, 3])),
            rotation_angle(T[:3, :3], self.target[:3, :3]),
        )
