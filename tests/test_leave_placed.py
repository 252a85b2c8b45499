"""Leaving a placed object: the open hand is drawn back the way it holds it, lowered off a
lip, and eased sideways off what still leans on a pad."""

from __future__ import annotations

import numpy as np
import pytest
from arm_setups import (
    BEHAVIOUR,
    DATA,
    RAIL_TOP,
    SETTINGS,
    TABLE_TOP,
    hand_at,
    isolation_robot,
    post_behind,
    scene_robot,
    side_pose,
    top_down,
)

from laserpick.behaviours import Behaviours
from laserpick.bench.referee import Referee
from laserpick.description import dims
from laserpick.description.kinematics import ik_tcp, tcp_pose
from laserpick.description.shapes import body_frames
from laserpick.pipeline.collision import SPHERES, CollisionChecker, sphere_centres
from laserpick.pipeline.lines import cartesian_line
from laserpick.pipeline.motion_limits import timed
from laserpick.transforms import rotx
from laserpick.types import Failure, Trajectory


@pytest.fixture
def robot():
    yield from isolation_robot()


def recorded_moves(b: Behaviours) -> list[str]:
    """The list to which each motion `b` runs from now on adds what it is ("drawing
    back", ...)."""
    moves: list[str] = []
    run = b.run

    def record(traj: Trajectory, what: str) -> Failure | None:
        moves.append(what)
        return run(traj, what)

    b.run = record  # type: ignore[method-assign]
    return moves


def test_after_a_place_the_open_hand_leaves_the_object_the_way_it_holds_it(robot):
    """Drawn back off the object along the approach: from the side, straight up, the
    fingers would stay about a tall box's top. From the side, with the way back clear, the
    open hand is first lowered `leave_drop`, so that a pad under a lip of the object leaves
    it (a pill bottle's cap). From above, or where the way back is not clear, straight up to the
    pose above the place, the way it came down; neither is lowered first."""
    b = Behaviours(robot)
    moves = recorded_moves(b)
    free = CollisionChecker(np.zeros((0, 3)))
    q_side, above = hand_at(b, side_pose(1.70, -0.30, 0.80))
    moves.clear()
    assert b.leave_object(above, free) is None
    assert moves == ["freeing the fingers", "drawing back"]
    end = tcp_pose(robot.joint_state().q)[:3, 3]
    np.testing.assert_allclose(end[:2], [1.60, -0.30], atol=0.005)
    drop = BEHAVIOUR.leave_drop
    assert 0.80 - drop - 0.001 < end[2] < 0.80 - drop / 2  # the servos lag
    # Where the way back is not clear: up instead.
    hand_at(b, side_pose(1.70, -0.30, 0.80))
    moves.clear()
    assert b.leave_object(above, post_behind(q_side)) is None
    assert moves == ["rising from the object"]
    np.testing.assert_allclose(tcp_pose(robot.joint_state().q)[:3, 3], above[:3, 3], atol=0.005)
    _, above = hand_at(b, top_down(1.6, -0.3, 0.8))  # its approach is straight down
    moves.clear()
    assert b.leave_object(above, free) is None
    assert moves == ["drawing back"]
    np.testing.assert_allclose(tcp_pose(robot.joint_state().q)[:3, 3], above[:3, 3], atol=0.005)
    # From 45 deg above the side: back along the approach itself, up and back, not level
    # (drawn back level, the fingers drag a plush toy's head over), and not lowered.
    oblique = np.eye(4)
    approach = np.array([np.sqrt(0.5), 0.0, -np.sqrt(0.5)])
    across = np.array([0.0, 1.0, 0.0])
    oblique[:3, :3] = np.column_stack([np.cross(across, approach), across, approach])
    oblique[:3, 3] = [1.6, -0.3, 0.8]
    _, above = hand_at(b, oblique)
    moves.clear()
    assert b.leave_object(above, free) is None
    assert moves == ["drawing back"]
    moved = tcp_pose(robot.joint_state().q)[:3, 3] - oblique[:3, 3]
    assert np.linalg.norm(moved) > 0.045  # 10 cm, or 5 where the whole way is not clear
    np.testing.assert_allclose(moved / np.linalg.norm(moved), -approach, atol=0.05)


