"""EL-E's overhead grasp (000 section 4.4) and Jeeves' centroid approach (003 section IV) on
simple shapes whose right answers can be worked out by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from laserpick.pipeline.approach import bearing_gain, centroid_approach
from laserpick.pipeline.overhead import overhead_grasp
from laserpick.settings import ApproachSettings
from laserpick.types import Failure, Grasp

TABLE = 0.46
ARM_XY = np.array([1.14, -0.30])


def _box_points(centre, size, yaw=0.0, step=0.003) -> np.ndarray:
    """Points on the top and sides of a box standing on the table (m, `base`)."""
    sx, sy, sz = size
    xs, ys = np.arange(-sx / 2, sx / 2 + 1e-9, step), np.arange(-sy / 2, sy / 2 + 1e-9, step)
    X, Y = np.meshgrid(xs, ys)
    top = np.column_stack([X.ravel(), Y.ravel(), np.full(X.size, sz)])
    zs = np.arange(0.0, sz, step)
    sides = [
        np.column_stack([np.full(len(zs), x), np.full(len(zs), y), zs])
        for x in (-sx / 2, sx / 2)
        for y in ys
    ]
    pts = np.vstack([top, *sides])
    c, s = math.cos(yaw), math.sin(yaw)
    pts[:, :2] = pts[:, :2] @ np.array([[c, s], [-s, c]])
    return pts + [centre[0], centre[1], TABLE]


def test_a_long_thin_object_is_grasped_at_its_centroid_across_its_long_axis():
    yaw = math.radians(30)
    remote = _box_points((1.5, -0.2), (0.18, 0.045, 0.02), yaw)  # a TV remote, turned 30 deg
    g = overhead_grasp(remote, remote, TABLE, ARM_XY)
    assert isinstance(g, Grasp)
    np.testing.assert_allclose(g.position[:2], [1.5, -0.2], atol=0.006)
    long_axis = np.array([math.cos(yaw), math.sin(yaw), 0.0])
    assert abs(g.closing @ long_axis) < 0.05  # fingers close across the long axis
    np.testing.assert_allclose(g.approach, [0, 0, -1])
    assert 0.04 <= g.width <= 0.065


def test_a_wide_object_is_grasped_at_a_raised_point_near_the_arm():
    tray = _box_points((1.6, -0.2), (0.2, 0.2, 0.05))
    tray[(tray[:, 0] < 1.52) & (tray[:, 2] > TABLE + 0.049), 2] += 0.004  # a lip near the arm
    g = overhead_grasp(tray, tray, TABLE, ARM_XY)
    assert isinstance(g, Grasp)
    # The chosen point is on the raised band and on the arm's side of the centroid.
    assert g.position[0] < 1.6
    closing = g.closing[:2]
    towards = g.position[:2] - np.array([1.6, -0.2])
    assert abs(closing @ towards) / (np.linalg.norm(towards) + 1e-9) > 0.95


def test_a_neighbour_in_the_sweep_volume_blocks_the_grasp():
    can = _box_points((1.5, -0.2), (0.05, 0.05, 0.1))
    g = overhead_grasp(can, can, TABLE, ARM_XY)
    assert isinstance(g, Grasp)
    # A tall box standing right where a finger comes down.
    finger_spot = g.position[:2] + g.closing[:2] * 0.05
    wall = _box_points(finger_spot, (0.02, 0.02, 0.2))
    blocked = overhead_grasp(can, np.vstack([can, wall]), TABLE, ARM_XY)
    assert isinstance(blocked, Failure) and blocked.kind == "detect_grasp"
    assert "way down" in blocked.message


def test_gain_schedule_changes_at_20_and_7_cm():
    s = ApproachSettings()
    assert bearing_gain(0.5, s) == s.kw_far
    assert bearing_gain(0.15, s) == s.kw_mid
    assert bearing_gain(0.05, s) == 0.0
    assert s.kw_mid < s.kw_far


def test_centroid_approach_drives_toward_the_spot_and_stops():
    s = ApproachSettings()
    spot = np.array(s.grasp_spot)
    cmd = centroid_approach(spot + [0.5, 0.2], s)
    assert cmd.v == pytest.approx(min(s.kv * math.hypot(0.5, 0.2), s.v_max))
    assert cmd.w > 0  # target to the left: turn left
    near = centroid_approach(spot + [0.05, 0.04], s)
    assert near.w == 0.0 and near.v > 0  # no bearing correction inside 7 cm
    assert centroid_approach(spot + [0.01, 0.0], s).done
    back = centroid_approach(spot + [-0.3, 0.0], s)
    assert back.v < 0 and back.w == 0.0


def test_closed_loop_on_a_unicycle_reaches_the_target():
    s = ApproachSettings()
    pose = np.array([0.0, 0.0, 0.0])  # the scooter in world
    target_world = np.array([2.3, 0.4])
    dt = 0.05
    for _ in range(600):
        c, sn = math.cos(pose[2]), math.sin(pose[2])
        rel = target_world - pose[:2]
        cmd = centroid_approach(np.array([c * rel[0] + sn * rel[1], -sn * rel[0] + c * rel[1]]), s)
        if cmd.done:
            break
        pose += [cmd.v * c * dt, cmd.v * sn * dt, cmd.w * dt]
    assert cmd.done


def test_the_overhead_grasp_of_a_pill_beside_a_phone_closes_on_the_pill(tmp_path):
    """An 8 mm pill goes with 004's 1.5 cm plane removal, and the segmentation falls back on
    its 10 cm ball about the mark, less the phone's cluster at its edge: whole, the ball held
    part of the phone, and the overhead grasp closed between them (in `surfaces`, on the
    phone, 9 of 12 pills). As `surfaces` sets out EL-E's second table, seen from where the
    user parks."""
    from laserpick.bench.picking import BENCH
    from laserpick.bench.protocols import Options, scripted_operator
    from laserpick.robot.sim.scenes import load_scene
    from laserpick.server.session import TaskState

    scene = tmp_path / "pill.yaml"
    scene.write_text(
        "name: pill\nscooter: {x: 0.0, y: 0.0, yaw_deg: 0.0}\n"
        "surfaces:\n"
        "  - {name: t, kind: table, xy: [1.75, -0.15], size: [0.6, 0.9], height: 0.698}\n"
        "objects:\n"
        "  - {name: phone, model: cordless_phone, on: t, xy: [1.57, -0.27], yaw_deg: 30}\n"
        "  - {name: pill, model: pill, on: t, xy: [1.60, -0.05], yaw_deg: 45}\n"
    )
    with scripted_operator(load_scene(str(scene)), 0, 1, Options(tremor_deg=0.0)) as op:
        s = op.session
        s.set_mode(BENCH, strategy="overhead")
        assert op.mark(op.new_attempt("pill", "auto", "overhead"))
        assert s.state == TaskState.GRASPS_READY
        grasp = np.asarray(s.status()["current"]["position"])
        assert op.referee.object_at(grasp) == "pill"
