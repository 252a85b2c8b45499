"""The arm's collision model (004 section 7): its spheres and body frames against the
simulated links, the keep-out boxes, the cloud's obstacles and what the hand carries."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from arm_poses import EMPTY, top_grasp
from arm_setups import box_points

from laserpick.description import dims
from laserpick.description.kinematics import ik_tcp, tcp_pose
from laserpick.description.shapes import FLOOR_CLEARANCE, KEEPOUT_BOXES, body_frames
from laserpick.pipeline.collision import (
    SEGMENT_COARSE,
    SPHERES,
    CollisionChecker,
    carried_shape,
    object_middle,
    self_filter,
    sphere_centres,
    surface_front,
    thin,
)
from laserpick.pipeline.collision.arm_spheres import HAND_BODY
from laserpick.pipeline.collision.carried import (
    PAYLOAD_CLEAR_OF_BODY,
    PAYLOAD_POINT_RADIUS,
    held_points,
    off_upper_links,
)
from laserpick.pipeline.collision.keepout import BOX_CHECKS, box_contacts, box_gaps
from laserpick.robot.sim.model import ModelInfo, build_sim_model


def test_body_frames_match_the_simulated_links():
    m = build_sim_model(None)
    d = mujoco.MjData(m)
    info = ModelInfo.of(m)
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = rng.uniform(-3, 3, 6)
        d.qpos[info.arm_qpos] = q
        mujoco.mj_kinematics(m, d)
        F = body_frames(q)[0]
        for i in range(6):
            b = m.body(f"ur5/link{i + 1}").id
            assert np.allclose(d.xpos[b], F[i, :3, 3], atol=1e-9)
            assert np.allclose(d.xmat[b].reshape(3, 3), F[i, :3, :3], atol=1e-9)
        # The sphere model covers each MuJoCo capsule's end points, joint housings included.
        centres = sphere_centres(body_frames(q))[0]
        for g in range(m.ngeom):
            name = m.geom(g).name
            if not name.startswith("ur5/link"):
                continue
            radius, half = m.geom_size[g, :2]
            if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_SPHERE:  # a joint housing
                half = 0.0
            else:
                assert m.geom_type[g] == mujoco.mjtGeom.mjGEOM_CAPSULE, name
            axis = d.geom_xmat[g].reshape(3, 3)[:, 2]
            for end in (d.geom_xpos[g] + half * axis, d.geom_xpos[g] - half * axis):
                gap = np.linalg.norm(centres - end, axis=1) - SPHERES.radius
                assert gap.min() < -radius + 1e-6, name


def test_the_simulated_gripper_is_the_hand_grasp_detection_tests():
    """`dims.GRIPPER_HAND`, the boxes grasp detection tests, is the simulated gripper: its
    fingers' plates and pads (half extents along the hand axis, the closing axis and the
    approach), its housing across and along the hand axis, and no longer than the palm."""
    m = build_sim_model(None)
    hand = dims.GRIPPER_HAND
    for side in ("left", "right"):
        finger = m.geom_size[m.geom(f"gripper/finger_{side}").id]
        pad = m.geom_size[m.geom(f"gripper/pad_{side}").id]
        assert np.allclose(
            finger, [hand.finger_width / 2, hand.finger_thickness / 2, hand.finger_length / 2]
        )
        assert np.allclose(pad, [hand.pad_width / 2, hand.pad_thickness / 2, hand.pad_depth / 2])
    housing = m.geom_size[m.geom("gripper/housing").id]
    assert np.allclose(housing[:2], [hand.palm_depth / 2, hand.palm_width / 2])
    assert 2 * housing[2] <= hand.palm_length
    finger_joint = m.joint("finger_left")
    assert np.isclose(2 * m.jnt_range[finger_joint.id][1], hand.width_max)


def test_keepout_boxes_hold_every_part_of_the_scooter_the_arm_can_reach():
    # What the planner avoids must hold what the simulator collides with. Points over every
    # part from the posts up (and over the tiller and the basket) lie in some box: a box's
    # corners and a grid between them (a cylinder's box), a capsule's surface.
    m = build_sim_model(None)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    lo, hi = np.array([b.lo for b in KEEPOUT_BOXES]), np.array([b.hi for b in KEEPOUT_BOXES])
    turn = np.array([b.turn for b in KEEPOUT_BOXES])
    parts = ("sensor_", "post_", "projector", "tiller", "handlebar", "basket_", "arm_pedestal")
    steps = np.linspace(-1, 1, 5)
    cube = np.stack(np.meshgrid(steps, steps, steps), -1).reshape(-1, 3)
    outward = cube[np.linalg.norm(cube, axis=1) > 0]
    ball = outward / np.linalg.norm(outward, axis=1)[:, None]
    checked = 0
    for g in range(m.ngeom):
        name = m.geom(g).name.removeprefix("scooter/")
        if not name.startswith(parts):
            continue
        R, size = d.geom_xmat[g].reshape(3, 3), m.geom_size[g]
        if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX:
            local = cube * size
        elif m.geom_type[g] == mujoco.mjtGeom.mjGEOM_CYLINDER:
            local = cube * [size[0], size[0], size[1]]  # the box around it
        else:
            assert m.geom_type[g] == mujoco.mjtGeom.mjGEOM_CAPSULE, name
            axis = steps[:, None] * np.array([0.0, 0.0, size[1]])
            local = (axis[:, None] + size[0] * ball[None]).reshape(-1, 3)
        points = local @ R.T + d.geom_xpos[g]  # m, `base`
        local = np.einsum("pj,kji->pki", points, turn)  # in each box's frame
        inside = np.all((local >= lo - 1e-6) & (local <= hi + 1e-6), axis=2)
        assert inside.any(axis=1).all(), f"{name}: {points[~inside.any(axis=1)][:3]}"
        checked += 1
    assert checked == 17  # five sensors, two posts, projector and bracket, tiller, bar,


def test_stowed_and_ready_poses_are_clear_and_the_checker_sees_what_it_should():
    free = CollisionChecker(EMPTY)
    assert free.clearance_ok(np.stack([dims.UR5_HOME_Q, dims.UR5_READY_Q])).all()
    # A point where the wrist is makes the ready pose collide, and is named "cloud".
    wrist = tcp_pose(dims.UR5_READY_Q)[:3, 3] + [0, 0, 0.15]
    blocked = CollisionChecker(wrist[None], voxel=0.0)
    assert not blocked.clearance_ok(dims.UR5_READY_Q)[0]
    assert blocked.what_hits(dims.UR5_READY_Q) == ["cloud"]
    # And it is the point the posture comes too near; one 30 cm farther up is not.
    far = wrist + [0, 0, 0.30]
    both = CollisionChecker(np.stack([wrist, far]), voxel=0.0)
    assert np.allclose(both.points_near(dims.UR5_READY_Q), [wrist])
    assert len(free.points_near(dims.UR5_READY_Q)) == 0
    # The TCP through the floor, and into the rider's seat.
    for T, what in ((top_grasp(1.5, -0.3, 0.0), "floor"), (top_grasp(0.6, -0.1, 0.8), "rider")):
        Q = ik_tcp(T, dims.UR5_READY_Q)
        assert len(Q)
        assert not free.clearance_ok(Q).any()
        assert what in free.what_hits(Q[0])


def test_the_clearance_a_posture_keeps_is_found_to_within_its_steps():
    """A point 4 mm below the wrist's lowest sphere: the ready pose keeps 4 mm, less than
    the 1 cm margin; clear of it, the margin; touching it, nothing."""
    centres = sphere_centres(body_frames(dims.UR5_READY_Q))[0]
    wrist = ~SPHERES.hand & (SPHERES.body >= 3)
    lowest = np.flatnonzero(wrist)[np.argmin(centres[wrist, 2] - SPHERES.radius[wrist])]
    below = centres[lowest] - [0.0, 0.0, SPHERES.radius[lowest] + 0.004]
    checker = CollisionChecker(below[None], voxel=0.0, margin=0.01)
    assert not checker.clearance_ok(dims.UR5_READY_Q, hand=False)[0]
    kept = checker.clearance_kept(dims.UR5_READY_Q, hand=False)
    assert kept == pytest.approx(0.004, abs=0.01 / 2**8)
    assert checker.clearance_ok(dims.UR5_READY_Q, hand=False, margin=kept)[0]
    far = CollisionChecker(below[None] - [0.0, 0.0, 0.05], voxel=0.0, margin=0.01)
    assert far.clearance_kept(dims.UR5_READY_Q, hand=False) == 0.01
    inside = CollisionChecker(below[None] + [0.0, 0.0, 0.01], voxel=0.0, margin=0.01)
    assert inside.clearance_kept(dims.UR5_READY_Q, hand=False) is None


def test_the_basket_is_kept_out_of_only_where_the_steering_column_passes_through_it():
    """Inside the basket (a 1 cm grid, 5 mm in from its walls, above its floor's keep-out),
    only the steering column's corner is kept out of: as one box round the tiller and the
    handlebars, the keep-out took the back 6 cm of the basket's 20, and a cereal box in the
    hand fitted nowhere inside. Over the rim, the handlebars' box still keeps the arm 12 cm
    ahead of them, where the rider's hands are."""
    lo = dims.BASKET_CENTER - dims.BASKET_INNER / 2 + 0.005
    hi = dims.BASKET_CENTER + dims.BASKET_INNER / 2 - 0.005
    grid = np.mgrid[lo[0] : hi[0] : 0.01, lo[1] : hi[1] : 0.01, lo[2] + 0.02 : hi[2] : 0.01]
    points = grid.reshape(3, -1).T
    inside = box_gaps(points) == 0
    names = [b.name for b in KEEPOUT_BOXES]
    kept = points[inside.any(axis=1)]
    assert set(np.array(names)[inside.any(axis=0)]) == {"tiller_column"}
    column_front = dims.TILLER_X + dims.TILLER_FOOT_AHEAD + dims.TILLER_RADIUS + 0.01
    assert kept[:, 0].max() < column_front
    assert np.abs(kept[:, 1]).max() <= dims.TILLER_RADIUS + 0.01
    assert len(kept) < 0.03 * len(points)
    over_rim = np.array([dims.TILLER_X + 0.085, 0.2, dims.BASKET_CENTER[2] + 0.1])
    assert box_gaps(over_rim)[names.index("tiller_over_basket")] == 0


def test_keepout_boxes_are_well_formed():
    for b in KEEPOUT_BOXES:
        assert np.all(np.array(b.lo) < np.array(b.hi)), b.name


def test_thin_keeps_one_point_per_voxel():
    rng = np.random.default_rng(0)
    pts = rng.uniform(0, 0.2, (5000, 3))
    keep = thin(pts, 0.05)
    cells = np.floor(pts.astype(np.float32) / np.float32(0.05)).astype(int)
    assert keep.sum() == len(np.unique(cells, axis=0))
    assert len(np.unique(cells[keep], axis=0)) == keep.sum()


def test_carried_shape_fills_in_the_unseen_back_of_a_can():
    """A can seen from the front (-x) only: its front half-shell and its whole top. The
    carried shape must reach the back of the can, 3.3 cm behind its axis, as the real can does."""
    axis, r, h = np.array([1.5, -0.2]), 0.033, 0.12
    t = np.linspace(np.pi / 2, 3 * np.pi / 2, 40)  # the half facing the cameras (-x)
    z = np.linspace(0.46, 0.46 + h, 25)
    tt, zz = np.meshgrid(t, z)
    shell = np.c_[axis[0] + r * np.cos(tt.ravel()), axis[1] + r * np.sin(tt.ravel()), zz.ravel()]
    rho, phi = np.meshgrid(np.linspace(0, r, 6), np.linspace(0, 2 * np.pi, 30))
    top = np.c_[
        axis[0] + (rho * np.cos(phi)).ravel(),
        axis[1] + (rho * np.sin(phi)).ravel(),
        np.full(rho.size, 0.46 + h),
    ]
    seen = np.vstack([shell, top])
    assert seen[:, 0].max() == pytest.approx(axis[0] + r, abs=1e-3)  # only the top reaches back
    carried = carried_shape(seen)
    low = carried[carried[:, 2] < 0.5]  # below the top, where the seen shell is half a can
    assert low[:, 0].max() > axis[0] + 0.8 * r
    assert low[:, 0].min() < axis[0] - 0.8 * r
    assert len(carried) < len(seen)  # thinned to one point per 2 cm voxel
    assert len(carried_shape(np.zeros((0, 3)))) == 0
    # Seen only above a table's edge: the top 4 cm. Filled down to the table at 0.46 m.
    upper = seen[seen[:, 2] > 0.46 + h - 0.04]
    assert carried_shape(upper)[:, 2].min() > 0.53
    filled = carried_shape(upper, support=0.46)
    assert filled[:, 2].min() < 0.46 + 0.02
    assert np.all(np.abs(filled[:, :2] - axis).max(axis=1) < r + 0.03)  # within the footprint


def test_the_middle_of_a_box_whose_top_was_seen_in_part_is_the_middle_of_its_seen_width():
    """A 6 x 19 x 25 cm box standing on the 100 cm shelf, seen from the front (-x): its front
    face whole up to 5 cm under its top; above that, and of its top, only the 15 cm nearest
    its +y end, as the cameras see the kitchen's cereal box. The half turn about the middle
    of that top carries the box on past its +y end, so the carried shape's middle lies 2 cm
    off the box's. The middle a place turns it about must be the box's own, within 5 mm."""
    middle = np.array([1.60, -0.31])
    lo, hi = middle - [0.03, 0.095], middle + [0.03, 0.095]
    y, z = np.meshgrid(np.arange(lo[1], hi[1] + 1e-9, 0.005), np.arange(1.0, 1.25 + 1e-9, 0.005))
    y, z = y.ravel(), z.ravel()
    keep = (z < 1.20) | (y > hi[1] - 0.15)
    front = np.c_[np.full(keep.sum(), lo[0]), y[keep], z[keep]]
    x, y = np.meshgrid(np.arange(lo[0], hi[0] + 1e-9, 0.005), np.arange(hi[1] - 0.15, hi[1], 0.005))
    seen = np.vstack([front, np.c_[x.ravel(), y.ravel(), np.full(x.size, 1.25)]])
    carried = carried_shape(seen, support=1.0)
    carried_middle = (carried.min(axis=0) + carried.max(axis=0)) / 2
    assert abs(carried_middle[1] - middle[1]) > 0.015  # the half turn's guess is off
    found = object_middle(seen, carried)
    assert found[:2] == pytest.approx(middle, abs=0.005)
    assert found[2] == pytest.approx(1.125, abs=0.02)
    # Seen whole, top and all, it is the carried shape's middle, and the box's.
    x, y = np.meshgrid(np.arange(lo[0], hi[0] + 1e-9, 0.005), np.arange(lo[1], hi[1], 0.005))
    whole = np.vstack([front, np.c_[x.ravel(), y.ravel(), np.full(x.size, 1.25)]])
    carried = carried_shape(whole, support=1.0)
    found = object_middle(whole, carried)
    assert found == pytest.approx((carried.min(axis=0) + carried.max(axis=0)) / 2, abs=2e-3)
    assert found[:2] == pytest.approx(middle, abs=0.005)


def test_surface_front_walls_in_a_counter_front_the_view_cut_off():
    """An 87 cm counter whose front stands at x = 1.40 m: the cameras saw its top to
    y = -0.8 m, but right of y = -0.5 m the view's edge cuts the top on a slant (the top's
    nearest seen point there lies up to 30 cm deeper) and the front below it is not seen.
    The wall must stand at the nearest seen edge across the whole seen width, from just
    under the top down to the floor's clearance, where a stow's upper arm would meet the
    unseen front."""
    xs, ys = np.meshgrid(np.arange(1.40, 2.0, 0.01), np.arange(-0.8, 0.38, 0.01))
    top = np.c_[xs.ravel(), ys.ravel(), np.full(xs.size, 0.87)]
    top = top[top[:, 0] >= 1.40 + np.maximum(0.0, -0.5 - top[:, 1])]  # the slanted view edge
    fy, fz = np.meshgrid(np.arange(-0.5, 0.38, 0.01), np.arange(0.6, 0.86, 0.01))
    face = np.c_[np.full(fy.size, 1.40), fy.ravel(), fz.ravel()]
    mug = np.c_[np.full(10, 1.7), np.full(10, 0.1), np.linspace(0.87, 0.97, 10)]
    cloud = np.vstack([top, face, mug])
    wall = surface_front(cloud, 0.87, 0.015)
    assert np.allclose(wall[:, 0], 1.40)
    assert wall[:, 1].min() == pytest.approx(top[:, 1].min(), abs=1e-9)
    assert top[:, 1].max() <= wall[:, 1].max() <= top[:, 1].max() + 0.02 + 1e-9
    assert np.diff(np.unique(wall[:, 1])).max() <= 0.02 + 1e-9
    assert wall[:, 2].max() < 0.87 - 0.015  # below the top, which the hand may set things on
    assert wall[:, 2].min() >= FLOOR_CLEARANCE
    upper_arm = np.array([1.36, -0.58, 0.84])  # where a stow's upper arm meets the counter
    assert np.linalg.norm(cloud - upper_arm, axis=1).min() > 0.06  # its 6 cm sphere: clear
    assert np.linalg.norm(wall - upper_arm, axis=1).min() < 0.06  # not of the wall
    assert len(surface_front(cloud, 0.0, 0.015)) == 0  # the floor has no front
    assert len(surface_front(cloud, 0.5, 0.015)) == 0  # nothing seen at that height


def test_self_filter_removes_the_arm_and_keeps_the_rest():
    q = dims.UR5_READY_Q
    centres = sphere_centres(body_frames(q))[0]
    on_arm = centres + np.random.default_rng(1).normal(0, 0.01, centres.shape)
    away = np.array([[1.5, 0.2, 0.5], [1.8, -0.3, 0.47]])
    keep = self_filter(np.vstack([on_arm, away]), q)
    assert not keep[: len(on_arm)].any()
    assert keep[len(on_arm) :].all()


def test_segment_check_finds_an_obstacle_between_its_coarse_samples():
    """The coarse-first segment check still checks every configuration: a post the hand
    meets only between two coarse samples blocks the segment."""
    q0 = ik_tcp(top_grasp(1.6, -0.5, 0.65), dims.UR5_READY_Q)[0]
    q1 = ik_tcp(top_grasp(1.6, 0.1, 0.65), dims.UR5_READY_Q)[0]
    n = math.ceil(float(np.max(np.abs(q1 - q0))) / 0.03) + 1
    Q = np.linspace(q0, q1, n)
    fine = SEGMENT_COARSE // 2  # midway between the first two coarse samples
    checker = CollisionChecker(tcp_pose(Q[fine])[None, :3, 3], voxel=0.0, margin=0.0)
    coarse = np.r_[np.arange(0, n, SEGMENT_COARSE), n - 1]
    assert checker.clearance_ok(Q[coarse]).all()  # no coarse sample touches the post
    assert not checker.clearance_ok(Q[fine])[0]
    assert not checker.segment_ok(q0, q1)


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_checker_ignores_non_finite_points(bad):
    pts = np.array([[1.5, -0.3, bad], [5.0, 5.0, 5.0]])
    assert len(CollisionChecker(pts).points) == 0


def test_the_broad_phases_change_no_verdict():
    """The keep-out boxes and the upper links are first tested against a ball about each
    body's spheres (and the held object's points): the verdicts are those of measuring
    every sphere and every point, at configurations all over the joint space, some touching
    and some clear, at no margin, the usual one and a wider one."""
    rng = np.random.default_rng(7)
    Q = rng.uniform(
        np.maximum(dims.UR5_Q_MIN, -math.pi), np.minimum(dims.UR5_Q_MAX, math.pi), (3000, 6)
    )
    payload = box_points((0.19, 0.06, 0.24), step=0.03)  # a cereal box held at its top
    frames = body_frames(Q)
    held = held_points(frames, payload)
    centres = np.concatenate([sphere_centres(frames), held], axis=1)
    radius = np.append(SPHERES.radius, np.full(len(payload), PAYLOAD_POINT_RADIUS))
    body = np.append(SPHERES.body, np.full(len(payload), HAND_BODY))
    upper = SPHERES.body <= PAYLOAD_CLEAR_OF_BODY
    links = sphere_centres(frames)[:, upper]
    for margin in (0.0, 0.01, 0.03):
        reach = radius + margin
        every = (box_gaps(centres) < reach[:, None]) & BOX_CHECKS[body]
        assert 0 < every.any(axis=(1, 2)).sum() < len(Q)
        assert np.array_equal(box_contacts(centres, reach, body), every)
        gap = np.linalg.norm(held[:, :, None] - links[:, None], axis=-1)
        apart = ~(gap < SPHERES.radius[upper] + PAYLOAD_POINT_RADIUS + margin).any(axis=(1, 2))
        assert 0 < apart.sum() < len(Q)
        assert np.array_equal(off_upper_links(sphere_centres(frames), held, margin), apart)


def test_the_stopping_check_and_the_cloud_balls_change_no_verdict():
    """`all_clear` stops at the first test that finds a configuration blocked, and the
    cloud is asked about a held object's points only where their ball comes near it: over
    segments all over the joint space, with and without the hand, carrying a box or not,
    the verdicts are those of measuring every sphere and every point against every point of
    the cloud, the floor and the boxes."""
    rng = np.random.default_rng(11)
    xs, ys = np.meshgrid(np.linspace(0.9, 1.8, 40), np.linspace(-0.8, 0.8, 60))
    table = np.column_stack([xs.ravel(), ys.ravel(), np.full(xs.size, 0.73)])
    checker = CollisionChecker(table, voxel=0.0)
    payload = box_points((0.19, 0.06, 0.24), step=0.03)
    lo, hi = np.maximum(dims.UR5_Q_MIN, -math.pi), np.minimum(dims.UR5_Q_MAX, math.pi)
    verdicts = set()
    for k in range(400):
        Q = np.linspace(*rng.uniform(lo, hi, (2, 6)), 3)
        kw = {"hand": k % 2 == 0, "payload": payload if k % 3 == 0 else None}
        clear = checker.clearance_ok(Q, **kw)
        assert checker.all_clear(Q, **kw) == clear.all()
        frames = body_frames(Q)
        keep = np.ones(len(SPHERES.radius), bool) if kw["hand"] else ~SPHERES.hand
        centres, radius = sphere_centres(frames)[:, keep], SPHERES.radius[keep]
        body, apart = SPHERES.body[keep], np.ones(len(Q), bool)
        if kw["payload"] is not None:
            held = held_points(frames, payload)
            apart = off_upper_links(sphere_centres(frames), held, checker.margin)
            centres = np.concatenate([centres, held], axis=1)
            radius = np.append(radius, np.full(len(payload), PAYLOAD_POINT_RADIUS))
            body = np.append(body, np.full(len(payload), HAND_BODY))
        reach = radius + checker.margin
        gap = np.linalg.norm(centres[:, :, None] - checker.points[None, None], axis=-1)
        hit = (gap.min(axis=2) < reach).any(axis=1)
        hit |= (centres[..., 2] < radius + checker.floor_clearance).any(axis=1)
        hit |= ((box_gaps(centres) < reach[:, None]) & BOX_CHECKS[body]).any(axis=(1, 2))
        assert np.array_equal(clear, apart & ~hit)
        verdicts |= {tuple(clear)}
    assert len(verdicts) > 4  # clear, blocked and mixed segments were met