def test_an_open_hand_lowered_onto_something_goes_back_up_before_it_draws_back():
    """Lowered `leave_drop` from the side, open fingers can come down on a jar's shoulder,
    and drawn back from there, drag it (196 N, a protective stop). Here the open hand
    stands level 2 mm over a table top: lowered, it meets the table, stops, goes back up
    to where it stood, and is drawn back from there, level."""
    with scene_robot(str(DATA / "table_top.yaml")) as robot:
        b = Behaviours(robot)
        run = b.run  # the setup's own moves, not recorded
        moves = recorded_moves(b)
        top = np.mgrid[1.30:1.90:0.02, -0.65:0.35:0.02].reshape(2, -1).T
        table = CollisionChecker(np.c_[top, np.full(len(top), TABLE_TOP)], margin=0.0)
        high = side_pose(1.70, -0.30, TABLE_TOP + 0.06)
        q = next(q for q in ik_tcp(high, dims.UR5_READY_Q) if table.clearance_ok(q)[0])
        assert b.go_to(q, table, "test").ok
        s = b.settings.motion
        # Down onto the table until it is felt, then 2 mm back up off it.
        low = high.copy()
        low[2, 3] = TABLE_TOP
        path = cartesian_line(robot.joint_state().q, low, s.cartesian_step / 5)
        assert path is not None
        felt = b.descend(path, 0.02, "test")
        assert felt is not None and "unexpected contact" in felt.message
        over = tcp_pose(robot.joint_state().q)
        over[2, 3] += 0.002
        up = cartesian_line(robot.joint_state().q, over, s.cartesian_step / 5)
        assert up is not None
        assert run(timed(up, s, tcp_speed=0.02), "test") is None
        robot.sleep(0.3)
        start = tcp_pose(robot.joint_state().q)[:3, 3]
        above = tcp_pose(robot.joint_state().q)
        above[2, 3] += 0.10
        moves.clear()
        assert b.leave_object(above, CollisionChecker(np.zeros((0, 3)))) is None
        assert moves == ["freeing the fingers", "rising off what the fingers met", "drawing back"]
        moved = tcp_pose(robot.joint_state().q)[:3, 3] - start
        np.testing.assert_allclose(moved, [-0.10, 0.0, 0.0], atol=0.0025)


@pytest.mark.parametrize("lean", [0.026, -0.026], ids=["first-way-in", "first-way-out"])
def test_an_open_hand_a_light_object_leans_on_is_eased_off_it_before_it_rises(lean: float):
    """Let go on the floor, a pill bottle can spring onto one open pad and lean on it (0.4 N,
    well under GRIPPER_HOLD_FORCE) with its cap's lip over the pad: the hand, risen
    straight up, takes it 10 cm up. An open
    hand whose pads still feel something is lowered 5 mm, which here leaves the pads
    feeling nothing while the bottle still leans over one, and then eased sideways along
    its closing axis. The gripper feels only the pads' sum, not which pad, so the first
    way it tries may push into the bottle: the guard stops it there, and the other way
    frees the pad."""
    with scene_robot(str(DATA / "pill_lean.yaml")) as robot:
        referee = Referee(robot)
        bottle = referee.position("pill_bottle_1")
        b = Behaviours(robot)
        s = b.settings.motion
        # Level from the side, the pads' top edges 2 mm under the cap's lip (7 cm up); the
        # wrist stays in front of the table's edge, 6 cm before the bottle's middle.
        z = bottle[2] + 0.057
        top = np.mgrid[1.65:2.25:0.02, -0.65:0.35:0.02].reshape(2, -1).T
        table = CollisionChecker(np.c_[top, np.full(len(top), bottle[2])], margin=0.0)
        out_front = side_pose(bottle[0] - 0.10, bottle[1], z)
        q = next(q for q in ik_tcp(out_front, dims.UR5_READY_Q) if table.clearance_ok(q)[0])
        assert b.go_to(q, table, "test").ok
        for y, speed in ((bottle[1], 0.03), (bottle[1] + lean, 0.01)):  # about it, then aside
            path = cartesian_line(robot.joint_state().q, side_pose(bottle[0], y, z))
            assert path is not None and b.run(timed(path, s, tcp_speed=speed), "test") is None
        robot.sleep(0.5)
        assert BEHAVIOUR.pads_clear < robot.gripper_state().force < dims.GRIPPER_HOLD_FORCE
        start = tcp_pose(robot.joint_state().q)
        above = start.copy()
        above[2, 3] += 0.10
        # A post behind the hand: no way back, so it rises straight up, as on the floor.
        post = np.array(
            [[bottle[0] - 0.07, start[1, 3], h] for h in np.arange(z - 0.05, z + 0.3, 0.01)]
        )
        moves = recorded_moves(b)
        assert b.leave_object(above, CollisionChecker(post)) is None
        # The side pose's closing axis is +y, the first way tried. Moved +y, the hand's -y pad
        # presses the bottle, and +y takes that pad into it; moved -y, +y frees the +y pad.
        eased = 2 if lean > 0 else 1
        assert moves == ["freeing the fingers"] + ["easing the pads off"] * eased + [
            "rising from the object"
        ]
        robot.sleep(1.0)
        assert robot.gripper_state().force <= BEHAVIOUR.pads_clear
        assert abs(referee.position("pill_bottle_1")[2] - bottle[2]) < 0.003, "left on the table"
        end = tcp_pose(robot.joint_state().q)[:3, 3]
        shift = BEHAVIOUR.leave_shift
        np.testing.assert_allclose(end[1], start[1, 3] - np.sign(lean) * shift, atol=0.003)
        assert end[2] > z + 0.09, "and the hand rose"


