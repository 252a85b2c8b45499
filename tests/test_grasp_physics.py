"""Grasp physics: the gripper, pads and contact settings hold real objects.

For library objects standing upright on the 46 cm table, a scripted top-down grasp closes,
lifts the object 10 cm and holds it for 5 s. This test reads ground-truth object poses on
purpose: it tests the gripper and the contact model, not perception.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from laserpick.description import dims
from laserpick.description import kinematics as K
from laserpick.pipeline.timing import Limits, time_parametrize
from laserpick.robot.sim.loop import Simulation
from laserpick.robot.sim.objects import LIBRARY, min_width, support
from laserpick.robot.sim.scenes import parse_scene
from laserpick.settings import get_settings
from laserpick.transforms import invert, matrix_from_quat, planar_pose, rotz
from laserpick.types import Trajectory

MOTION = get_settings().motion

TABLE_HEIGHT = 0.46
OBJECT_XY = (1.50, -0.25)

# Ten or more objects across the papers' categories, all of which fit the 85 mm stroke.
GRASPED = [
    "soda_can",
    "water_bottle",
    "pill_bottle",
    "tea_box",
    "mug",
    "tv_remote",
    "cordless_phone",
    "ball",
    "spice_jar",
    "tissue_packet",
    "soap_box",
    "computer_mouse",
]


def _scene_text(model_name: str) -> str:
    x, y = OBJECT_XY
    return f"""
name: grasp-{model_name}
scooter: {{x: 0.0, y: 0.0, yaw_deg: 0.0}}
surfaces:
  - name: table
    kind: table
    xy: [1.65, -0.15]
    yaw_deg: 0
    size: [0.6, 1.0]
    height: {TABLE_HEIGHT}
objects:
  - {{name: target, model: {model_name}, on: table, xy: [{x}, {y}], yaw_deg: 20}}
"""


def _joint_path(q0: np.ndarray, q1: np.ndarray, speed: float) -> Trajectory:
    """A rest-to-rest joint move at up to `speed` rad/s, timed by the pipeline's own planner."""
    limits = Limits(speed, dims.UR5_QDD_MAX, MOTION.joint_jerk)
    return time_parametrize(np.stack([q0, q1]), limits=limits, tolerance=MOTION.blend_tolerance)


def _top_down_grasp(obj_pos: np.ndarray, obj_quat: np.ndarray, model) -> np.ndarray:
    """TCP pose in `base` (scooter at the origin): from above, closing across the thin side."""
    R_obj = matrix_from_quat(obj_quat)
    best, best_w = 0.0, math.inf
    for a in np.linspace(0.0, math.pi, 36, endpoint=False):
        d = R_obj @ np.array([math.cos(a), math.sin(a), 0.0])
        w = support(model, d, obj_quat) + support(model, -d, obj_quat)
        if w < best_w:
            best, best_w = a, w
    close_dir = R_obj @ np.array([math.cos(best), math.sin(best), 0.0])
    close_dir[2] = 0.0
    close_dir /= np.linalg.norm(close_dir)
    centre = obj_pos.copy()
    for axis in (np.array([1.0, 0, 0]), np.array([0, 1.0, 0])):
        centre += axis * (support(model, axis, obj_quat) - support(model, -axis, obj_quat)) / 2
    top = obj_pos[2] + support(model, np.array([0, 0, 1.0]), obj_quat)
    z = max(TABLE_HEIGHT + 0.014, top - 0.03)
    approach = np.array([0.0, 0.0, -1.0])
    hand = np.cross(close_dir, approach)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([hand, close_dir, approach])
    T[:3, 3] = [centre[0], centre[1], z]
    return T


def _ik(T: np.ndarray, q_ref: np.ndarray) -> np.ndarray:
    sols = K.ik_tcp(T, q_ref=q_ref)
    assert len(sols), f"no IK for grasp pose at {T[:3, 3]}"
    return sols[0]


def _at_grasp(name: str, turn: float = 0.0) -> tuple[Simulation, int, np.ndarray, np.ndarray]:
    """A simulation with the open hand around `name`, ready to close: the simulation, the
    object's body id, and the arm's grasp and lift configurations (rad). turn: the grasp
    turned by this (rad) about its approach, off the object's sides."""
    model = LIBRARY[name]
    assert min_width(model) <= dims.GRIPPER_STROKE
    sim = Simulation(parse_scene(_scene_text(name)), realtime=False)
    sim.settle(0.5)
    body = sim.info.object_bodies["target"]
    s = sim.snapshot()
    T_world_base = planar_pose(*s.base_pose)
    T_base_world = invert(T_world_base)
    p_obj = (T_base_world @ np.append(s.xpos[body], 1.0))[:3]
    q_obj = s.xquat[body]  # the scooter starts unrotated, so world and base share axes

    grasp = _top_down_grasp(p_obj, q_obj, model)
    grasp[:3, :3] = rotz(turn) @ grasp[:3, :3]  # the approach is straight down
    pre = grasp.copy()
    pre[2, 3] += 0.12
    lift = grasp.copy()
    lift[2, 3] += 0.10
    q_home = s.arm_q
    q_ready = dims.UR5_READY_Q
    q_pre = _ik(pre, q_ready)
    q_grasp = _ik(grasp, q_pre)
    q_lift = _ik(lift, q_grasp)

    for q0, q1, speed in ((q_home, q_ready, 1.0), (q_ready, q_pre, 1.0), (q_pre, q_grasp, 0.3)):
        h = sim.execute(_joint_path(q0, q1, speed))
        assert sim.run_until(h, 15.0) == "done", h.message
    return sim, body, q_grasp, q_lift


