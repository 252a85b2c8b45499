"""Indices into a compiled sim model that the loop and controllers use every tick."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from laserpick.description import dims
from laserpick.robot.sim.model.names import (
    ARM_JOINTS,
    ARM_PREFIX,
    BASE_JOINTS,
    FINGER_JOINTS,
    GRIPPER_ACTUATOR,
    LASER_SITE,
    SCOOTER_BODY,
    TCP_SITE,
)


@dataclass(frozen=True)
class ModelInfo:
    """Indices into a compiled sim model that the loop and controllers use every tick."""

    arm_qpos: np.ndarray  #: qpos addresses of the six arm joints
    arm_dof: np.ndarray  #: qvel addresses of the six arm joints
    arm_ctrl: np.ndarray  #: actuator ids of the six arm servos
    base_qpos: np.ndarray  #: qpos addresses of base_x, base_y, base_yaw
    base_dof: np.ndarray
    base_ctrl: np.ndarray
    finger_qpos: np.ndarray
    gripper_ctrl: int
    tcp_site: int
    laser_site: int
    scooter_body: int
    pad_geoms: np.ndarray
    arm_geoms: np.ndarray  #: every geom of the arm and the gripper, pads included
    camera_ids: dict[str, int]
    object_bodies: dict[str, int]  #: instance name -> body id

    @classmethod
    def of(cls, m: mujoco.MjModel) -> ModelInfo:
        """The indices of compiled sim model `m`."""

        def jq(names):
            return np.array([m.jnt_qposadr[m.joint(n).id] for n in names])

        def jd(names):
            return np.array([m.jnt_dofadr[m.joint(n).id] for n in names])

        def act(names):
            return np.array([m.actuator(n).id for n in names])

        objects = {}
        for b in range(m.nbody):
            name = m.body(b).name
            if name.startswith("obj/"):
                objects[name[4:]] = b
        return cls(
            arm_qpos=jq(ARM_JOINTS),
            arm_dof=jd(ARM_JOINTS),
            arm_ctrl=act(ARM_JOINTS),
            base_qpos=jq(BASE_JOINTS),
            base_dof=jd(BASE_JOINTS),
            base_ctrl=act(BASE_JOINTS),
            finger_qpos=jq(FINGER_JOINTS),
            gripper_ctrl=m.actuator(GRIPPER_ACTUATOR).id,
            tcp_site=m.site(TCP_SITE).id,
            laser_site=m.site(LASER_SITE).id,
            scooter_body=m.body(SCOOTER_BODY).id,
            pad_geoms=np.array([m.geom(f"gripper/pad_{s}").id for s in ("left", "right")]),
            arm_geoms=_subtree_geoms(m, m.body(ARM_PREFIX + "base").id),
            camera_ids={c.name: m.camera(c.name).id for c in dims.CAMERA_MOUNTS},
            object_bodies=objects,
        )


def _subtree_geoms(m: mujoco.MjModel, root: int) -> np.ndarray:
    """Ids of the geoms of body `root` and of all bodies below it."""
    inside = np.zeros(m.nbody, bool)
    for b in range(m.nbody):  # parents come before their children
        inside[b] = b == root or (b > 0 and inside[m.body_parentid[b]])
    return np.flatnonzero(inside[m.geom_bodyid])
