"""The MJCF of the scooter robot, built in code with MuJoCo's MjSpec from `dims`.

Two models come from the same builders, so they can never disagree about the arm:

* `build_sim_model(scene)`: the world. Ground plane, the scene's surfaces and objects, and the
  scooter on planar base joints (x, y, yaw) carrying the UR5, the gripper, five depth cameras,
  the projector and the laser origin.
* `build_arm_model()`: the arm alone in the `base` frame, on a fixed scooter, with the fingers
  held open. Used by mink IK, Pinocchio cross-checks and collision queries.

The UR5 bodies follow the standard DH convention exactly: body i is frame i-1 turned by q_i about
its z axis, and body i+1 sits at (a_i, 0, d_i) turned by alpha_i about x. So MuJoCo's forward
kinematics is the DH forward kinematics, and the analytic IK applies unchanged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from laserpick.description import dims
from laserpick.description.shapes import (
    HOUSING_CAPSULES,
    HOUSINGS,
    LINK_CAPSULES,
    PEDESTAL_FOOT,
    PEDESTAL_RADIUS,
    POST_BACK,
    POST_RADIUS,
    PROJECTOR_HOUSING_RAISE,
)
from laserpick.robot.sim.objects import GROUP_OPAQUE, GROUP_ROBOT
from laserpick.robot.sim.scenes import Scene, add_scene_to_spec
from laserpick.settings import get_settings
from laserpick.transforms import pinhole_intrinsics, quat_from_matrix, rotx, roty, rotz

G = mujoco.mjtGeom
J = mujoco.mjtJoint

# Collision bitmasks. Two geoms touch if (type_a & affinity_b) or (type_b & affinity_a).
# The scooter shell never touches the floor (its planar joints carry it), and the arm does not
# touch itself (mink keeps it clear); everything else collides.
STATIC_TYPE, STATIC_AFFINITY = 1, 2  # floor and surfaces
ARM_TYPE, ARM_AFFINITY = 4, 1 | 2 | 8  # arm and gripper
SCOOTER_TYPE, SCOOTER_AFFINITY = 8, 2  # scooter shell, basket
# Objects use type 2 / affinity 1|2|4|8 (see objects.py).

SCOOTER_BODY = "scooter"
ARM_PREFIX = "ur5/"
TCP_SITE = "tcp"
FLANGE_SITE = "flange"
LASER_SITE = "laser/origin"
PROJECTOR_CAMERA = "projector"
BASE_JOINTS = ("base_x", "base_y", "base_yaw")
FINGER_JOINTS = ("finger_left", "finger_right")
GRIPPER_ACTUATOR = "gripper"
SCOOTER_COLLISION_PREFIX = "scooter/"

ROBOT_RGBA = (0.62, 0.66, 0.72, 1.0)
JOINT_RGBA = (0.20, 0.45, 0.75, 1.0)
SCOOTER_RGBA = (0.75, 0.12, 0.12, 1.0)
DARK_RGBA = (0.12, 0.12, 0.13, 1.0)
PAD_RGBA = (0.05, 0.05, 0.05, 1.0)


def arm_joint_name(i: int) -> str:
    """Name of UR5 joint i (0-based) in both models."""
    return ARM_PREFIX + dims.UR5_JOINT_NAMES[i]


ARM_JOINTS = tuple(arm_joint_name(i) for i in range(6))


def _quat(R: np.ndarray) -> list[float]:
    return quat_from_matrix(R).tolist()


def camera_rotation(pitch_down: float, yaw: float) -> np.ndarray:
    """Rotation of a MuJoCo camera frame (looks along -z, +y up) in `base`.

    At zero pitch and yaw the camera looks along +x of `base` with its image's up along +z.
    """
    look_forward = np.array([[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    return rotz(yaw) @ roty(pitch_down) @ look_forward


def depth_intrinsics() -> np.ndarray:
    """K (3x3, pixels) of every depth camera, from dims' resolution and vertical field of view."""
    return pinhole_intrinsics(dims.DEPTH_WIDTH, dims.DEPTH_HEIGHT, dims.DEPTH_FOVY)


