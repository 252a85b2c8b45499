"""A grasp the arm can take has a clear straight approach. The reachability filter checks the
postures at the approach's ends; the grasp choice checks the line between them, as far as it
needs to know whether any grasp can be taken, so that the fallback passes still run when none
can. Frames: `base`, metres, radians."""

from __future__ import annotations

import numpy as np
import pytest
from arm_poses import EMPTY, top_grasp
from test_grasping import _perception

from laserpick.description import dims
from laserpick.description.kinematics import tcp_pose
from laserpick.pipeline import grasp_choice
from laserpick.pipeline.collision import CollisionChecker
from laserpick.pipeline.grasp_choice import FilteredCandidates, GraspSet, find_grasps
from laserpick.pipeline.parking_advice import back_up_advice
from laserpick.pipeline.plan import APPROACH_BLOCKED, straight_approach
from laserpick.pipeline.reach import pregrasp_pose, reachable
from laserpick.settings import get_settings
from laserpick.types import Failure, Grasp

#: A top grasp, and a point beside the wrist's way down to it: within the wrist's sphere and
#: margin halfway down, clear of them at the pre-grasp and at the grasp.
GRASP = top_grasp(1.5, -0.3, 0.60)
BESIDE_THE_WRIST = np.array([[1.5231, -0.3509, 0.8865]])
CLEAR = top_grasp(1.6, 0.0, 0.60)


def _filtered(world: CollisionChecker, *poses: np.ndarray) -> list[Grasp]:
    m = get_settings().motion
    grasps = [Grasp(T, 0.05) for T in poses]
    return reachable(grasps, world, dims.UR5_READY_Q, m.approach_distance, m.lift_least)


def _pool(world: CollisionChecker, checked: list[Grasp]) -> FilteredCandidates:
    rng = np.random.default_rng(0)
    timings = {"detect": 0.0, "filter": 0.0}
    pool = FilteredCandidates(None, dims.UR5_READY_Q, get_settings(), rng, world, timings)
    pool.checked = checked
    return pool


def test_a_point_beside_the_wrists_way_blocks_the_approach_and_not_its_ends():
    s = get_settings().motion
    world = CollisionChecker(BESIDE_THE_WRIST, voxel=0.0)
    (grasp,) = _filtered(world, GRASP)
    assert grasp.ik is not None, "the filter keeps it: both ends are clear"
    blocked = straight_approach(grasp.ik, world, s)
    assert isinstance(blocked, Failure) and APPROACH_BLOCKED in blocked.message.lower()
    line = straight_approach(grasp.ik, CollisionChecker(EMPTY), s)
    assert isinstance(line, np.ndarray) and len(line) == 11  # 10 cm in 1 cm steps
    assert np.allclose(tcp_pose(line[0]), pregrasp_pose(tcp_pose(grasp.ik), 0.10), atol=1e-6)
    assert np.array_equal(line[-1], grasp.ik)


def test_a_grasp_whose_approach_is_blocked_is_one_the_arm_cannot_take():
    world = CollisionChecker(BESIDE_THE_WRIST, voxel=0.0)
    pool = _pool(world, _filtered(world, GRASP))
    assert pool.none_reachable()
    (out,) = pool.without_blocked()
    assert out.ik is None and out.ik_failure == APPROACH_BLOCKED
    assert pool.timings["filter"] > 0
    with_a_clear_one = _pool(world, _filtered(world, GRASP, CLEAR))
    assert not with_a_clear_one.none_reachable()


def test_approaches_are_checked_only_up_to_the_first_clear_one():
    """A check costs about a millisecond, and the open table leaves hundreds of grasps: the
    grasps after the first clear one are left to the planner, which checks each it tries."""
    world = CollisionChecker(BESIDE_THE_WRIST, voxel=0.0)
    pool = _pool(world, _filtered(world, CLEAR, GRASP))
    assert not pool.none_reachable()
    assert pool.approaches == {0: True}
    assert [g.ik is not None for g in pool.without_blocked()] == [True, True]


def test_the_advice_to_back_up_asks_for_a_clear_approach_too():
    """Backed up 10 cm, the grasp 10 cm short of GRASP lies where GRASP does, and what the
    cameras saw beside it where BESIDE_THE_WRIST is: its postures are clear there and its
    approach is not, so backing up that far does not serve."""
    m = get_settings().motion
    short = [Grasp(top_grasp(1.4, -0.3, 0.60), 0.05)]
    seen = CollisionChecker(BESIDE_THE_WRIST - [0.10, 0.0, 0.0], voxel=0.0)
    nothing = CollisionChecker(EMPTY)
    assert back_up_advice(short, nothing, dims.UR5_READY_Q, m, steps=(0.10,)) == 0.10
    assert back_up_advice(short, seen, dims.UR5_READY_Q, m, steps=(0.10,)) is None


@pytest.mark.parametrize("blocked", [False, True])
def test_the_fallback_passes_run_when_every_approach_is_blocked(monkeypatch, blocked):
    """GPD's grasps on a can in the open are reachable. With every straight approach blocked
    (as by a board just above the can's wrist-high neighbours), none can be taken, and the
    other passes run, as when none is reachable; with the approaches clear, they do not."""
    passes: list[str] = []
    add = FilteredCandidates.add

    def spy(self, kind, complete=False, tilted=False, most=None):
        passes.append(f"{kind}{' completed' if complete else ''}{' tilted' if tilted else ''}")
        return add(self, kind, complete, tilted, most)

    def nothing_straight(q_grasp, world, s):
        return False

    monkeypatch.setattr(FilteredCandidates, "add", spy)
    if blocked:
        monkeypatch.setattr(grasp_choice, "approach_clear", nothing_straight)
    found = find_grasps(_perception((1.55, -0.3)), dims.UR5_READY_Q)
    if not blocked:
        assert isinstance(found, GraspSet) and passes == []
        return
    assert passes == ["gpd completed", "vertical", "gpd completed tilted"]
    assert isinstance(found, Failure) and found.kind == "ik_plan"
    assert found.message.startswith("The arm cannot take any of")
    assert f"({APPROACH_BLOCKED})" in found.message