def _press_a_pad_on_the_rail(b: Behaviours) -> None:
    """From above the rail, lower the open hand to straddle it, then move it sideways 12.5
    mm past where a pad meets the rail: the finger gives, and presses it (less and less as
    it goes on giving: read at once)."""
    robot, s = b.robot, b.settings.motion
    straddling = top_down(1.60, -0.30, RAIL_TOP - 0.01)
    down = cartesian_line(robot.joint_state().q, straddling, s.cartesian_step)
    assert down is not None and b.run(timed(down, s, tcp_speed=0.05), "test") is None
    pressed = top_down(1.60, -0.30 + 0.04, RAIL_TOP - 0.01)
    across = cartesian_line(robot.joint_state().q, pressed, s.cartesian_step / 5)
    assert across is not None and b.run(timed(across, s, tcp_speed=0.02), "test") is None
    assert robot.gripper_state().force > dims.GRIPPER_HOLD_FORCE, "a pad presses the rail"


def test_an_open_hand_whose_pads_still_press_something_is_lowered_before_it_leaves():
    """Opened, a finger can still press a mug it dragged by its handle (8.9 N), and drawn
    straight up, lift the mug 9 cm by the handle's top bar; lowered first, it comes
    free. An open hand whose pads still press something is lowered first from any
    approach, guarded over what the pads already bear, then eased sideways off it. Here
    the open hand straddles a rail from above, one pad pressed against it."""
    with scene_robot(str(DATA / "rail.yaml")) as robot:
        b = Behaviours(robot)
        moves = recorded_moves(b)
        free = CollisionChecker(np.zeros((0, 3)))
        hand_at(b, top_down(1.60, -0.30, RAIL_TOP + 0.10))
        _press_a_pad_on_the_rail(b)
        start = tcp_pose(robot.joint_state().q)
        above = start.copy()
        above[2, 3] += 0.10
        moves.clear()
        assert b.leave_object(above, free) is None
        assert moves[0] == "freeing the fingers"
        assert moves[-1] == "drawing back"
        # Lowered `leave_drop` (or less, where the guard stopped it), eased sideways off the
        # rail (the -y pad pressed the rail's -y face from outside: away is -y), then drawn
        # straight up.
        end = tcp_pose(robot.joint_state().q)[:3, 3]
        assert "easing the pads off" in moves
        np.testing.assert_allclose(end[0], above[0, 3], atol=0.005)
        shift, drop = BEHAVIOUR.leave_shift, BEHAVIOUR.leave_drop
        assert above[1, 3] - shift - 0.003 < end[1] < above[1, 3] - shift / 2
        assert above[2, 3] - drop - 0.003 < end[2] < above[2, 3] + 0.003


def test_pads_that_still_press_what_the_hand_let_go_of_are_freed_before_it_rises():
    """`free_the_pads`, which the basket's drop runs before the open hand rises (there, a
    spray bottle wedged against a pad was lifted out with it): an open hand whose pads feel
    nothing does not move; one whose pad presses a rail is lowered and eased off it, and
    its pads then feel nothing."""
    with scene_robot(str(DATA / "rail.yaml")) as robot:
        b = Behaviours(robot)
        free = CollisionChecker(np.zeros((0, 3)))
        hand_at(b, top_down(1.60, -0.30, RAIL_TOP + 0.10))
        moves = recorded_moves(b)
        assert b.free_the_pads(free) is False and moves == []
        _press_a_pad_on_the_rail(b)
        moves.clear()
        assert b.free_the_pads(free) is True
        assert moves[0] == "freeing the fingers" and "easing the pads off" in moves
        robot.sleep(BEHAVIOUR.leave_settle)
        assert robot.gripper_state().force <= BEHAVIOUR.pads_clear


