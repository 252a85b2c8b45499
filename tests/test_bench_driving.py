"""Where the scripted user parks and how they drive: planned ways that keep the scooter off
the furniture, parking at floor objects, and where they park for the next try."""

from __future__ import annotations

import math

import numpy as np
import pytest

from laserpick.bench.attempts import Attempt
from laserpick.bench.parking import FLOOR_TURNS, PARK_FLOOR_REACH, parking_pose, spots_near
from laserpick.bench.protocols.retries import RETRY_BACK, next_try
from laserpick.bench.route_planning import (
    DRIVE_MARGIN,
    Footprint,
    Outline,
    base_points_at,
    clearance,
    parked_clear,
    plan_drive,
    straight_poses,
    turn_poses,
)
from laserpick.description import dims
from laserpick.pipeline.parking_advice import UNSEEN_WAYS
from laserpick.robot.sim.scenes import load_scene
from laserpick.transforms import invert, planar_pose

#: m to the arm's left: a spot to the side, as the robot asks for one (`park_aside_advice`)
ASIDE = 0.20


def _driven(
    start: np.ndarray, back: float, waypoints: list[np.ndarray], goal: np.ndarray
) -> list[np.ndarray]:
    """The poses of a planned way as `follow` drives it: backing out, then a turn on the
    spot and a straight drive to each waypoint, then the turn to the goal's heading and the
    creep in; one array a move."""
    heading = start[2]
    here = start[:2] - back * np.array([math.cos(heading), math.sin(heading)])
    poses = [straight_poses(start[:2], here, heading)]
    for point in waypoints:
        h = math.atan2(point[1] - here[1], point[0] - here[0])
        poses += [turn_poses(here, heading, h), straight_poses(here, point, h)]
        here, heading = point, h
    return poses + [turn_poses(here, heading, goal[2]), straight_poses(here, goal[:2], goal[2])]


def test_the_scripted_user_drives_around_tables_not_through_them() -> None:
    """From the 73 cm table to the counter, the straight way swings the scooter's front (the
    arm, 1.30 m ahead of the rear axle) through the table: the simulated scooter drives
    through furniture and sweeps objects off it. The planned way keeps the whole outline
    clear of every surface but the two it is parked at, and ends where the user parks."""
    scene = load_scene("kitchen", seed=1)
    outline = Outline((-0.15, 1.30), (-0.68, 0.38))  # the referee's, with the arm stowed
    table, counter = scene.surface("table_73"), scene.surface("counter")
    start, goal = parking_pose(table), parking_pose(counter, 0.3)
    plan = plan_drive(start, goal, scene.surfaces, outline, 0.6, parked_at=("counter",))
    assert plan is not None
    back, waypoints = plan
    assert back >= 0.6
    assert np.allclose(waypoints[-1], goal[:2] - 0.8 * np.array([0.0, -1.0])) or np.allclose(
        waypoints[-1], goal[:2] - 1.2 * np.array([0.0, -1.0])
    )
    # Replay the moves as drive_to drives them and look at every pose's outline.
    poses = _driven(start, back, waypoints, goal)
    points = base_points_at(np.vstack(poses), outline.points())
    others = [s for s in scene.surfaces if s.name not in ("table_73", "counter")]
    assert clearance(others, points).min() >= DRIVE_MARGIN
    # The table is touched only while the scooter is still parked at it (its first 5 cm).
    away = base_points_at(np.vstack(poses[1:]), outline.points())
    assert clearance([table], away).min() >= DRIVE_MARGIN
    # The user's old way, straight from the table to 0.8 m before the counter, hit the table.
    straight = straight_poses(start[:2] - 0.6 * np.array([1.0, 0.0]), waypoints[-1], 0.0)
    assert clearance([table], base_points_at(straight, outline.points())).min() < DRIVE_MARGIN


def test_the_user_parks_over_only_what_they_work_at() -> None:
    """Parked at the 31 cm table, the arm stands over it. That is where the user parks to
    work at the table; to work at anything else (an object on the floor before it) the same
    pose would press the arm into the table, and no way leads there."""
    scene = load_scene("kitchen", seed=1)
    outline = Outline((-0.15, 1.30), (-0.68, 0.38))  # the referee's, with the arm stowed
    start, goal = parking_pose(scene.surface("table_73")), parking_pose(scene.surface("table_31"))
    assert plan_drive(start, goal, scene.surfaces, outline, 0.6, parked_at=("table_31",))
    assert plan_drive(start, goal, scene.surfaces, outline, 0.6, parked_at=()) is None
    assert plan_drive(start, goal, scene.surfaces, outline, 0.6, parked_at=("table_73",)) is None


def test_a_turn_near_half_a_turn_is_planned_clear_either_way() -> None:
    """A turn planned close to half a turn may go either way from where the scooter stands
    (a few degrees off): it is checked all the way round; a smaller one the short way
    only."""

    def passes(yaw0: float, yaw1: float, heading_deg: float) -> bool:
        """Whether the turn's poses come within 5 deg of the heading."""
        yaws = turn_poses(np.zeros(2), yaw0, yaw1)[:, 2]
        return bool(np.any(np.cos(yaws - math.radians(heading_deg)) > math.cos(math.radians(5))))

    assert passes(0.6876, -2.4601, 90) and passes(0.6876, -2.4601, -90)
    assert passes(0.0, math.pi / 2, 45) and not passes(0.0, math.pi / 2, -45)


