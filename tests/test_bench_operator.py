"""The scripted operator: what it sees of the dot, where it aims, how it chooses a grasp by
hand, how the helper tidies after an attempt, and the protocols' scenes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from laserpick.bench.parking import fallen, go_to_object, obstacles, parking_pose
from laserpick.bench.picking import (
    BENCH,
    LEVER_MAX,
    ScriptedOperator,
    open_session,
    seen_middle,
)
from laserpick.bench.protocols import Options, scripted_operator
from laserpick.bench.protocols.jeeves import JEEVES_MODELS, jeeves_scene
from laserpick.bench.protocols.laser_scan import scan_points
from laserpick.bench.protocols.pick_place import coin_flip_kitchen
from laserpick.bench.referee import Referee
from laserpick.bench.route_planning import parked_clear
from laserpick.description import dims
from laserpick.pipeline.balance import hold_lever
from laserpick.pipeline.cloud import fuse
from laserpick.robot.sim.scenes import load_scene, scene_config
from laserpick.robot.sim.truth import capture
from laserpick.transforms import matrix_from_quat, planar_pose


def test_every_jeeves_object_stands_at_every_location() -> None:
    for model in JEEVES_MODELS:
        for k in range(1, 7):
            scene = jeeves_scene(model, f"loc{k}")
            assert [p.model.name for p in scene.placements] == [model]


def test_every_coin_flipped_kitchen_builds() -> None:
    """pick-place flips each kitchen object onto its side or not; where one does not fit its
    spot lying (a cereal box past a shelf's edge), it stands instead."""
    flipped = 0
    for seed in range(1, 21):
        scene = coin_flip_kitchen(np.random.default_rng(seed))
        assert len(scene.placements) == len(scene_config("kitchen")["objects"])
        flipped += sum(p.lying for p in scene.placements)
    assert 0 < flipped < 20 * len(scene.placements)  # both sides of the coin come up


def test_scan_points_step_across_the_visible_top() -> None:
    """002's scan: aim points 1.5 cm apart over the object's top, all on the object."""
    cap = capture("isolation", seed=1)
    try:
        name = next(p.instance for p in cap.scene.placements if p.model.name == "tv_remote")
        pts = scan_points(cap, name)
        on_it = cap.object_points(fuse(cap.frames), name)
        seen = fuse(cap.frames).points[on_it]
    finally:
        cap.close()
    assert 4 <= len(pts) <= 100, len(pts)  # an 18 x 5 cm remote, in 1.5 cm squares
    gaps = np.linalg.norm(pts[:, None, :2] - pts[None, :, :2], axis=2)
    np.fill_diagonal(gaps, np.inf)
    assert gaps.min() > 0.005  # one point per 1.5 cm cell, near its centre
    assert np.ptp(pts[:, 2]) < 0.025  # all on the top
    nearest = np.linalg.norm(pts[:, None] - seen[None], axis=2).min(axis=1)
    assert nearest.max() < 1e-6  # each is a point the cameras saw on the object


def test_the_user_sees_whether_the_dot_is_on_the_object() -> None:
    """What the scripted user re-aims by: the dot aimed at an object's visible top lies on
    it; aimed beside it, onto the table, it does not."""
    cap = capture("isolation", seed=1)
    try:
        referee = Referee(cap.robot)
        name = next(p.instance for p in cap.scene.placements if p.model.name == "mug")
        top = cap.visible_top(fuse(cap.frames), name)
        assert top is not None
        laser = cap.robot.laser
        laser.aim_at(top)
        assert referee.dot_on(name)
        beam = (top - laser.origin_base)[:2] / np.linalg.norm((top - laser.origin_base)[:2])
        beside = top + 0.15 * np.r_[-beam[1], beam[0], 0.0]  # 15 cm to its left
        laser.aim_at(beside)
        assert not referee.dot_on(name)
        hit = cap.robot.laser_hits()
        assert hit, "the dot aimed beside the mug lies on the table"
    finally:
        cap.close()


def test_choosing_by_hand_the_user_holds_across_the_middle_and_toggles_on(tmp_path: Path) -> None:
    """A TV remote lying across the table. Seen whole, the middle of what the user sees is
    its middle, and the system's best cluster holds it there (G_b is the hand's bottom,
    selection.hand_bottom): the user takes it. With 8 cm of one end hidden from them (the
    test cuts it from what the cameras saw), the middle they see lies 4 cm toward the other
    end: the best clusters hold it off that middle, and the user steps past them to the
    first that holds it across it (a grasp on the hidden end is not on the remote as they
    see it). Told that grasp failed to plan, the user passes its cluster by the next
    time."""
    scene = tmp_path / "remote.yaml"
    scene.write_text(
        "name: remote\nscooter: {x: 0.0, y: 0.0, yaw_deg: 0.0}\n"
        "surfaces:\n  - {name: t, kind: table, xy: [1.6, -0.2], size: [0.6, 1.0], height: 0.46}\n"
        "objects:\n  - {name: remote, model: tv_remote, on: t, xy: [1.5, -0.3], yaw_deg: 90}\n"
    )
    with scripted_operator(load_scene(str(scene)), 0, 1, Options(tremor_deg=0.0)) as op:
        s = op.session
        s.set_mode(BENCH, selection="manual", mode="pick_and_place")
        assert op.mark(op.new_attempt("remote", "manual", "gpd"))
        seen = op.referee.view().points()
        middle = seen_middle(seen["remote"])
        assert np.linalg.norm((middle - op.referee.centre_of_mass("remote"))[:2]) < 0.01
        op.choose("remote", seen)
        assert s.status()["grasps"]["cluster"] == 0
        # Its long axis, from `world` into `base`; 8 cm of one end hidden.
        ref = op.referee
        origin = ref.world_position("remote")
        along = ref.to_base(origin + matrix_from_quat(ref.world_quat("remote"))[:, 0])
        along -= ref.to_base(origin)
        reach = (seen["remote"] - middle) @ along
        seen["remote"] = seen["remote"][reach > reach.min() + 0.08]
        middle = seen_middle(seen["remote"])
        on, levers = [], []  # per cluster: on the remote as the user sees it; lever (m)
        for k in range(s.status()["grasps"]["clusters"]):
            s.select_grasp(BENCH, k, 0)
            pose = np.asarray(s.status()["current"]["pose"])
            on.append(op.referee.object_at(pose[:3, 3], seen) == "remote")
            levers.append(hold_lever(pose, middle))
        assert on[0] and levers[0] > LEVER_MAX, "the best cluster should hold it off that middle"
        balanced = [k for k, x in enumerate(levers) if on[k] and x <= LEVER_MAX]
        op.choose("remote", seen)
        chosen = s.status()["grasps"]["cluster"]
        assert balanced and chosen == balanced[0]
        # That grasp failed to plan: on the next try the user toggles past its cluster.
        op.saw_unplanned("remote", np.asarray(s.status()["current"]["position"]))
        op.choose("remote", seen)
        again = s.status()["grasps"]["cluster"]
        others = [k for k in range(len(on)) if on[k] and k != chosen]
        assert again == ([k for k in others if levers[k] <= LEVER_MAX] or others)[0]


def test_the_middle_a_person_sees_is_the_middle_of_the_seen_bounds() -> None:
    """Hand-worked: points seen densely at one end of a 20 cm object and sparsely at the
    other; its middle is halfway between its ends, not where most points lie."""
    pts = np.array([[0.0, 0.0, 0.1], [0.01, 0.0, 0.1], [0.02, 0.01, 0.1], [0.2, 0.02, 0.12]])
    assert seen_middle(pts) == pytest.approx([0.1, 0.01, 0.11])


def test_the_helper_empties_the_basket_of_any_object_after_an_attempt() -> None:
    """An object that fell in the basket (a wrong object's pick) stands in the laser's way;
    tidying after the attempt takes it out, whatever it was."""
    scene = load_scene("isolation", seed=1)
    with scripted_operator(scene, 0, 1, Options()) as op:
        name = scene.placements[0].instance
        T_world_base = planar_pose(*op.robot.base_pose())
        drop = (T_world_base @ np.append(dims.BASKET_CENTER + [0.0, 0.0, 0.05], 1.0))[:3]

        def into_basket(m, d) -> None:
            j = m.joint(f"obj/{name}")
            d.qpos[j.qposadr[0] : j.qposadr[0] + 3] = drop
            d.qvel[j.dofadr[0] : j.dofadr[0] + 6] = 0.0

        op.robot.sim.call(into_basket)
        op.robot.sleep(1.0)
        assert op.referee.in_basket(name)
        op.tidy()
        assert not op.referee.in_basket(name)
        assert np.linalg.norm(op.referee.position(name)[:2]) > 3.0  # out of the scene


def test_a_tasks_random_draws_do_not_depend_on_the_tasks_before_it() -> None:
    """The user's, the grasp sampler's and the cameras' draws of a pick-place task come from
    (the trial's seed, the task) alone: after other draws, task 2 begins as it began before;
    task 3 draws otherwise."""
    session = open_session(load_scene("isolation", seed=1), seed=5)
    try:
        op = ScriptedOperator(session, np.random.default_rng(5), seed=5)
        sampler, robot = session.behaviours.rng, session.robot

        def draws() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            depth = robot.capture()[0].depth
            return op.rng.random(4), sampler.random(4), depth

        op.begin_task(2)
        first = draws()
        later = draws()  # what the task's attempts go on to draw
        assert not np.array_equal(first[2], later[2]), "the cameras draw noise"
        op.begin_task(2)
        again = draws()
        for a, b in zip(first, again, strict=True):
            np.testing.assert_array_equal(a, b)
        op.begin_task(3)
        other = draws()
        for a, b in zip(first, other, strict=True):
            assert not np.array_equal(a, b)
    finally:
        session.close()


def test_where_something_fallen_keeps_the_user_from_parking_it_is_picked_up() -> None:
    """The mug lies on the floor where the scooter parks before the 73 cm table, as one that
    missed the basket there does: the user cannot park there for the table's soda can until
    someone picks the mug up, and then does. What lies on a floor area was put there, and
    stays."""
    scene = load_scene("kitchen", seed=1)
    session = open_session(scene, seed=5)
    try:
        op = ScriptedOperator(session, np.random.default_rng(5), seed=5)
        table = scene.surface("table_73")
        local_y = table.to_local(op.referee.world_position("soda_can")[:2])[1]
        goal = parking_pose(table, local_y)  # where the user parks for the soda can
        spot = planar_pose(*goal) @ np.array([0.6, -0.2, 0.0, 1.0])  # under the scooter
        op.referee.put_back("mug", np.array([spot[0], spot[1], 0.0, 1.0, 0.0, 0.0, 0.0]))
        assert fallen(scene, op.referee) == ["mug"]
        on_floor = obstacles(scene.surfaces, op.referee, ["mug"])
        assert not parked_clear(goal, on_floor, op.referee.outline())
        assert go_to_object(op, scene, "soda_can")
        assert op.referee.taken_out("mug")
        assert np.linalg.norm(op.base_pose()[:2] - goal[:2]) < 0.05
        assert not any(op.referee.taken_out(n) for n in ("stuffed_toy", "tissue_packet"))
    finally:
        session.close()