def test_the_pads_are_freed_only_as_far_as_the_arm_keeps_its_clearance():
    """Lowered and eased sideways, the open hand takes the arm with it: over the basket a
    1 cm easing brought the arm within the margin of a sensor post, from where no way to
    stand by, to ready or to stow could start. Here something stands just outside the
    margin on either side of the wrist, along the closing axis the pads ease along: they
    are eased only as far as that margin, and the arm keeps its clearance."""
    with scene_robot(str(DATA / "rail.yaml")) as robot:
        b = Behaviours(robot)
        hand_at(b, top_down(1.60, -0.30, RAIL_TOP + 0.10))
        _press_a_pad_on_the_rail(b)
        q = robot.joint_state().q
        closing = tcp_pose(q)[:3, 1]
        arm = ~SPHERES.hand
        centres = sphere_centres(body_frames(q))[0][arm]
        reach = SPHERES.radius[arm] + SETTINGS.motion.clearance
        wrist = int(np.argmax(centres @ -tcp_pose(q)[:3, 2]))  # the arm's lowest sphere
        sides = []
        for way in (1.0, -1.0):  # out along the closing axis to 2 mm past every margin
            t = np.arange(0.0, 0.3, 0.001)
            at = centres[wrist] + np.outer(t, way * closing)
            gap = np.linalg.norm(at[:, None] - centres[None], axis=2) - reach
            sides.append(at[np.argmax((gap > 0).all(axis=1))] + 0.002 * way * closing)
        beside = CollisionChecker(np.array(sides), margin=SETTINGS.motion.clearance)
        assert beside.clearance_ok(q, hand=False)[0], "the arm starts clear"
        moves = recorded_moves(b)
        assert b.free_the_pads(beside) is True
        assert "easing the pads off" in moves, "eased as far as the margin"
        assert beside.clearance_ok(robot.joint_state().q, hand=False)[0]


def test_pads_still_pressed_after_the_easing_tip_it_off_turned_upright_and_back():
    """What hangs from a tilted pad's edge goes with the pad as it is eased sideways (over
    the basket, a pill bottle by its cap's lip, `test_parking_advice`); so pads that still
    press then have the open hand turn about its TCP to point straight down, and back to
    where it let go; only as far as that turn is clear (here, not at all). The rail scene
    cannot hang an object from a pad: here the pads read pressed while the hand tilts more
    than 5 deg."""
    with scene_robot(str(DATA / "rail.yaml")) as robot:
        b = Behaviours(robot)
        tilted = top_down(1.30, 0.0, RAIL_TOP + 0.20)
        tilted[:3, :3] = rotx(np.radians(30)) @ tilted[:3, :3]
        hand_at(b, tilted)

        def tilt() -> float:
            return float(np.degrees(np.arccos(-tcp_pose(robot.joint_state().q)[2, 2])))

        b._pads_still_pressed = lambda: tilt() > 5.0  # type: ignore[method-assign]
        tilts: list[float] = []
        run = b.run

        def record(traj: Trajectory, what: str) -> Failure | None:
            failure = run(traj, what)
            if what == "tipping it off":
                tilts.append(tilt())
            return failure

        b.run = record  # type: ignore[method-assign]
        let_go = tcp_pose(robot.joint_state().q)
        in_the_way = CollisionChecker(let_go[:3, 3][None] + [0.0, 0.0, 0.12])
        assert b.free_the_pads(in_the_way) is True and tilts == [], "not turned into it"
        let_go = tcp_pose(robot.joint_state().q)
        assert b.free_the_pads(CollisionChecker(np.zeros((0, 3)))) is True
        assert len(tilts) == 2 and tilts[0] < 1.0, "turned upright"
        end = tcp_pose(robot.joint_state().q)
        assert abs(tilts[1] - 30.0) < 1.0, "and back"
        np.testing.assert_allclose(end[:3, :3], let_go[:3, :3], atol=0.02)
        # Only lowered (`leave_drop`) and eased sideways (`leave_shift`) before the turns.
        assert np.linalg.norm(end[:3, 3] - let_go[:3, 3]) < 0.04


