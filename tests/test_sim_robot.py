"""SimRobot behind the Robot interface: frames with laser dots, state reads, and capture that
runs beside the real-time loop without stalling it."""

from __future__ import annotations

import time

import numpy as np
import pytest

from laserpick.description import dims
from laserpick.robot.interface import Robot
from laserpick.robot.sim.robot import SimRobot
from laserpick.robot.sim.scenes import load_scene


@pytest.fixture(scope="module")
def robot():
    r = SimRobot(load_scene("isolation"), realtime=False)
    yield r
    r.close()


def test_sim_robot_satisfies_the_robot_interface(robot):
    for name in Robot.__dict__:
        if not name.startswith("_"):
            assert callable(getattr(robot, name)), name


def test_capture_gives_five_frames_with_the_confirmed_laser_seen(robot):
    p = robot.sim.scene.placements[0]
    robot.laser.aim_at(p.pos + np.array([0.0, 0.0, 0.8 * p.model.height]))
    robot.laser.confirm()
    frames = robot.capture()
    assert [f.camera for f in frames] == [c.name for c in dims.CAMERA_MOUNTS]
    hits = robot.laser_hits()
    assert len(hits) == 2
    seen = 0
    for f in frames:
        assert f.depth.shape == (dims.DEPTH_HEIGHT, dims.DEPTH_WIDTH)
        assert f.ir.dtype == np.uint8
        bright = np.argwhere(f.ir >= 250)
        if len(bright) == 0:
            continue
        # Deproject the brightest pixels and check they land on a beam's hit point.
        v, u = bright.mean(axis=0)
        z = f.depth[round(v), round(u)]
        if z <= 0:
            continue
        ray = np.linalg.solve(f.K, [u, v, 1.0]) * z
        p_base = f.T_base_cam[:3, :3] @ ray + f.T_base_cam[:3, 3]
        midpoint = (hits[0] + hits[1]) / 2  # scooter at the origin: world == base
        assert np.linalg.norm(p_base - midpoint) < 0.03
        seen += 1
    assert seen >= 2
    robot.laser.off()
    assert all(int((f.ir >= 250).sum()) == 0 for f in robot.capture())


def test_state_reads_match_the_snapshot(robot):
    js = robot.joint_state()
    np.testing.assert_allclose(js.q, dims.UR5_HOME_Q, atol=0.02)
    gs = robot.gripper_state()
    assert gs.width == pytest.approx(dims.GRIPPER_STROKE, abs=0.002)
    assert not gs.holding
    np.testing.assert_allclose(robot.base_pose(), [0.0, 0.0, 0.0], atol=1e-3)


def test_capture_does_not_stall_the_realtime_loop():
    r = SimRobot(load_scene("isolation"), realtime=True)
    try:
        r.capture()  # the first capture builds the GL context
        t0, w0 = r.sim.snapshot().time, time.perf_counter()
        for _ in range(4):
            r.capture()
        t1, w1 = r.sim.snapshot().time, time.perf_counter()
        # Physics went on while frames rendered on the capture thread.
        assert t1 - t0 > 0.5 * (w1 - w0)
    finally:
        r.close()