def _geom(body: mujoco.MjsBody, name: str, kind: mujoco.mjtGeom, size, pos=(0, 0, 0), **kw):
    g = body.add_geom(name=name, type=kind, size=list(size) + [0] * (3 - len(size)), pos=list(pos))
    for key, value in kw.items():
        setattr(g, key, value)
    return g


def _capsule_between(
    body: mujoco.MjsBody, name: str, a, b, radius: float, mass: float, rgba=ROBOT_RGBA
) -> mujoco.MjsGeom:
    """An arm collision capsule from point a to point b in the body's frame (m)."""
    return _geom(
        body,
        name,
        G.mjGEOM_CAPSULE,
        (radius,),
        fromto=[*a, *b],
        mass=mass,
        rgba=list(rgba),
        group=GROUP_ROBOT,
        contype=ARM_TYPE,
        conaffinity=ARM_AFFINITY,
    )


# --- the arm ----------------------------------------------------------------------------------


def _add_ur5(parent: mujoco.MjsBody, fingers_move: bool) -> mujoco.MjsBody:
    """The UR5 and its gripper under `parent`; returns the gripper body."""
    d, a, alpha = dims.UR5_D, dims.UR5_A, dims.UR5_ALPHA
    m, r = dims.UR5_LINK_MASSES, dims.UR5_LINK_RADII
    base = parent.add_body(
        name=ARM_PREFIX + "base",
        pos=dims.ARM_MOUNT_POS.tolist(),
        quat=_quat(rotz(dims.ARM_MOUNT_YAW)),
    )
    _capsule_between(base, ARM_PREFIX + "base/c", (0, 0, 0.0), (0, 0, 0.03), r[0], m[0], DARK_RGBA)

    body = base
    for i in range(6):
        if i == 0:
            pos, R = (0.0, 0.0, 0.0), np.eye(3)
        else:
            pos, R = (a[i - 1], 0.0, d[i - 1]), rotx(alpha[i - 1])
        body = body.add_body(name=ARM_PREFIX + f"link{i + 1}", pos=list(pos), quat=_quat(R))
        body.gravcomp = 1.0  # the UR5 controller compensates gravity; so does ours
        j = body.add_joint(name=arm_joint_name(i), type=J.mjJNT_HINGE, axis=[0, 0, 1])
        j.range = [float(dims.UR5_Q_MIN[i]), float(dims.UR5_Q_MAX[i])]
        j.limited = mujoco.mjtLimited.mjLIMITED_TRUE
        j.armature = 0.1 if i < 3 else 0.02
        j.damping = [1.0 if i < 3 else 0.2, 0.0, 0.0]
        share = m[i + 1] / len(LINK_CAPSULES[i])
        for k, (p0, p1, rad) in enumerate(LINK_CAPSULES[i]):
            if np.allclose(p0, p1):
                p1 = (p1[0], p1[1], p1[2] + 1e-3)
            _capsule_between(body, ARM_PREFIX + f"link{i + 1}/c{k}", p0, p1, rad, share)
        # The joint's housing, for looks and collision: a ball or a short capsule.
        _, end, radius = HOUSING_CAPSULES[i]  # centred on the origin, along z
        hous = body.add_geom(name=ARM_PREFIX + f"link{i + 1}/joint", pos=[0, 0, 0])
        if end[2] > 0:
            hous.type, hous.size = G.mjGEOM_CAPSULE, [radius, end[2], 0]
        else:
            hous.type, hous.size = G.mjGEOM_SPHERE, [radius, 0, 0]
        hous.rgba = list(JOINT_RGBA)
        hous.group = GROUP_ROBOT
        hous.mass = 0.0
        hous.contype, hous.conaffinity = ARM_TYPE, ARM_AFFINITY
    flange = body.add_body(name=ARM_PREFIX + "flange", pos=[0, 0, d[5]])
    flange.add_site(name=FLANGE_SITE, pos=[0, 0, 0], size=[0.005, 0, 0], group=5)
    return _add_gripper(flange, fingers_move)


