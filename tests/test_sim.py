"""The simulation loop: real-time pacing, pause, headless determinism, e-stop, the drive's
dead-man and acceleration limits, trajectory tracking, and that bad commands hurt nothing."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from laserpick.description import dims
from laserpick.description import kinematics as K
from laserpick.pipeline.timing import Limits, time_parametrize
from laserpick.robot.sim.loop import Simulation
from laserpick.robot.sim.scenes import load_scene
from laserpick.settings import get_settings
from laserpick.types import GripperEvent, Trajectory

MOTION = get_settings().motion


@pytest.fixture
def sim():
    s = Simulation(load_scene("isolation"), realtime=False)
    yield s
    s.close()


def _line(q0: np.ndarray, q1: np.ndarray, speed: float = 0.5) -> Trajectory:
    """A rest-to-rest joint move at up to `speed` rad/s, timed by the pipeline's own planner."""
    limits = Limits(speed, dims.UR5_QDD_MAX, MOTION.joint_jerk)
    return time_parametrize(np.stack([q0, q1]), limits=limits, tolerance=MOTION.blend_tolerance)


def test_contact_options_hold_a_parallel_jaw_grasp(sim):
    import mujoco

    opt = sim.model.opt
    assert opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC
    assert opt.impratio >= 10
    pads = sim.info.pad_geoms
    assert np.all(sim.model.geom_condim[pads] == 4)


def test_trajectory_is_tracked_and_its_gripper_events_fire(sim):
    q0 = sim.snapshot().arm_q
    q1 = q0 + np.array([0.4, 0.3, -0.3, 0.2, 0.2, 0.5])
    traj = _line(q0, q1)
    traj = Trajectory(traj.times, traj.q, (GripperEvent(traj.duration / 2, "close"),))
    h = sim.execute(traj)
    assert sim.run_until(h, traj.duration + 2.0) == "done"
    sim.settle(0.5)
    s = sim.snapshot()
    assert np.max(np.abs(s.arm_q - q1)) < 2e-3
    assert s.gripper_closed and s.gripper_width < 0.002  # closed on nothing
    assert not s.holding


def test_estop_halts_within_one_step_and_latches(sim):
    q0 = sim.snapshot().arm_q
    h = sim.execute(_line(q0, q0 + np.array([1.5, 0.0, 0.0, 0.0, 0.0, 1.5]), speed=1.0))
    sim.step(300)  # mid-motion
    assert np.max(np.abs(sim.snapshot().arm_qd)) > 0.3
    t_stop = sim.snapshot().time
    sim.stop()
    assert h.status == "stopped"
    sim.step(10)  # 20 ms of sim time
    s = sim.snapshot()
    assert s.time - t_stop <= 0.02 + 1e-9
    assert np.max(np.abs(s.arm_qd)) < 1e-3, f"arm still moving after e-stop: {s.arm_qd}"
    assert s.estopped
    # Latched: new motion is refused, the arm stays put.
    h2 = sim.execute(_line(s.arm_q, s.arm_q + 0.3))
    assert h2.status == "failed" and "e-stop" in h2.message
    sim.drive(0.5, 0.0)
    sim.step(100)
    assert np.linalg.norm(sim.snapshot().base_velocity) < 1e-6
    sim.reset_stop()
    h3 = sim.execute(_line(sim.snapshot().arm_q, sim.snapshot().arm_q + 0.1))
    assert sim.run_until(h3, 3.0) == "done"


def test_drive_is_a_dead_man_with_acceleration_limits(sim):
    x0 = sim.snapshot().base_pose.copy()
    sim.drive(0.6, 0.0, duration=10.0)  # asks for 10 s; capped at 0.5 s
    sim.step(round(0.1 / sim.dt))
    v = sim.snapshot().base_velocity[0]
    assert v <= dims.BASE_A_MAX * 0.1 + 0.02, "acceleration limit not respected"
    sim.settle(2.0)
    s = sim.snapshot()
    assert abs(s.base_velocity[0]) < 1e-2, "the base kept moving without a fresh command"
    moved = s.base_pose[0] - x0[0]
    assert 0.05 < moved < 0.6 * 0.5 + 0.05


