"""Whole models: the simulated world with the scooter robot, and the arm alone."""

from __future__ import annotations

import mujoco

from laserpick.description import dims
from laserpick.robot.sim.model.actuators import add_actuators
from laserpick.robot.sim.model.arm import add_ur5
from laserpick.robot.sim.model.geoms import STATIC_AFFINITY, STATIC_TYPE, G, J
from laserpick.robot.sim.model.mounts import add_mounts
from laserpick.robot.sim.model.names import ARM_PREFIX, SCOOTER_BODY
from laserpick.robot.sim.model.scooter import add_scooter_shell
from laserpick.robot.sim.objects import GROUP_OPAQUE
from laserpick.robot.sim.scenes import Scene, add_scene_to_spec
from laserpick.settings import get_settings


def _configure(spec: mujoco.MjSpec) -> None:
    """Compiler, physics options and rendering limits shared by both models."""
    s = get_settings().sim
    spec.compiler.degree = False  # every angle the builders give is in radians
    spec.option.timestep = 1.0 / s.rate_hz
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    # Elliptic cones with a high impratio keep a parallel-jaw grasp from slipping.
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.impratio = s.impratio
    spec.option.noslip_iterations = s.noslip_iterations
    spec.visual.global_.offwidth = max(dims.DEPTH_WIDTH, 1280)
    spec.visual.global_.offheight = max(dims.DEPTH_HEIGHT, 960)
    # Clip planes are relative to the model's extent, which a big scene (the 12 surfaces) makes
    # 40 m; the near plane would then cut table tops 0.4 m from a camera. Fix the extent at the
    # robot's working scale so the planes sit at 2 cm and 20 m whatever the scene.
    spec.stat.extent = 5.0
    spec.visual.map.znear = 0.004
    spec.visual.map.zfar = 4.0


def build_sim_spec(scene: Scene | None) -> mujoco.MjSpec:
    """The full world: ground, scene, and the scooter robot on planar base joints."""
    spec = mujoco.MjSpec()
    spec.modelname = "laserpick" + (f"_{scene.name}" if scene else "")
    _configure(spec)
    world = spec.worldbody
    floor = world.add_geom(name="floor", type=G.mjGEOM_PLANE, size=[30, 30, 0.05])
    floor.rgba = [0.82, 0.80, 0.76, 1.0]
    floor.group = GROUP_OPAQUE
    floor.contype, floor.conaffinity = STATIC_TYPE, STATIC_AFFINITY
    floor.friction = [0.9, 0.005, 0.0001]
    world.add_light(
        name="sun", pos=[0, 0, 4], dir=[0.2, 0.1, -1], type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL
    )
    if scene is not None:
        add_scene_to_spec(spec, scene)
    scooter = world.add_body(name=SCOOTER_BODY, pos=[0, 0, 0])
    scooter.mass = dims.SCOOTER_MASS
    scooter.ipos = [0.45, 0, 0.3]
    scooter.inertia = [8.0, 15.0, 18.0]
    scooter.explicitinertial = True
    for name, jtype, axis in (
        ("base_x", J.mjJNT_SLIDE, [1, 0, 0]),
        ("base_y", J.mjJNT_SLIDE, [0, 1, 0]),
        ("base_yaw", J.mjJNT_HINGE, [0, 0, 1]),
    ):
        j = scooter.add_joint(name=name, type=jtype, axis=axis)
        j.damping = [50.0, 0.0, 0.0]
    add_scooter_shell(scooter)
    add_mounts(scooter)
    add_ur5(scooter, fingers_move=True)
    # The arm's first links sit in the pedestal; they must not push on it.
    for link in ("base", "link1"):
        spec.add_exclude(bodyname1=SCOOTER_BODY, bodyname2=ARM_PREFIX + link)
    add_actuators(spec)
    return spec


def build_sim_model(scene: Scene | None) -> mujoco.MjModel:
    """Compile the full world for `scene` (None: the robot on an empty floor)."""
    return build_sim_spec(scene).compile()


def build_arm_spec(with_scooter: bool = True) -> mujoco.MjSpec:
    """The arm in `base` on a fixed scooter, fingers open: 6 DoF, nothing else moves."""
    spec = mujoco.MjSpec()
    spec.modelname = "laserpick_arm"
    _configure(spec)
    root = spec.worldbody.add_body(name=SCOOTER_BODY, pos=[0, 0, 0])
    if with_scooter:
        add_scooter_shell(root)
    add_ur5(root, fingers_move=False)
    if with_scooter:
        for link in ("base", "link1"):
            spec.add_exclude(bodyname1=SCOOTER_BODY, bodyname2=ARM_PREFIX + link)
    return spec


def build_arm_model(with_scooter: bool = True) -> mujoco.MjModel:
    """Compile the arm-only kinematic model (see `build_arm_spec`)."""
    return build_arm_spec(with_scooter).compile()