def _add_gripper(flange: mujoco.MjsBody, fingers_move: bool) -> mujoco.MjsBody:
    """A two-finger parallel gripper. Local frame = flange: z approach, y closing, x hand axis."""
    g = flange.add_body(name="gripper", pos=[0, 0, 0])
    g.gravcomp = 1.0
    L, F = dims.GRIPPER_BASE_LENGTH, dims.GRIPPER_FINGER_LENGTH
    housing = _geom(
        g,
        "gripper/housing",
        G.mjGEOM_BOX,
        (dims.GRIPPER_BODY_DEPTH / 2, dims.GRIPPER_BODY_WIDTH / 2, L / 2 - 0.01),
        (0, 0, L / 2 + 0.01),
        rgba=list(DARK_RGBA),
        group=GROUP_ROBOT,
        mass=dims.GRIPPER_MASS * 0.8,
        contype=ARM_TYPE,
        conaffinity=ARM_AFFINITY,
    )
    del housing
    _geom(
        g,
        "gripper/coupling",
        G.mjGEOM_CYLINDER,
        (0.038, 0.006),
        (0, 0, 0.006),
        rgba=list(ROBOT_RGBA),
        group=GROUP_ROBOT,
        mass=0.05,
        contype=ARM_TYPE,
        conaffinity=ARM_AFFINITY,
    )
    g.add_site(name=TCP_SITE, pos=[0, 0, dims.GRIPPER_TCP_OFFSET], size=[0.006, 0, 0], group=5)

    finger_t = 0.008  # finger plate thickness along the closing axis (m)
    pad_t = dims.GRIPPER_PAD_THICKNESS
    for side, sign in (("left", 1.0), ("right", -1.0)):
        f = g.add_body(name=f"finger_{side}", pos=[0, 0, 0])
        f.gravcomp = 1.0
        if fingers_move:
            j = f.add_joint(name=f"finger_{side}", type=J.mjJNT_SLIDE, axis=[0, sign, 0])
            j.range = [0.0, dims.GRIPPER_STROKE / 2]
            j.limited = mujoco.mjtLimited.mjLIMITED_TRUE
            j.armature = 0.01
            j.damping = [5.0, 0.0, 0.0]
            q_open = 0.0
        else:
            # The kinematic model holds the fingers fully open.
            q_open = dims.GRIPPER_STROKE / 2
        y_pad = sign * (q_open + pad_t / 2)
        y_plate = sign * (q_open + pad_t + finger_t / 2)
        _geom(
            f,
            f"gripper/finger_{side}",
            G.mjGEOM_BOX,
            (0.012, finger_t / 2, F / 2),
            (0, y_plate, L + F / 2),
            rgba=list(ROBOT_RGBA),
            group=GROUP_ROBOT,
            mass=0.05,
            contype=ARM_TYPE,
            conaffinity=ARM_AFFINITY,
        )
        _geom(
            f,
            f"gripper/pad_{side}",
            G.mjGEOM_BOX,
            (dims.GRIPPER_PAD_WIDTH / 2, pad_t / 2, dims.GRIPPER_PAD_DEPTH / 2),
            (0, y_pad, L + F - dims.GRIPPER_PAD_DEPTH / 2),
            rgba=list(PAD_RGBA),
            group=GROUP_ROBOT,
            mass=0.01,
            contype=ARM_TYPE,
            conaffinity=ARM_AFFINITY,
            condim=4,
            friction=list(dims.PAD_FRICTION),
            # Stiff, slightly soft-contact pads: a firm rubber pad rather than steel.
            solref=[0.004, 1.0],
            solimp=[0.95, 0.99, 0.001, 0.5, 2.0],
            priority=1,
        )
    return g


