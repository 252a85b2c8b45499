"""Laser mark detection (pipeline/laser_spots.py, laser_mark.py) against the simulator's true
beam hits."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from laserpick.pipeline.cloud import fuse
from laserpick.pipeline.laser_mark import detect_mark, direct_mark
from laserpick.pipeline.laser_spots import find_spots, pair_spots
from laserpick.robot.sim.truth import capture
from laserpick.settings import get_settings
from laserpick.types import Failure, LaserMark


@pytest.fixture(scope="module")
def captured():
    c = capture("isolation")
    yield c
    c.close()


def _mark(c, target, confirm: bool):
    """Aim at `target` (base = world in isolation), optionally confirm, capture and detect.
    Returns (detection, true hit of the aiming beam or None, frames)."""
    c.robot.laser.aim_at(np.asarray(target))
    if confirm:
        c.robot.laser.confirm()
    frames = c.robot.capture()
    hits = c.robot.laser_hits()
    return detect_mark(frames), (hits[0] if hits else None), frames


def _targets(c, cloud, instance: str, rng) -> list[np.ndarray]:
    """Visible points on an object: the centre of its top (highest 5 mm of its points) and
    five random points the cameras saw on it (mostly its sides facing the scooter)."""
    pts = cloud.points[c.object_points(cloud, instance)]
    assert len(pts) > 50, f"{instance} is barely visible"
    return [c.visible_top(cloud, instance), *pts[rng.choice(len(pts), 5, replace=False)]]


def test_marks_on_every_object_are_within_a_centimetre(captured):
    c = captured
    cloud = fuse(c.frames)
    rng = np.random.default_rng(7)
    errors, states = [], []
    for instance in c.robot.sim.info.object_bodies:
        for target in _targets(c, cloud, instance, rng):
            mark, hit, _ = _mark(c, target, confirm=True)
            assert hit is not None
            if isinstance(mark, Failure):
                errors.append(np.inf)
                continue
            errors.append(np.linalg.norm(mark.point - hit))
            states.append(mark.state)
    errors = np.array(errors)
    assert len(errors) >= 30
    within = np.mean(errors < 0.01)
    assert within >= 0.95, f"only {within:.0%} within 1 cm; errors (mm) {np.sort(errors) * 1e3}"
    assert np.median(errors) < 0.003
    assert states.count("confirmed") >= 0.9 * len(states)


def test_one_beam_is_aiming_two_are_confirmed(captured):
    c = captured
    cloud = fuse(c.frames)
    rng = np.random.default_rng(3)
    for instance in [p.instance for p in c.scene.placements[:3]]:
        target = _targets(c, cloud, instance, rng)[0]
        aiming, hit, frames = _mark(c, target, confirm=False)
        assert isinstance(aiming, LaserMark) and aiming.state == "aiming"
        assert aiming.source == "laser" and aiming.views >= 2
        assert np.linalg.norm(aiming.point - hit) < 0.01
        # One beam: one spot per image that sees it.
        s = get_settings().perception
        assert all(len(find_spots(f.ir, s.laser_threshold)) <= 1 for f in frames)
        confirmed, hit2, _ = _mark(c, target, confirm=True)
        assert isinstance(confirmed, LaserMark) and confirmed.state == "confirmed"
        np.testing.assert_allclose(hit2, hit, atol=1e-9)  # the aiming beam did not move
        assert np.linalg.norm(confirmed.point - hit) < 0.01


def test_the_reported_point_is_the_aiming_beam_not_the_midpoint(captured):
    # The beams are 1.5 cm apart: reporting their midpoint would be 7.5 mm off; telling them
    # apart puts the error at the depth noise.
    c = captured
    mark, hit, _ = _mark(c, [1.6, -0.05, 0.46], confirm=True)
    beams = c.robot.laser_hits()
    assert len(beams) == 2 and isinstance(mark, LaserMark)
    assert np.linalg.norm(mark.point - hit) < 0.004
    assert np.linalg.norm(mark.point - (beams[0] + beams[1]) / 2) > 0.005


def _assert_failure(result) -> None:
    assert isinstance(result, Failure), f"expected a failure, got {result}"
    assert result.kind == "detect_laser"
    assert len(result.message.split()) >= 4 and result.message[-1] in ".!?"


def test_mark_on_the_floor_beyond_the_workspace_fails(captured):
    c = captured
    mark, hit, frames = _mark(c, [3.2, 1.1, 0.0], confirm=True)
    assert hit is not None and hit[0] > get_settings().perception.workspace_max[0]
    # The dot is seen (so this exercises the workspace check, not the "can't see" path).
    assert any(f.ir.max() >= 250 for f in frames)
    _assert_failure(mark)
    assert "outside" in mark.message


def test_mark_into_the_sky_or_off_fails(captured):
    c = captured
    mark, hit, _ = _mark(c, [2.0, 0.0, 3.0], confirm=True)
    assert hit is None
    _assert_failure(mark)
    c.robot.laser.off()
    _assert_failure(detect_mark(c.robot.capture()))


def test_a_dot_without_depth_fails_rather_than_guessing(captured):
    # A dot on glass or a shiny highlight: the IR shows it, the depth has a hole around it.
    c = captured
    _, _, frames = _mark(c, [1.6, -0.05, 0.46], confirm=False)
    s = get_settings().perception
    holed = []
    for f in frames:
        depth = f.depth.copy()
        for spot in find_spots(f.ir, s.laser_threshold):
            u, v = round(spot.u), round(spot.v)
            depth[max(v - 12, 0) : v + 13, max(u - 12, 0) : u + 13] = 0
        holed.append(dataclasses.replace(f, depth=depth))
    _assert_failure(detect_mark(holed))


def test_views_that_disagree_fail(captured):
    c = captured
    s = get_settings().perception
    _, _, a = _mark(c, [1.55, -0.3, 0.46], confirm=False)
    _, _, b = _mark(c, [1.75, 0.1, 0.46], confirm=False)
    sees_a = [f for f in a if len(find_spots(f.ir, s.laser_threshold))]
    sees_b = [f for f in b if len(find_spots(f.ir, s.laser_threshold))]
    assert len(sees_a) >= 2 and len(sees_b) >= 2
    _assert_failure(detect_mark([*sees_a[:2], *sees_b[:2]]))
    # One view more for either side breaks the tie: that side wins.
    win = detect_mark([*sees_a[:3], *sees_b[:2]])
    assert isinstance(win, LaserMark) and np.linalg.norm(win.point[:2] - [1.55, -0.3]) < 0.03


def test_find_spots_centroid_and_pairing():
    ir = np.full((60, 80), 40, np.uint8)
    yy, xx = np.mgrid[:60, :80]
    ir[(xx - 20.5) ** 2 + (yy - 30.0) ** 2 <= 2.5**2] = 255
    ir[(xx - 31.0) ** 2 + (yy - 33.5) ** 2 <= 2.5**2] = 255
    ir[5, 5] = 255  # a single hot pixel: below the minimum spot size
    spots = find_spots(ir, 250, min_px=3)
    assert len(spots) == 2
    got = sorted((s.u, s.v) for s in spots)
    np.testing.assert_allclose(got, [(20.5, 30.0), (31.0, 33.5)], atol=0.05)
    assert pair_spots(spots, 40.0) == [[0, 1]]
    assert sorted(pair_spots(spots, 5.0)) == [[0], [1]]
    assert find_spots(np.zeros((10, 10), np.uint8), 250) == []


@pytest.mark.parametrize(
    "point",
    [
        [np.nan, 0.0, 0.5],
        [1.5, np.inf, 0.5],
        [5.0, 0.0, 0.5],  # beyond the workspace
        [1.5, 0.0, -1.0],  # under the floor
        [1.5, 0.0],  # not three numbers
        "here",
    ],
)
def test_direct_mark_rejects_bad_points(point):
    _assert_failure(direct_mark(point))


def test_direct_mark_accepts_a_point_in_the_workspace():
    mark = direct_mark((1.5, -0.1, 0.5))
    assert isinstance(mark, LaserMark)
    assert mark.state == "confirmed" and mark.views == 0 and mark.source == "direct"
    np.testing.assert_allclose(mark.point, [1.5, -0.1, 0.5])