def test_drive_turns_with_the_heading(sim):
    for _ in range(20):
        sim.drive(0.0, 0.8)
        sim.settle(0.1)
    sim.settle(1.5)
    yaw = sim.snapshot().base_pose[2]
    assert yaw > 0.5
    x0 = sim.snapshot().base_pose[:2].copy()
    for _ in range(10):
        sim.drive(0.4, 0.0)
        sim.settle(0.1)
    sim.settle(1.0)
    d = sim.snapshot().base_pose[:2] - x0
    heading = math.atan2(d[1], d[0])
    assert abs(heading - yaw) < 0.05


def test_bad_commands_are_refused_and_the_loop_survives(sim):
    with pytest.raises(ValueError):
        sim.drive(float("nan"), 0.0)
    with pytest.raises(ValueError):
        Trajectory(times=np.array([0.0, 1.0]), q=np.full((2, 6), np.inf))
    bad = np.eye(4)
    bad[0, 3] = np.nan
    h = sim.move_tcp(bad)
    assert h.status == "failed"
    q = sim.snapshot().arm_q
    far = _line(q + 1.0, q + 1.2)  # does not start where the arm is
    assert sim.execute(far).status == "failed"
    sim.step(50)
    assert np.max(np.abs(sim.snapshot().arm_q - q)) < 1e-3


def test_cartesian_move_reaches_a_pose_in_front(sim):
    T = K.tcp_pose(sim.snapshot().arm_q)
    T[:3, 3] += [0.2, 0.1, 0.1]
    h = sim.move_tcp(T)
    assert sim.run_until(h, 10.0) == "done", h.message
    s = sim.snapshot()
    assert np.linalg.norm(K.tcp_pose(s.arm_q)[:3, 3] - T[:3, 3]) < 3e-3


def test_headless_mode_is_deterministic():
    def run() -> np.ndarray:
        s = Simulation(load_scene("isolation"), realtime=False)
        q0 = s.snapshot().arm_q
        s.run_until(s.execute(_line(q0, q0 + 0.3)), 3.0)
        s.drive(0.3, 0.2)
        s.settle(0.5)
        return s.snapshot().qpos

    np.testing.assert_array_equal(run(), run())


def test_realtime_loop_keeps_pace_and_pauses():
    s = Simulation(load_scene("isolation"), realtime=True)
    s.start()
    try:
        time.sleep(0.3)
        t0, w0 = s.snapshot().time, time.perf_counter()
        time.sleep(1.5)
        t1, w1 = s.snapshot().time, time.perf_counter()
        rate = (t1 - t0) / (w1 - w0)
        # Loose bounds: this checks pacing (not free-running), not the machine's speed.
        assert 0.5 < rate < 1.5, f"sim advanced {rate:.2f} s per wall second"
        s.pause()
        time.sleep(0.1)
        tp = s.snapshot().time
        time.sleep(0.3)
        assert s.snapshot().time == tp
        s.resume()
        time.sleep(0.2)
        assert s.snapshot().time > tp
        # A command from another thread is applied by the loop.
        s.stop()
        time.sleep(0.1)
        assert s.snapshot().estopped
    finally:
        s.close()


def test_a_can_laid_on_its_side_stays_on_its_table():
    """Object contacts have rolling friction: without it, a soda can laid on its side on the
    kitchen's 73 cm table rolls off it within a minute."""
    import yaml

    from laserpick.robot.sim.scenes import parse_scene, scene_config

    config = scene_config("kitchen")
    for obj in config["objects"]:
        obj["lying"] = obj["name"] == "soda_can"
    sim = Simulation(parse_scene(yaml.safe_dump(config)), realtime=False)
    try:
        can = sim.info.object_bodies["soda_can"]
        sim.settle(1.0)
        start = sim.snapshot().xpos[can].copy()
        sim.settle(30.0)
        drift = np.linalg.norm(sim.snapshot().xpos[can] - start)
        assert drift < 0.002, f"the can rolled {drift * 100:.1f} cm in 30 s"
    finally:
        sim.close()