def _close_and_lift(sim: Simulation, q_grasp: np.ndarray, q_lift: np.ndarray) -> None:
    """Close the hand at q_grasp, lift to q_lift (rad) and let the object settle."""
    sim.gripper(True)
    sim.settle(1.0)
    h = sim.execute(_joint_path(q_grasp, q_lift, 0.3))
    assert sim.run_until(h, 10.0) == "done", h.message
    sim.settle(0.5)


@pytest.mark.parametrize("name", GRASPED)
def test_top_down_grasp_lifts_10cm_and_holds_5s(name):
    sim, body, q_grasp, q_lift = _at_grasp(name)
    z_rest = sim.snapshot().xpos[body][2]
    _close_and_lift(sim, q_grasp, q_lift)
    z_lifted = sim.snapshot().xpos[body][2]
    sim.settle(5.0)

    s = sim.snapshot()
    lifted = s.xpos[body][2] - z_rest
    assert s.holding, f"{name}: gripper reports empty (width {s.gripper_width * 1000:.1f} mm)"
    # The object may settle a little in the pads as the lift takes its weight (a mug held by
    # its rim sinks about 1.3 cm, depending on sub-millimetre differences of approach), but
    # it must rise most of the 10 cm and then not slip at all while held.
    assert lifted > 0.08, f"{name}: lifted only {lifted * 100:.1f} cm after 5 s"
    drift = z_lifted - s.xpos[body][2]
    assert drift < 0.002, f"{name}: slipped {drift * 1000:.1f} mm in the pads over 5 s"


def test_the_fingers_close_together_and_report_the_objects_width():
    """The 2F-85's linkage moves both fingers as one. A soft coupling let the driven finger
    push a 6.6 cm can 5 mm across the table and against the other finger, opened to its
    stop, and the gripper then reported a 4.3 cm width."""
    sim, body, _, _ = _at_grasp("soda_can")
    before = sim.snapshot().xpos[body][:2].copy()
    sim.gripper(True)
    sim.settle(1.0)
    s = sim.snapshot()
    finger_q = s.qpos[sim.info.finger_qpos]
    assert abs(finger_q[0] - finger_q[1]) < 0.001, f"finger travels {finger_q} (m)"
    assert s.gripper_width == pytest.approx(0.066, abs=0.002)
    pushed = np.linalg.norm(s.xpos[body][:2] - before)
    assert pushed < 0.002, f"closing pushed the can {pushed * 1000:.1f} mm"


def _until_still(sim: Simulation, most: float = 2.0) -> float:
    """Step `sim` until its gripper reports its fingers still; the seconds that took."""
    waited = 0.0
    while sim.snapshot().gripper_moving or waited == 0.0:
        assert waited < most, f"the gripper still reports moving after {most} s"
        sim.settle(0.02)
        waited += 0.02
    return waited


def test_the_gripper_reports_still_at_full_grip_and_lets_go_at_once():
    """As the 2F-85 reports its object status: closed on a 6.6 cm can, the fingers are still
    once the grip is at its force limit, well before the full stroke's time; opened, the
    squeeze is off at once and the fingers stand fully open in a fraction of that."""
    sim, _, _, _ = _at_grasp("soda_can")
    stroke_time = dims.GRIPPER_STROKE / dims.GRIPPER_SPEED
    sim.gripper(True)
    closing = _until_still(sim)
    grip = abs(float(sim.data.actuator_force[sim.info.gripper_ctrl]))
    assert closing < 0.9 * stroke_time, f"closing took {closing:.2f} s"
    assert grip >= 0.99 * dims.GRIPPER_FORCE_MAX, f"still at {grip:.1f} N"
    assert sim.snapshot().holding
    sim.gripper(False)
    opening = _until_still(sim)
    s = sim.snapshot()
    assert opening < 0.5 * stroke_time, f"opening took {opening:.2f} s"
    assert s.gripper_width >= dims.GRIPPER_STROKE - 0.0015
    assert s.gripper_force == 0.0


def test_the_empty_gripper_reports_still_only_once_shut():
    sim = Simulation(None, realtime=False)
    sim.gripper(True)
    closing = _until_still(sim)
    assert closing >= dims.GRIPPER_STROKE / dims.GRIPPER_SPEED - 0.02
    assert sim.snapshot().gripper_width < dims.GRIPPER_EMPTY_GAP


def test_the_palm_does_not_give_under_what_a_squeezed_jar_presses_on_it():
    """The housing is as stiff as the pads: carried from a side grasp on a shelf, a spice jar
    squeezed against the palm by the pads pressed on it with some 80 N, and with MuJoCo's
    default contact softness sank 15 mm into it, to spring out when let go. Here the jar
    stands in the open hand under the palm and is pushed up into it with 80 N: it sinks in
    less than a millimetre (3.5 mm with the default softness)."""
    sim, body, _, _ = _at_grasp("spice_jar")

    def push(m, d):
        d.xfrc_applied[body, :3] = [0.0, 0.0, 80.0]

    def into_the_hand(m, d) -> list[float]:
        """How deep (m) each contact between the jar and the hand's body goes."""
        hand = m.body("gripper").id
        return [
            -float(c.dist)
            for c in d.contact[: d.ncon]
            if {int(m.geom_bodyid[g]) for g in c.geom} == {hand, body}
        ]

    sim.call(push)
    sim.settle(1.0)
    depths = sim.call(into_the_hand)
    assert depths, "the jar is pushed against the palm"
    assert max(depths) < 0.001
