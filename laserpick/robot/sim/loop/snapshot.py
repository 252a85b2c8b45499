"""The snapshot: a consistent copy of the simulation state at one instant, for any thread."""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from laserpick.description import dims
from laserpick.robot.sim.model import ModelInfo


@dataclass(frozen=True)
class Snapshot:
    """A consistent copy of the simulation state at one instant, safe to read from any thread.

    Poses are in `world`. `base_pose` is the scooter's (x, y, yaw) in `world`.
    """

    time: float
    qpos: np.ndarray
    qvel: np.ndarray
    xpos: np.ndarray  #: (nbody, 3) body positions
    xquat: np.ndarray  #: (nbody, 4) body orientations (w, x, y, z)
    arm_q: np.ndarray  #: (6,) rad
    arm_qd: np.ndarray  #: (6,) rad/s
    base_pose: np.ndarray  #: (3,) x, y (m), yaw (rad)
    base_velocity: np.ndarray  #: (2,) forward speed (m/s), turn rate (rad/s)
    gripper_width: float  #: opening between the pads (m)
    gripper_force: float  #: summed normal force on the pads (N)
    gripper_closed: bool  #: the last gripper command was "close"
    gripper_moving: bool  #: the fingers are still on their way (`GripperDrive.moving`)
    holding: bool
    estopped: bool
    moving: bool  #: an arm motion is in progress
    #: Why the scooter last stopped itself while driving (it pushed the still arm into
    #: something), until it has driven freely for `drive.DRIVE_STOP_CLEARS`; "" otherwise.
    drive_stop: str
    rtf: float  #: measured real-time factor of the loop (sim seconds per wall second)
    taken_at: float  #: wall-clock time (s since the epoch) the state stands for


def take_snapshot(
    data: mujoco.MjData,
    info: ModelInfo,
    *,
    gripper_force: float,
    gripper_closed: bool,
    gripper_moving: bool,
    estopped: bool,
    moving: bool,
    drive_stop: str,
    rtf: float,
    taken_at: float,
) -> Snapshot:
    """The state in `data` now, with what the loop knows beside it: the pads' force (N), the
    last gripper command, the e-stop, an arm motion in progress, the drive's stop reason and
    the real-time factor, and the wall-clock time (s since the epoch) the state stands for."""
    d = data
    width = float(d.qpos[info.finger_qpos].sum())  # each finger's travel from centre
    yaw = float(d.qpos[info.base_qpos[2]])
    vx, vy = d.qvel[info.base_dof[:2]]
    return Snapshot(
        time=float(d.time),
        qpos=d.qpos.copy(),
        qvel=d.qvel.copy(),
        xpos=d.xpos.copy(),
        xquat=d.xquat.copy(),
        arm_q=d.qpos[info.arm_qpos].copy(),
        arm_qd=d.qvel[info.arm_dof].copy(),
        base_pose=d.qpos[info.base_qpos].copy(),
        base_velocity=np.array([vx * math.cos(yaw) + vy * math.sin(yaw), d.qvel[info.base_dof[2]]]),
        gripper_width=width,
        gripper_force=gripper_force,
        gripper_closed=gripper_closed,
        gripper_moving=gripper_moving,
        holding=gripper_closed
        and width > dims.GRIPPER_EMPTY_GAP
        and gripper_force > dims.GRIPPER_HOLD_FORCE,
        estopped=estopped,
        moving=moving,
        drive_stop=drive_stop,
        rtf=rtf,
        taken_at=taken_at,
    )
