"""The basket's boards stop what falls on them: a light, small object let go high over the
basket comes to rest in it, not through its floor. Reads ground-truth poses on purpose: it
tests the contact model, not the robot."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from laserpick.description import dims
from laserpick.robot.sim.loop import Simulation
from laserpick.robot.sim.scenes import parse_scene
from laserpick.robot.sim.truth import inside_basket

#: A table far from the scooter for the objects to start on; the scooter at the origin, so
#: `base` is `world`.
SCENE = """
name: basket-drops
scooter: {x: 0.0, y: 0.0, yaw_deg: 0.0}
surfaces:
  - {name: table, kind: table, xy: [3.0, 0.0], size: [0.6, 1.0], height: 0.46}
objects:
  - {name: pill, model: pill, on: table, xy: [3.0, -0.2]}
  - {name: remote, model: tv_remote, on: table, xy: [3.0, 0.2]}
"""


@pytest.mark.parametrize("name", ["pill", "remote"])
@pytest.mark.parametrize("height", [0.20, 0.45, 0.60])
def test_what_is_let_go_over_the_basket_comes_to_rest_in_it(name, height):
    """Let go `height` m over the basket's floor, still, tilted 30 deg: a 0.6 g pill fell
    through the 3 cm board from 34 cm at MuJoCo's default contact stiffness."""
    sim = Simulation(parse_scene(SCENE), realtime=False)
    m, d = sim.model, sim.data
    body = m.body(f"obj/{name}")
    qpos = m.jnt_qposadr[m.body_jntadr[body.id]]
    d.qpos[qpos : qpos + 3] = dims.BASKET_CENTER[:2].tolist() + [dims.BASKET_FLOOR + height]
    half = math.radians(30.0) / 2
    d.qpos[qpos + 3 : qpos + 7] = [math.cos(half), math.sin(half), 0.0, 0.0]
    mujoco.mj_forward(m, d)
    sim.settle(2.0)
    assert inside_basket(np.asarray(d.xipos[body.id])), f"{name} at {d.xipos[body.id]}"