def from_plus_y(x: float, y: float, z: float) -> np.ndarray:
    """A TCP pose at (x, y, z) (m, `base`) with the hand level, approaching along -y and
    closing across x."""
    T = np.eye(4)
    T[:3, :3] = np.column_stack([[0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    T[:3, 3] = x, y, z
    return T


def test_let_go_low_on_the_floor_the_open_hand_is_drawn_back_off_a_tall_box():
    """A cereal box let go from the side 6 cm above the floor, its top 19 cm above the hand:
    held to the floor's margin, the open hand has no way back that keeps it, and rises
    straight up 10 cm with its fingers still about the box (the way to stand by from there
    dragged the box 60 cm). Let go on the floor, the floor is its support, as on the way
    down: the hand is drawn back off the box, the box stands where it stood, and the hand
    then rises out of the floor's margin, where a way to stand by can start."""
    with scene_robot(str(DATA / "floor_box.yaml")) as robot:
        referee = Referee(robot)
        box = referee.position("cereal_box_1")
        b = Behaviours(robot)
        run = b.run  # the setup's own moves, not recorded
        free = CollisionChecker(np.zeros((0, 3)))
        low = from_plus_y(box[0], box[1] + 0.07, 0.063)  # 2.5 cm in from its +y face
        out = from_plus_y(box[0], box[1] + 0.17, 0.12)  # clear of the floor's margin
        q_out = next(q for q in ik_tcp(out, dims.UR5_READY_Q) if free.clearance_ok(q)[0])
        assert b.go_ready().ok
        assert b.go_to(q_out, free, "test", via=(dims.UR5_HIGH_READY_Q,)).ok
        path = cartesian_line(q_out, low, b.settings.motion.cartesian_step)
        assert path is not None
        assert run(timed(path, b.settings.motion, tcp_speed=0.03), "in") is None
        robot.sleep(0.3)
        assert not robot.gripper_state().closed
        assert not free.clearance_ok(robot.joint_state().q)[0], "within the floor's margin"
        above = low.copy()
        above[2, 3] += 0.10
        moves = recorded_moves(b)
        assert b.leave_object(above, free, on_floor=True) is None
        assert moves[-2:] == ["drawing back", "rising off the floor"], moves
        end = tcp_pose(robot.joint_state().q)[:3, 3]
        assert end[1] - low[1, 3] > 0.09, "drawn back 10 cm along the approach"
        assert end[2] > above[2, 3] - 0.005, "and risen as high as it came down from"
        assert free.clearance_ok(robot.joint_state().q)[0]
        np.testing.assert_allclose(referee.position("cereal_box_1"), box, atol=0.005)
        # Held to the floor's margin, as the place went by before: straight up instead.
        assert b.go_to(q_out, free, "test").ok
        assert run(timed(path, b.settings.motion, tcp_speed=0.03), "in") is None
        moves.clear()
        assert b.leave_object(above, free) is None
        assert moves == ["rising from the object"]


def test_an_open_hand_drawing_back_stops_where_a_pad_touches_and_eases_off():
    """Drawn back from a spice jar it let go of 1 cm off its middle, a pad brushed the jar's
    top and dragged it over. The draw-back after a place is guarded (`leave_nudge` over
    what the pads bear): where a pad touches what it let go of, the hand stops, eases the
    pads off it sideways and draws back from there along its approach. Here the way back
    given also runs 8 cm across (-y), and the hand stands 1.9 cm to the jar's -y, so that
    the +y pad, 1 mm from the jar's top, meets it at once. Drawn back that way unguarded
    (`leave_touches` 0), the pad tipped the jar over."""
    with scene_robot(str(DATA / "jar_table.yaml")) as robot:
        referee = Referee(robot)
        jar = referee.position("spice_jar_1")
        b = Behaviours(robot)
        s = b.settings.motion
        z = jar[2] + 0.08  # the pads about the jar's top, as a side grasp from a shelf
        top = np.mgrid[1.65:2.25:0.02, -0.65:0.35:0.02].reshape(2, -1).T
        table = CollisionChecker(np.c_[top, np.full(len(top), jar[2])], margin=0.0)
        out_front = side_pose(jar[0] - 0.10, jar[1], z)
        q = next(q for q in ik_tcp(out_front, dims.UR5_READY_Q) if table.clearance_ok(q)[0])
        assert b.go_to(q, table, "test").ok
        y = jar[1] - 0.019
        about = cartesian_line(robot.joint_state().q, side_pose(jar[0], y, z))
        assert about is not None and b.run(timed(about, s, tcp_speed=0.03), "test") is None
        robot.sleep(0.5)
        assert robot.gripper_state().force <= BEHAVIOUR.pads_clear, "the pads touch nothing"
        across = cartesian_line(robot.joint_state().q, side_pose(jar[0] - 0.10, y - 0.08, z))
        assert across is not None
        moves = recorded_moves(b)
        assert b._draw_back_by_touch(across, side_pose(0, 0, 0)[:3, 2], table) is None
        assert moves[:2] == ["drawing back", "easing the pads off"], moves
        assert moves[-1] == "drawing back"
        end = tcp_pose(robot.joint_state().q)[:3, 3]
        assert end[0] < jar[0] - 0.08, "drawn back off the jar"
        robot.sleep(1.0)
        assert np.linalg.norm(referee.position("spice_jar_1") - jar) < 0.003, "left standing"
