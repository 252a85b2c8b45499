"""The scooter's shell in `base`: deck, seat, tiller, wheels, sensor posts, basket, pedestal,
each a shape of the described `scooter` part (`description.visuals`)."""

from __future__ import annotations

import mujoco

from laserpick.robot.sim.model.geoms import PARTS_BY_NAME, SHELL_GEOM, add_shape
from laserpick.robot.sim.model.names import SCOOTER_BODY


def add_scooter_shell(body: mujoco.MjsBody) -> None:
    """Every shape of the scooter as a massless geom of `body`: the base's planar joints, not
    wheel contacts, carry the scooter."""
    for shape in PARTS_BY_NAME[SCOOTER_BODY].shapes:
        add_shape(body, shape, **SHELL_GEOM)