def test_the_user_parks_at_a_floor_object_from_a_side_with_nothing_under_the_scooter() -> None:
    """Facing the kitchen floor's +x, the tissue packet 1.45 m ahead puts the plush toy
    under the scooter: wholly inside its outline, which the outline's edges alone never
    meet. The user parks from another side, the packet before the arm."""
    scene = load_scene("kitchen", seed=1)
    floor = scene.surface("floor_area")
    outline = Outline((-0.15, 1.30), (-0.68, 0.38))  # the referee's, with the arm stowed
    tissue = scene.placement("tissue_packet").pos[:2]
    toy = Footprint("stuffed_toy", tuple(scene.placement("stuffed_toy").pos[:2]), 0.0, (0.1, 0.1))
    packet = Footprint("tissue_packet", tuple(tissue), 0.0, (0.11, 0.03))
    around = [*(s for s in scene.surfaces if s.kind != "floor"), toy, packet]
    lx, ly = floor.to_local(tissue)
    straight = parking_pose(floor, ly, 0.0, local_x=lx)
    assert clearance([toy], base_points_at(straight[None], outline.points())).min() > DRIVE_MARGIN
    assert not parked_clear(straight, around, outline)
    goals = [parking_pose(floor, ly, 0.0, local_x=lx, turn=t) for t in FLOOR_TURNS]
    clear = [g for g in goals if parked_clear(g, around, outline)]
    assert clear
    for goal in clear:
        in_base = invert(planar_pose(*goal)) @ np.array([*tissue, 0.0, 1.0])
        assert np.allclose(in_base[:2], [PARK_FLOOR_REACH, dims.ARM_MOUNT_POS[1]], atol=1e-9)


def test_after_the_arm_could_not_take_the_object_the_user_parks_farther_back():
    """After an ik_plan failure the user parks farther back; other failures change nothing.
    Where the robot asked to park to a side, that spot is kept and backed off from; the
    parking pose puts the spot that far to the arm's left."""

    kitchen = load_scene("kitchen", seed=1)

    def failed(kind: str, message: str) -> Attempt:
        return Attempt(0, 1, "juice_bottle", "m", None, "manual", "gpd").fail(kind, message)

    unseen = failed("ik_plan", f"None of the 2 grasps could be planned (No way{UNSEEN_WAYS})")
    blocked = failed("ik_plan", "The arm cannot take any of 9 grasps (every posture collides).")
    assert next_try(unseen, 0.0, ASIDE) == (RETRY_BACK, ASIDE)
    assert next_try(blocked, 0.0, 0.0) == (RETRY_BACK, 0.0)
    assert next_try(failed("execute", "slipped" + UNSEEN_WAYS), 0.1, 0.0) == (0.1, 0.0)

    table = kitchen.surface("high_table")
    spot = np.array([*table.xy, 0.0]) + [-table.size[0] / 2 + 0.25, 0.0, 0.0]  # yaw 0
    for across in (0.0, ASIDE):
        x, y, yaw = parking_pose(table, 0.0, table.levels[0], across=across)
        in_base = invert(planar_pose(x, y, yaw)) @ np.append(spot, 1.0)
        assert in_base[1] == pytest.approx(dims.ARM_MOUNT_POS[1] + across, abs=1e-9)


def test_where_the_spot_asked_is_not_clear_the_user_parks_as_near_it_as_the_room_allows():
    """With the arm standing by beside the scooter (its outline 10 cm wider on the right than
    stowed), the spot 20 cm to the arm's left before the 108 cm table, as the robot asks
    for one, brings the scooter's right side against the furniture beside it. The user parks
    at the nearest spot that is clear instead: 10 cm across. Stowed, the spot asked is."""
    kitchen = load_scene("kitchen", seed=1)
    table = kitchen.surface("high_table")
    others = [s for s in kitchen.surfaces if s.kind != "floor" and s.name != "high_table"]
    stowed = Outline((-0.15, 1.30), (-0.68, 0.38))  # about the referee's, stowed
    standing_by = Outline((-0.15, 1.32), (-0.78, 0.38))
    spots = spots_near(table, 0.0, -0.05, table.levels[0], across=ASIDE)
    assert np.allclose(spots[0], parking_pose(table, -0.05, table.levels[0], across=0.2))
    assert parked_clear(spots[0], others, stowed)
    first = next(k for k, spot in enumerate(spots) if parked_clear(spot, others, standing_by))
    assert first > 0
    assert np.allclose(spots[first], parking_pose(table, -0.05, table.levels[0], across=0.1))


@pytest.mark.slow
def test_where_no_way_with_one_stop_leads_the_user_drives_one_with_several() -> None:
    """In-situ seed 7010: parked at the floor area's far corner beside a stuffed toy on the
    floor, the user is to park at the counter. No way with one stop leads there (the creep
    in needs the scooter already facing the counter, and the 73 cm table beside its
    approach leaves no room to turn there); a way with several stops does, and every pose
    of it keeps clear of everything but the counter it parks at."""
    scene = load_scene("kitchen", seed=7010)
    outline = Outline((-0.15, 1.3022), (-0.6822, 0.3844))  # as the referee had it there
    toy = Footprint("stuffed_toy", (-1.1009, -1.3999), 0.0, (0.1003, 0.1029))
    around = [s for s in scene.surfaces if s.kind != "floor"] + [toy]
    start = np.array([-2.0439, -2.5071, 7.0665])
    goal = np.array([0.55, -0.70, -math.pi / 2])
    plan = plan_drive(start, goal, around, outline, 0.6, parked_at=("counter",))
    assert plan is not None
    back, waypoints = plan
    assert len(waypoints) >= 3
    poses = _driven(start, back, waypoints, goal)
    others = [s for s in around if s.name != "counter"]
    filled = base_points_at(np.vstack(poses), outline.points(filled=True))
    assert clearance(others, filled).min() >= DRIVE_MARGIN