def test_the_force_felt_adds_forces_as_vectors_body_by_body(sim):
    """`contacts` gives the normal force on our geom: an object resting on its table is pushed
    up by its weight. `felt` adds forces as vectors within a body (a finger pressed from both
    sides at once feels nothing net) and their sizes across bodies."""
    from laserpick.robot.sim.loop import Contact

    sim.settle(1.0)
    m = sim.model
    name, body = next(iter(sim.info.object_bodies.items()))
    ours = m.geom_bodyid == body
    contacts = sim.call(lambda m_, d_: sim.contacts(ours, from_outside=True))
    assert contacts, f"{name} rests on nothing"
    weight = float(m.body_subtreemass[body]) * 9.81
    net = np.sum([c.on_ours for c in contacts], axis=0)
    np.testing.assert_allclose(net, [0.0, 0.0, weight], atol=0.05 * weight)
    assert sim.felt(contacts) == pytest.approx(weight, rel=0.05)
    arm = np.asarray(sim.info.arm_geoms)
    finger = int(arm[-1])  # two geoms of the arm on different bodies
    wrist = int(next(g for g in arm if m.geom_bodyid[g] != m.geom_bodyid[finger]))
    push = np.array([0.0, 40.0, 0.0])
    pinched = [Contact(40.0, finger, 0, push), Contact(40.0, finger, 0, -push)]
    assert sim.felt(pinched) == pytest.approx(0.0)
    two = [Contact(40.0, finger, 0, push), Contact(30.0, wrist, 0, np.array([30.0, 0, 0]))]
    assert sim.felt(two) == pytest.approx(70.0)


def test_a_dead_man_halt_while_driving_is_told_to_the_consoles():
    """The dead-man halting a driving scooter leaves the reason where the consoles show why
    the scooter stopped (`drive_stop`): otherwise a drive cut short by a silent controller
    ends without a word."""
    s = Simulation(load_scene("isolation"), realtime=True)
    s.start()
    try:
        time.sleep(0.2)
        s.drive(0.2, 0.0, 0.5)
        s.deadman(time.monotonic() + 0.1)
        give_up = time.monotonic() + 10.0
        while not s.snapshot().drive_stop and time.monotonic() < give_up:
            time.sleep(0.01)
        snap = s.snapshot()
        assert "dead-man" in snap.drive_stop and snap.drive_stop.startswith("The scooter stopped")
        time.sleep(0.1)
        assert np.max(np.abs(s.snapshot().base_velocity)) < 0.01
    finally:
        s.close()


def test_the_controllers_dead_man_halts_at_its_deadline_by_itself():
    """Armed and never renewed, the dead-man halts a running trajectory within one physics
    step of its deadline with nobody else acting, refuses motion while tripped, and lets
    motion again once disarmed."""
    s = Simulation(load_scene("isolation"), realtime=True)
    s.start()
    try:
        time.sleep(0.2)
        q0 = s.snapshot().arm_q
        handle = s.execute(_line(q0, q0 + np.array([0.8, 0, 0, 0, 0, 0])))
        until = time.monotonic() + 0.4
        s.deadman(until)
        readings: list[tuple[float, np.ndarray]] = []  # (monotonic s the state stands for, qd)
        give_up = until + 10.0  # a loaded machine steps late; the readings say when they stand for
        while sum(t >= until + s.dt for t, _ in readings) <= 20 and time.monotonic() < give_up:
            snap = s.snapshot()
            readings.append((snap.taken_at - time.time() + time.monotonic(), snap.arm_qd))
            time.sleep(0.005)
        assert any(np.max(np.abs(qd)) > 0.05 for t, qd in readings if t < until)
        after = [np.max(np.abs(qd)) for t, qd in readings if t >= until + s.dt]
        assert len(after) > 20 and max(after) < 0.01
        assert handle.status == "stopped" and "dead-man" in handle.message
        refused = s.execute(_line(s.snapshot().arm_q, q0))
        time.sleep(0.1)
        assert refused.status == "failed" and "dead-man" in refused.message
        s.deadman(None)
        again = s.execute(_line(s.snapshot().arm_q, q0))
        time.sleep(0.1)
        assert again.status in ("running", "done")
    finally:
        s.close()
