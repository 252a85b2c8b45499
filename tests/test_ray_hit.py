"""`ray_hit`: a click's ray turned into the cloud point the user meant."""

from __future__ import annotations

import numpy as np
import pytest

from laserpick.pipeline.cloud import ray_distance, ray_hit


def _wall_and_box() -> np.ndarray:
    """A wall at x = 2 (1 cm grid) and a small box face at x = 1 in front of it."""
    g = np.arange(-0.5, 0.5, 0.01)
    yy, zz = np.meshgrid(g, g)
    wall = np.c_[np.full(yy.size, 2.0), yy.ravel(), zz.ravel()]
    b = np.arange(-0.05, 0.05, 0.01)
    by, bz = np.meshgrid(b, b)
    box = np.c_[np.full(by.size, 1.0), by.ravel(), bz.ravel()]
    return np.vstack([wall, box]).astype(np.float32)


def test_the_first_surface_along_the_ray_wins() -> None:
    points = _wall_and_box()
    hit = ray_hit(points, np.zeros(3), np.array([1.0, 0.0, 0.0]))
    assert hit is not None and hit[0] == pytest.approx(1.0)  # the box, not the wall
    hit = ray_hit(points, np.zeros(3), np.array([1.0, 0.2, 0.0]))
    assert hit is not None and hit[0] == pytest.approx(2.0, abs=1e-6)  # past the box


def test_a_ray_that_misses_or_points_away_finds_nothing() -> None:
    points = _wall_and_box()
    assert ray_hit(points, np.zeros(3), np.array([0.0, 0.0, 1.0])) is None
    assert ray_hit(points, np.zeros(3), np.array([-1.0, 0.0, 0.0])) is None


def test_a_zero_direction_is_refused() -> None:
    with pytest.raises(ValueError, match="direction"):
        ray_hit(_wall_and_box(), np.zeros(3), np.zeros(3))


def test_how_far_a_point_lies_from_a_ray() -> None:
    o, d = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 2.0])  # up the z axis from x = 1
    assert ray_distance(np.array([1.0, 0.0, 5.0]), o, d) == pytest.approx(0.0)
    assert ray_distance(np.array([1.0, 0.3, 5.0]), o, d) == pytest.approx(0.3)
    assert ray_distance(np.array([1.0, 0.0, -0.4]), o, d) == pytest.approx(0.4)  # behind
    with pytest.raises(ValueError, match="direction"):
        ray_distance(np.zeros(3), o, np.zeros(3))