# --- the scooter ------------------------------------------------------------------------------


def _shell(body: mujoco.MjsBody, name: str, kind, size, pos, rgba=SCOOTER_RGBA, quat=None, **kw):
    """A massless geom of the scooter's shell, in `base`."""
    g = _geom(
        body,
        SCOOTER_COLLISION_PREFIX + name,
        kind,
        size,
        pos,
        rgba=list(rgba),
        group=GROUP_ROBOT,
        contype=SCOOTER_TYPE,
        conaffinity=SCOOTER_AFFINITY,
        mass=0.0,
        **kw,
    )
    if quat is not None:
        g.quat = list(quat)
    return g


def _shell_capsule(body: mujoco.MjsBody, name: str, a, b, radius: float, rgba=DARK_RGBA) -> None:
    """A shell capsule from point a to point b in `base` (m)."""
    _shell(body, name, G.mjGEOM_CAPSULE, (radius,), (0, 0, 0), rgba, fromto=[*a, *b])


def _add_scooter_shell(body: mujoco.MjsBody) -> None:
    """Deck, seat, tiller, handlebars, wheels, sensor posts and the basket, in `base`."""
    x0 = -dims.SCOOTER_REAR_OVERHANG
    length = dims.SCOOTER_LENGTH - 0.12  # the basket overhangs the deck's front edge
    deck_z = dims.SCOOTER_DECK_HEIGHT - dims.SCOOTER_DECK_THICKNESS / 2
    _shell(
        body,
        "deck",
        G.mjGEOM_BOX,
        (length / 2, dims.SCOOTER_WIDTH / 2, dims.SCOOTER_DECK_THICKNESS / 2),
        (x0 + length / 2, 0, deck_z),
    )
    # Seat: a post, a cushion and a backrest.
    _shell(body, "seat_post", G.mjGEOM_CYLINDER, (0.035, 0.12), (dims.SEAT_X, 0, 0.42), DARK_RGBA)
    _shell(
        body,
        "seat",
        G.mjGEOM_BOX,
        (0.22, 0.24, 0.05),
        (dims.SEAT_X, 0, dims.SEAT_HEIGHT - 0.05),
        DARK_RGBA,
    )
    _shell(
        body,
        "seat_back",
        G.mjGEOM_BOX,
        (0.05, 0.23, 0.2),
        (dims.SEAT_X - 0.2, 0, dims.SEAT_BACK_HEIGHT - 0.2),
        DARK_RGBA,
    )
    # Tiller, leaning back toward the rider, and the handlebars across its top.
    tiller_bottom = np.array([dims.TILLER_X + 0.04, 0.0, dims.SCOOTER_DECK_HEIGHT])
    tiller_top = np.array([dims.TILLER_X, 0.0, dims.HANDLEBAR_HEIGHT])
    _shell_capsule(body, "tiller", tiller_bottom, tiller_top, 0.04, SCOOTER_RGBA)
    half, bar_x = dims.HANDLEBAR_WIDTH / 2, dims.TILLER_X - 0.03
    _shell_capsule(
        body,
        "handlebar",
        (bar_x, half, dims.HANDLEBAR_HEIGHT),
        (bar_x, -half, dims.HANDLEBAR_HEIGHT),
        0.018,
    )
    # Wheels: rear drive wheels on the axle (x = 0) and a front caster. Visual and collision
    # only: the base's planar joints, not wheel contacts, carry the scooter.
    wheel_q = _quat(rotx(math.pi / 2))
    for side, sign in (("left", 1), ("right", -1)):
        _shell(
            body,
            f"wheel_{side}",
            G.mjGEOM_CYLINDER,
            (dims.WHEEL_RADIUS, dims.WHEEL_WIDTH / 2),
            (0, sign * dims.WHEEL_TRACK / 2, dims.WHEEL_RADIUS),
            DARK_RGBA,
            quat=wheel_q,
        )
    _shell(
        body,
        "caster",
        G.mjGEOM_SPHERE,
        (dims.CASTER_RADIUS,),
        (dims.CASTER_X, 0, dims.CASTER_RADIUS),
        DARK_RGBA,
    )
    # Sensor posts: two uprights carrying the four low sensors, the left one taller for the
    # fifth sensor.
    # The cameras' and the projector's housings, as the planner's keep-out boxes know them.
    for h in HOUSINGS:
        _shell(body, h.name, G.mjGEOM_BOX, h.half, h.centre, DARK_RGBA, quat=_quat(h.R))
    for side, y, top in (
        ("left", dims.SENSOR_GROUP_SPACING / 2, dims.SENSOR_HIGH_HEIGHT),
        ("right", -dims.SENSOR_GROUP_SPACING / 2, dims.SENSOR_LOW_HEIGHT),
    ):
        x = dims.SENSOR_X - POST_BACK
        _shell_capsule(
            body, f"post_{side}", (x, y, dims.SCOOTER_DECK_HEIGHT), (x, y, top - 0.02), POST_RADIUS
        )
    # The projector's bracket, from the tall post to the projector's housing at its height.
    px, py, pz = dims.PROJECTOR_POS
    bracket_z = pz + PROJECTOR_HOUSING_RAISE
    _shell_capsule(
        body,
        "projector_bracket",
        (dims.SENSOR_X - POST_BACK, dims.SENSOR_GROUP_SPACING / 2, bracket_z),
        (px, py, bracket_z),
        0.012,
    )
    # Basket: a floor and four walls, open at the top.
    c, inner, w = dims.BASKET_CENTER, dims.BASKET_INNER, dims.BASKET_WALL
    hx, hy, hz = inner / 2
    basket_rgba = (0.15, 0.15, 0.16, 1.0)
    _shell(
        body,
        "basket_floor",
        G.mjGEOM_BOX,
        (hx + w, hy + w, dims.BASKET_FLOOR_THICKNESS / 2),
        c + np.array([0.0, 0.0, -hz - dims.BASKET_FLOOR_THICKNESS / 2]),
        basket_rgba,
    )
    for name, pos, size in (
        ("basket_front", (hx + w / 2, 0, 0), (w / 2, hy + w, hz)),
        ("basket_back", (-hx - w / 2, 0, 0), (w / 2, hy + w, hz)),
        ("basket_left", (0, hy + w / 2, 0), (hx, w / 2, hz)),
        ("basket_right", (0, -hy - w / 2, 0), (hx, w / 2, hz)),
    ):
        _shell(body, name, G.mjGEOM_BOX, size, c + np.array(pos), basket_rgba)
    # The arm's pedestal on the front of the deck.
    mx, my, mz = dims.ARM_MOUNT_POS
    _shell(
        body,
        "arm_pedestal",
        G.mjGEOM_CYLINDER,
        (PEDESTAL_RADIUS, (mz - PEDESTAL_FOOT) / 2),
        (mx, my, (mz + PEDESTAL_FOOT) / 2),
        DARK_RGBA,
    )
    _shell(
        body,
        "arm_bracket",
        G.mjGEOM_BOX,
        ((mx - 0.9) / 2 + 0.05, 0.05, 0.04),
        ((mx + 0.9) / 2, my, 0.19),
        DARK_RGBA,
    )


