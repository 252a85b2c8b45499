"""Time parametrization keeps joint speed, joint acceleration and TCP speed within limits."""

from __future__ import annotations

import numpy as np
import pytest

from laserpick.description import kinematics as K
from laserpick.pipeline.timing import time_parametrize


def _rates(traj):
    dt = np.diff(traj.times)
    v = np.diff(traj.q, axis=0) / dt[:, None]
    a = np.diff(v, axis=0) / dt[1:, None]
    return v, a


def test_single_segment_respects_speed_and_acceleration_and_rests_at_the_ends():
    q0 = np.zeros(6)
    q1 = np.array([1.2, -0.6, 0.9, 0.0, 0.3, -1.5])
    traj = time_parametrize(np.stack([q0, q1]), v_max=1.0, a_max=2.0, dt=0.005)
    v, a = _rates(traj)
    assert np.abs(v).max() <= 1.0 + 1e-6
    assert np.abs(a).max() <= 2.0 + 1e-3
    np.testing.assert_allclose(traj.q[0], q0)
    np.testing.assert_allclose(traj.q[-1], q1)
    assert np.abs(v[0]).max() < 0.02 and np.abs(v[-1]).max() < 0.02
    # The slowest joint (1.5 rad) sets the pace: cruise at 1 rad/s plus 0.5 s of ramps.
    assert traj.duration == pytest.approx(1.5 + 1.0 / 2.0, abs=0.01)


def test_short_moves_use_a_triangle_profile():
    traj = time_parametrize(np.stack([np.zeros(6), np.full(6, 0.1)]), v_max=1.0, a_max=2.0)
    v, _ = _rates(traj)
    assert np.abs(v).max() < 1.0  # never reached cruise
    assert traj.duration == pytest.approx(2 * np.sqrt(0.1 / 2.0), abs=0.02)


def test_tcp_speed_cap_slows_a_long_reach():
    q0 = np.array([-0.4, -1.7, 1.5, 1.7, 1.57, 1.1])
    q1 = q0 + np.array([0.6, 0.3, -0.4, 0.0, 0.0, 0.0])
    path = np.linspace(q0, q1, 30)
    tcp = K.tcp_pose(path)[:, :3, 3]
    fast = time_parametrize(path, v_max=3.14, a_max=3.0)
    slow = time_parametrize(path, v_max=3.14, a_max=3.0, tcp=tcp, tcp_speed=0.25)
    assert slow.duration > fast.duration
    p = K.tcp_pose(slow.q)[:, :3, 3]
    speed = np.linalg.norm(np.diff(p, axis=0), axis=1) / np.diff(slow.times)
    assert speed.max() <= 0.25 * 1.05  # 5 %: the path between waypoints is not a straight line


def test_gripper_events_fire_at_their_waypoints():
    path = np.array([np.zeros(6), np.full(6, 0.2), np.full(6, 0.4)])
    traj = time_parametrize(path, v_max=1.0, a_max=2.0, gripper=((1, "close"),))
    (event,) = traj.gripper
    assert event.action == "close"
    np.testing.assert_allclose(traj.sample(event.t), path[1], atol=1e-3)


def test_bad_paths_are_refused_with_a_reason():
    with pytest.raises(ValueError, match="two"):
        time_parametrize(np.zeros((1, 6)), v_max=1.0, a_max=1.0)
    with pytest.raises(ValueError, match="positive"):
        time_parametrize(np.zeros((2, 6)), v_max=0.0, a_max=1.0)
    with pytest.raises(ValueError, match="waypoint 5"):
        time_parametrize(
            np.stack([np.zeros(6), np.ones(6)]), v_max=1, a_max=1, gripper=((5, "open"),)
        )
