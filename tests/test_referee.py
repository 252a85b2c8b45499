"""The bench's judge of a drop: an object lies in the basket when its centre of mass is within
the walls and below the rim, judged on the simulator's truth."""

from __future__ import annotations

import mujoco
import numpy as np
from arm_setups import DATA, scene_robot

from laserpick.description import dims
from laserpick.robot.sim.truth import SimTruth, inside_basket, on_scooter

FLOOR = dims.BASKET_FLOOR
RIM = dims.BASKET_CENTER[2] + dims.BASKET_INNER[2] / 2


def test_a_centre_of_mass_is_inside_within_the_walls_and_below_the_rim():
    middle = dims.BASKET_CENTER.copy()
    assert inside_basket(middle)
    assert inside_basket(np.append(middle[:2], FLOOR + 0.01))
    assert not inside_basket(np.append(middle[:2], RIM + 0.01)), "lying across the rims"
    beside = middle + [0.0, dims.BASKET_INNER[1] / 2 + 0.01, 0.0]
    assert not inside_basket(beside)
    assert not inside_basket(np.append(middle[:2], FLOOR - 0.05)), "under the basket"


def test_an_object_that_missed_the_basket_and_lies_on_the_scooter_is_on_it():
    """The helper takes such an object off the scooter (`ScriptedOperator.tidy`): a cereal
    box left across the basket's rim took the drops of the next four tasks in one trial."""
    across_the_rims = np.append(dims.BASKET_CENTER[:2], RIM + 0.03)
    assert on_scooter(across_the_rims) and not inside_basket(across_the_rims)
    on_the_deck = np.array([0.5, 0.0, dims.SCOOTER_DECK_HEIGHT + 0.04])
    assert on_scooter(on_the_deck)
    assert not on_scooter(np.array([0.5, 0.0, 0.05])), "on the floor beneath"
    assert not on_scooter(np.array([1.5, -0.3, 0.50])), "on a table before the arm"
    assert not on_scooter(np.array([0.9, -0.8, 0.60])), "beside the scooter"


def test_a_box_standing_on_its_top_in_the_basket_is_in_it():
    """A 25 cm cereal box that came to rest on its top in the basket: its origin (the middle
    of its bottom face) is 9 cm over the rim, its centre of mass inside."""
    with scene_robot(str(DATA / "tall_object.yaml")) as robot:
        truth = SimTruth(robot)
        name = "cereal_box_1"
        height = truth.centre_of_mass(name)[2] - truth.position(name)[2]  # half its height
        top = truth.to_world(np.append(dims.BASKET_CENTER[:2], FLOOR + 2 * height + 0.005))

        def upside_down(m: mujoco.MjModel, d: mujoco.MjData) -> None:
            j = m.joint(f"obj/{name}")
            d.qpos[j.qposadr[0] : j.qposadr[0] + 7] = [*top, 0.0, 1.0, 0.0, 0.0]
            d.qvel[j.dofadr[0] : j.dofadr[0] + 6] = 0.0

        robot.sim.call(upside_down)
        robot.sleep(1.0)
        assert truth.position(name)[2] > RIM + 0.05, "the origin stands over the rim"
        assert truth.in_basket(name)
        truth.take_out(name)
        assert not truth.in_basket(name)