def _add_sensors(body: mujoco.MjsBody) -> None:
    """The five depth cameras, the projector camera and the laser origin, fixed to `body`."""
    for mount in dims.CAMERA_MOUNTS:
        cam = body.add_camera(
            name=mount.name,
            pos=list(mount.pos),
            quat=_quat(camera_rotation(mount.pitch_down, mount.yaw)),
        )
        cam.fovy = math.degrees(dims.DEPTH_FOVY)
    proj = body.add_camera(
        name=PROJECTOR_CAMERA,
        pos=list(dims.PROJECTOR_POS),
        quat=_quat(camera_rotation(dims.PROJECTOR_PITCH_DOWN, dims.PROJECTOR_YAW)),
    )
    proj.fovy = math.degrees(dims.PROJECTOR_FOVY)
    body.add_site(name=LASER_SITE, pos=list(dims.LASER_ORIGIN), size=[0.01, 0, 0], group=5)


# --- whole models -----------------------------------------------------------------------------


def _configure(spec: mujoco.MjSpec) -> None:
    s = get_settings().sim
    spec.compiler.degree = False  # every angle in this file is in radians
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


def _add_actuators(spec: mujoco.MjSpec) -> None:
    for i, name in enumerate(ARM_JOINTS):
        act = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        kp = 3000.0 if i < 3 else 600.0
        act.set_to_position(kp=kp, kv=2 * math.sqrt(kp * (6.0 if i < 3 else 0.5)))
        act.ctrlrange = [float(dims.UR5_Q_MIN[i]), float(dims.UR5_Q_MAX[i])]
        act.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
        act.forcerange = [-dims.UR5_TORQUE_MAX[i], dims.UR5_TORQUE_MAX[i]]
        act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
    # One actuator drives the left finger; an equality mirrors it on the right, as the
    # 2F-85's linkage does. The force range is the grip force limit.
    grip = spec.add_actuator(
        name=GRIPPER_ACTUATOR, target=FINGER_JOINTS[0], trntype=mujoco.mjtTrn.mjTRN_JOINT
    )
    grip.set_to_position(kp=4000.0, kv=60.0)
    grip.ctrlrange = [0.0, dims.GRIPPER_STROKE / 2]
    grip.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
    grip.forcerange = [-dims.GRIPPER_FORCE_MAX, dims.GRIPPER_FORCE_MAX]
    grip.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
    eq = spec.add_equality(
        type=mujoco.mjtEq.mjEQ_JOINT, name1=FINGER_JOINTS[1], name2=FINGER_JOINTS[0]
    )
    eq.objtype = mujoco.mjtObj.mjOBJ_JOINT
    eq.data[:5] = [0, 1, 0, 0, 0]
    # The linkage is rigid. At MuJoCo's default softness the coupling gave way under the
    # grip force: the driven finger pushed the object 1.1 cm off the hand's centre,
    # against the other finger opened to its stop.
    # The stiffest MuJoCo keeps stable: a time constant of two steps.
    eq.solref = [2 * spec.option.timestep, 1.0]
    eq.solimp = [0.99, 0.999, 0.001, 0.5, 2.0]
    # Base: velocity servos on the planar joints; the drive turns (v, w) into these.
    for name, kv in zip(BASE_JOINTS, (4000.0, 4000.0, 2000.0), strict=True):
        act = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.set_to_velocity(kv=kv)
        act.forcerange = [-5000.0, 5000.0]
        act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE


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
    _add_scooter_shell(scooter)
    _add_sensors(scooter)
    _add_ur5(scooter, fingers_move=True)
    # The arm's first links sit in the pedestal; they must not push on it.
    for link in ("base", "link1"):
        spec.add_exclude(bodyname1=SCOOTER_BODY, bodyname2=ARM_PREFIX + link)
    _add_actuators(spec)
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
        _add_scooter_shell(root)
    _add_ur5(root, fingers_move=False)
    if with_scooter:
        for link in ("base", "link1"):
            spec.add_exclude(bodyname1=SCOOTER_BODY, bodyname2=ARM_PREFIX + link)
    return spec


def build_arm_model(with_scooter: bool = True) -> mujoco.MjModel:
    """Compile the arm-only kinematic model (see `build_arm_spec`)."""
    return build_arm_spec(with_scooter).compile()
