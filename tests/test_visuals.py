"""The robot's visual description (`description.visuals`) is the simulator's robot: every
visible geom of the scooter, the arm and the gripper is a shape of the same name, kind,
size, pose and colour, and `part_poses` puts each part where MuJoCo's kinematics puts its
body, for any joint state and gripper opening."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from laserpick.description import dims
from laserpick.description.visuals import PARTS, finger, part_poses
from laserpick.robot.sim.model import ARM_JOINTS, FINGER_JOINTS, build_arm_model, build_sim_model
from laserpick.transforms import invert, make_transform, matrix_from_quat

KIND = {
    "box": mujoco.mjtGeom.mjGEOM_BOX,
    "sphere": mujoco.mjtGeom.mjGEOM_SPHERE,
    "capsule": mujoco.mjtGeom.mjGEOM_CAPSULE,
    "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
}


@pytest.fixture(scope="module")
def model() -> mujoco.MjModel:
    return build_sim_model(None)


def test_every_visible_robot_geom_is_a_shape_of_the_description(model) -> None:
    described = set()
    for part in PARTS:
        for shape in part.shapes:
            g = model.geom(shape.name).id
            described.add(g)
            assert model.geom_bodyid[g] == model.body(part.name).id, shape.name
            assert model.geom_type[g] == KIND[shape.kind], shape.name
            np.testing.assert_allclose(model.geom_size[g][: len(shape.size)], shape.size)
            np.testing.assert_allclose(model.geom_pos[g], shape.pose[:3, 3], atol=1e-12)
            R = matrix_from_quat(model.geom_quat[g])
            if shape.kind == "box":
                np.testing.assert_allclose(R, shape.pose[:3, :3], atol=1e-12)
            else:  # round about their axis: only the axis matters
                assert abs(R[:, 2] @ shape.pose[:3, 2]) == pytest.approx(1.0), shape.name
            np.testing.assert_allclose(model.geom_rgba[g], shape.rgba)
    scooter = model.body("scooter").id
    visible = [
        g
        for g in range(model.ngeom)
        if model.body_rootid[model.geom_bodyid[g]] == scooter and model.geom_group[g] <= 3
    ]
    missing = [model.geom(g).name for g in visible if g not in described]
    assert not missing, f"robot geoms the description does not draw: {missing}"


def test_part_poses_are_the_simulator_s_body_poses(model) -> None:
    data = mujoco.MjData(model)
    rng = np.random.default_rng(0)
    scooter = model.body("scooter").id
    for _ in range(5):
        q = rng.uniform(-3.0, 3.0, 6)
        width = rng.uniform(0.0, dims.GRIPPER_STROKE)
        data.qpos[:] = 0.0
        for name, angle in zip(ARM_JOINTS, q, strict=True):
            data.qpos[model.jnt_qposadr[model.joint(name).id]] = angle
        for name in FINGER_JOINTS:
            data.qpos[model.jnt_qposadr[model.joint(name).id]] = width / 2
        data.qpos[model.jnt_qposadr[model.joint("base_x").id]] = 0.3
        data.qpos[model.jnt_qposadr[model.joint("base_yaw").id]] = 0.5
        mujoco.mj_kinematics(model, data)

        def pose(body: int) -> np.ndarray:
            return make_transform(matrix_from_quat(data.xquat[body]), data.xpos[body])

        T_world_base = pose(scooter)
        for part, T in zip(PARTS, part_poses(q, width), strict=True):
            in_base = invert(T_world_base) @ pose(model.body(part.name).id)
            np.testing.assert_allclose(in_base, T, atol=1e-9, err_msg=part.name)


def test_the_arm_model_holds_the_described_fingers_fully_open() -> None:
    model = build_arm_model()
    for side in ("left", "right"):
        part = finger(side, travel=dims.GRIPPER_STROKE / 2)
        for shape in part.shapes:
            g = model.geom(shape.name).id
            assert model.geom_bodyid[g] == model.body(part.name).id, shape.name
            np.testing.assert_array_equal(model.geom_pos[g], shape.pose[:3, 3])
            np.testing.assert_array_equal(model.geom_size[g], shape.size)
    gap = model.geom("gripper/pad_left").pos[1] - model.geom("gripper/pad_right").pos[1]
    assert gap - dims.GRIPPER_PAD_THICKNESS == pytest.approx(dims.GRIPPER_STROKE)
