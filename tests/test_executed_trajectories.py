"""Every trajectory the arm runs in a bench episode is one a real UR5 could follow: sampled
evenly, from rest to rest, with no jump in joint velocity between samples, and within the
joint speed, acceleration and jerk limits, the TCP's speed caps and, while the hand holds
the object, the hand's turning cap of `MotionSettings`."""

from __future__ import annotations

import numpy as np
import pytest

from laserpick.bench.protocols import Options
from laserpick.bench.runner import run
from laserpick.description import kinematics as K
from laserpick.pipeline.timing import Limits, excess
from laserpick.robot.sim.robot import SimRobot
from laserpick.settings import get_settings
from laserpick.types import Trajectory

#: Rounding in the finite differences (relative).
ROUNDING = 1e-6


def _finite_differences(traj: Trajectory) -> tuple[np.ndarray, ...]:
    """Joint velocity, acceleration and jerk (rad/s^n) by finite differences, the arm at
    rest for three samples before and after, and the sample spacing (s)."""
    h = np.diff(traj.times)
    assert np.allclose(h, h[0], rtol=1e-9), "samples evenly spaced"
    rest = np.vstack([traj.q[:1]] * 3 + [traj.q] + [traj.q[-1:]] * 3)
    v = np.diff(rest, axis=0) / h[0]
    a = np.diff(v, axis=0) / h[0]
    return v, a, np.diff(a, axis=0) / h[0], h[0]


def test_every_trajectory_of_a_bench_episode_is_smooth_and_within_the_limits(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """One isolation trial on one object (seed 1): the pick, the carry to the basket and the
    way to stand by. Each trajectory the robot was given is checked, sample by sample:
    joint speed <= `joint_speed`, acceleration <= `joint_accel`, jerk <= `joint_jerk`
    (the stated bound), the change of velocity from one sample to the next <= joint_accel
    times the sample spacing (no jump, from rest at the start either), the TCP's speed <=
    `tcp_speed`, and on the guarded approach <= `approach_speed`; with the object in the
    hand, the hand turns no faster than `carry_turn_speed`."""
    executed: list[Trajectory] = []
    holding: list[Trajectory] = []
    real_execute = SimRobot.execute

    def execute(self: SimRobot, traj: Trajectory):
        executed.append(traj)
        if self.gripper_state().holding:
            holding.append(traj)
        return real_execute(self, traj)

    monkeypatch.setattr(SimRobot, "execute", execute)
    result = run("isolation", trials=1, seed=1, options=Options(objects=1), workers=1)
    assert [r["success"] for r in result["records"]] == [True]
    # To the grasp, approach, re-grip, lift, carry, rise off the object, stand by.
    assert len(executed) >= 7
    s = get_settings().motion
    for traj in executed:
        v, a, j, h = _finite_differences(traj)
        assert np.abs(v).max() <= s.joint_speed * (1 + ROUNDING)
        assert np.abs(a).max() <= s.joint_accel * (1 + ROUNDING)
        assert np.abs(j).max() <= s.joint_jerk * (1 + ROUNDING)
        assert np.abs(np.diff(v, axis=0)).max() <= s.joint_accel * h * (1 + ROUNDING)
        p = K.tcp_pose(traj.q)[:, :3, 3]
        tcp = np.linalg.norm(np.diff(p, axis=0), axis=1).max() / h
        cap = s.approach_speed if traj.guard_force == s.guard_force else s.tcp_speed
        assert tcp <= cap * (1 + ROUNDING)
    assert any(t.guard_force == s.guard_force for t in executed)  # the approach was among them
    turning = Limits(s.joint_speed, s.joint_accel, s.joint_jerk, turn_speed=s.carry_turn_speed)
    carried = [t for t in holding if len(t.q) > 1]
    assert len(carried) >= 3  # the re-grip's lift, the lift, the carry
    for traj in carried:
        assert excess(traj.q, traj.times[1] - traj.times[0], turning)["turn_speed"] <= 1 + 1e-6
