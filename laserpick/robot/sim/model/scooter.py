"""The scooter's shell in `base`: deck, seat, tiller, wheels, sensor posts, basket, pedestal,
each a shape of the described `scooter` part (`description.visuals`)."""

from __future__ import annotations

import mujoco

from laserpick.robot.sim.model.geoms import PARTS_BY_NAME, SHELL_GEOM, add_shape
from laserpick.robot.sim.model.names import SCOOTER_BODY

#: The basket's contacts: a time constant stiffer than MuJoCo's default (0.02 s), and the
#: basket's is the one a contact with an object takes (`solmix` weighs the mix). A drop then
#: stops within the board: at the default, a 0.6 g pill let go 34-60 cm over the basket's
#: floor went through its 3 cm board in 24 of 45 drops (the soft contact lets it sink 2-3 cm
#: first); at 0.01 s in none, and where a mug, a spice jar, a pill bottle, a soda can, a
#: remote and a phone land from the same drops is unchanged.
BASKET_CONTACT = {"solref": [0.01, 1.0], "solmix": 1000.0}


def add_scooter_shell(body: mujoco.MjsBody) -> None:
    """Every shape of the scooter as a massless geom of `body`: the base's planar joints, not
    wheel contacts, carry the scooter. The basket's boards take `BASKET_CONTACT`."""
    for shape in PARTS_BY_NAME[SCOOTER_BODY].shapes:
        basket = "basket" in shape.name
        add_shape(body, shape, **SHELL_GEOM, **(BASKET_CONTACT if basket else {}))
