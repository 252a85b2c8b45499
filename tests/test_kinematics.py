"""The arm's kinematics agree three ways: DH (the datasheet), MuJoCo (the MJCF we build) and
Pinocchio (an independent library reading the same MJCF); and the analytic IK inverts them."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from laserpick.description import dims
from laserpick.description import kinematics as K
from laserpick.robot.sim.model import TCP_SITE, build_arm_model, build_arm_spec
from laserpick.transforms import rotation_angle


@pytest.fixture(scope="module")
def arm():
    m = build_arm_model(with_scooter=False)
    return m, mujoco.MjData(m)


def _random_q(rng: np.random.Generator, n: int) -> np.ndarray:
    return rng.uniform(dims.UR5_Q_MIN, dims.UR5_Q_MAX, size=(n, 6))


def test_mjcf_fk_matches_dh_fk_over_1000_configurations(arm):
    m, d = arm
    tcp = m.site(TCP_SITE).id
    Q = _random_q(np.random.default_rng(1), 1000)
    T_dh = K.tcp_pose(Q)
    worst_pos, worst_rot = 0.0, 0.0
    for q, T in zip(Q, T_dh, strict=True):
        d.qpos[:] = q
        mujoco.mj_kinematics(m, d)
        worst_pos = max(worst_pos, float(np.linalg.norm(d.site_xpos[tcp] - T[:3, 3])))
        worst_rot = max(worst_rot, rotation_angle(d.site_xmat[tcp].reshape(3, 3), T[:3, :3]))
    assert worst_pos < 1e-4, f"MJCF vs DH TCP position differs by {worst_pos * 1000:.4f} mm"
    assert worst_rot < 1e-6


def test_dh_zero_pose_is_the_ur5_datasheet_pose():
    # At q = 0 the stretched UR5's flange sits at (a2 + a3, -(d4 + d6), d1 - d5) in frame 0.
    T = K.dh_fk(np.zeros(6))
    d, a = dims.UR5_D, dims.UR5_A
    np.testing.assert_allclose(T[:3, 3], [a[1] + a[2], -(d[3] + d[5]), d[0] - d[4]], atol=1e-12)


def test_ik_round_trips_within_0_1_mm_and_0_1_deg():
    rng = np.random.default_rng(2)
    checked = 0
    for q in _random_q(rng, 300):
        q[2] = rng.uniform(-3.0, 3.0)  # keep clear of the elbow's fully stretched singularity
        T = K.tcp_pose(q)
        sols = K.ik_tcp(T, q_ref=q)
        assert len(sols) > 0, f"no IK solution for a pose reached by q={q}"
        for s in sols:
            Ts = K.tcp_pose(s)
            assert np.linalg.norm(Ts[:3, 3] - T[:3, 3]) < 1e-4
            assert math.degrees(rotation_angle(Ts[:3, :3], T[:3, :3])) < 0.1
        # The nearest solution (in the 2*pi sense) is the configuration we started from.
        assert np.allclose(sols[0], q, atol=1e-6)
        checked += 1
    assert checked == 300


def test_ik_returns_up_to_eight_distinct_solutions_and_none_out_of_reach():
    T = K.tcp_pose(np.array([0.3, -1.2, 1.4, -1.6, -1.5, 0.4]))
    sols = K.ik_tcp(T)
    assert 2 <= len(sols) <= 8
    assert len(np.unique(np.round(sols, 6), axis=0)) == len(sols)
    far = T.copy()
    far[:3, 3] = K.T_BASE_UR5[:3, 3] + [2.0, 0.0, 0.0]
    assert len(K.ik_tcp(far)) == 0


def _pinocchio_arm(tmp_path):
    path = tmp_path / "arm.xml"
    path.write_text(build_arm_spec(with_scooter=False).to_xml())
    model = pin.buildModelFromMJCF(str(path))
    # Pinocchio 4.1's MJCF parser places a site relative to the parent joint, dropping the
    # offsets of fixed bodies in between (our TCP site sits in `gripper`, under `ur5/flange`).
    # Bodies come out right, so hang our own TCP frame on the `gripper` body's frame, using
    # the site offset read from the same MJCF.
    gripper = model.frames[model.getFrameId("gripper")]
    site_pos = build_arm_model(with_scooter=False).site(TCP_SITE).pos.copy()
    model.addFrame(
        pin.Frame(
            "tcp_check",
            gripper.parentJoint,
            model.getFrameId("gripper"),
            gripper.placement * pin.SE3(np.eye(3), site_pos),
            pin.FrameType.OP_FRAME,
        )
    )
    return model, model.createData()


def test_pinocchio_and_mujoco_agree_on_tcp_pose_and_jacobian(arm, tmp_path):
    m, d = arm
    pm, pd = _pinocchio_arm(tmp_path)
    assert pm.nq == 6
    frame = pm.getFrameId("tcp_check")
    tcp = m.site(TCP_SITE).id
    jacp, jacr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
    for q in _random_q(np.random.default_rng(3), 50):
        d.qpos[:] = q
        mujoco.mj_forward(m, d)
        mujoco.mj_jacSite(m, d, jacp, jacr, tcp)
        pin.forwardKinematics(pm, pd, q)
        pin.updateFramePlacements(pm, pd)
        oMf = pd.oMf[frame]
        np.testing.assert_allclose(oMf.translation, d.site_xpos[tcp], atol=1e-9)
        np.testing.assert_allclose(oMf.rotation, d.site_xmat[tcp].reshape(3, 3), atol=1e-9)
        J = pin.computeFrameJacobian(pm, pd, q, frame, pin.LOCAL_WORLD_ALIGNED)
        np.testing.assert_allclose(J[:3], jacp, atol=1e-8)
        np.testing.assert_allclose(J[3:], jacr, atol=1e-8)


def test_joint_limits_and_speeds_come_from_dims(arm):
    m, _ = arm
    np.testing.assert_allclose(m.jnt_range[:, 0], dims.UR5_Q_MIN)
    np.testing.assert_allclose(m.jnt_range[:, 1], dims.UR5_Q_MAX)
    assert dims.UR5_Q_MAX[2] == pytest.approx(math.pi)
    assert pytest.approx(3.14) == dims.UR5_QD_MAX


def test_nearest_turns_turns_only_the_wrists_and_keeps_the_posture():
    """The last two wrists take the 2*pi-equivalent nearest the reference; shoulder and
    elbow keep theirs, and angles that need no turn come back exactly."""
    q = np.array([2.9, -0.6, -1.75, -0.52, 4.56, 1.52])
    ref = dims.UR5_UNSTOW_Q
    out = K.nearest_turns(q, ref)
    np.testing.assert_array_equal(out[[0, 1, 2, 3, 5]], q[[0, 1, 2, 3, 5]])
    assert out[4] == pytest.approx(4.56 - 2 * math.pi)
    np.testing.assert_allclose(K.tcp_pose(out), K.tcp_pose(q), atol=1e-9)


def test_nearest_turns_keeps_the_hands_pitch_not_the_first_wrist_nearest():
    """Shoulder, elbow and first wrist turn about parallel axes, and their sum pitches the
    hand: the first wrist takes the angle that keeps that sum nearest the reference's, even
    where another is nearer its own angle. From the floor to a drop posture the nearer first
    wrist turned the hand over on the way."""
    ref = np.array([-0.31, -0.41, 1.86, 0.12, 1.57, 1.26])  # sum of 1-3: 1.57
    q = np.array([-1.11, -1.49, -1.26, 4.32, 1.57, -1.11])  # sum of 1-3: 1.57
    out = K.nearest_turns(q, ref)
    assert out[3] == q[3], "its own nearest, -1.96, would pitch the hand a turn"
    assert out[1:4].sum() == pytest.approx(ref[1:4].sum(), abs=1e-2)
