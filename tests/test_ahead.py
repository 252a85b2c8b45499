"""Searching ahead: the arm stands still only for the part of a search that outlasts the
motion it ran during, by the robot's clock."""

from __future__ import annotations

import time
from types import SimpleNamespace

import numpy as np
import pytest

from laserpick.behaviours.ahead import Ahead


class _Clock:
    """A robot whose clock the test sets: all `Ahead` reads of it (`joint_state().stamp`)."""

    def __init__(self) -> None:
        self.now = 0.0

    def joint_state(self) -> SimpleNamespace:
        return SimpleNamespace(stamp=self.now)


def _search(seconds: float, out: str = "way"):
    def search() -> str:
        time.sleep(seconds)
        return out

    return search


def test_a_search_done_within_the_motion_costs_no_wait() -> None:
    robot = _Clock()
    ahead = Ahead(robot, np.zeros(6), ("mug",), _search(0.05))
    robot.now = 2.0  # the lift took 2 s of robot time
    assert ahead.result() == ("way", 0.0)


def test_a_search_that_outlasts_the_motion_charges_the_rest() -> None:
    robot = _Clock()
    ahead = Ahead(robot, np.zeros(6), ("mug",), _search(0.3))
    robot.now = 0.1
    way, waited = ahead.result()
    assert way == "way"
    assert 0.2 <= waited < 0.3 + 0.2  # its wall time (0.3 s and the thread's start) less 0.1


def test_it_fits_only_what_it_was_searched_for_where_the_arm_stands_at_its_start() -> None:
    ahead = Ahead(_Clock(), np.zeros(6), ("mug",), _search(0.0))
    near = np.full(6, 0.01)
    assert ahead.fits(("mug",), near, tolerance=0.02)
    assert not ahead.fits(("ball",), near, tolerance=0.02)
    assert not ahead.fits(("mug", "shelf"), near, tolerance=0.02)
    assert not ahead.fits(("mug",), near + 0.05, tolerance=0.02)


def test_what_the_search_raises_is_raised_to_whoever_takes_it_up() -> None:
    def broken() -> None:
        raise ValueError("no postures")

    ahead = Ahead(_Clock(), np.zeros(6), ("mug",), broken)
    with pytest.raises(ValueError, match="no postures"):
        ahead.result()
