"""Where the simulated dual laser pointer's beams land (paper 004, sections 4.3 and 5.2).

The aim lives in `laserpick.robot.pointer`; here the beams are a pair of rays from the model
site `laser/origin`, which rides on the scooter, so the pointer is aimed in `base` and moves
with the scooter.

What the beams hit: `mujoco.mj_ray` against geom groups 0 (surfaces, opaque objects),
1 (robot) and 3 (specular objects), excluding the scooter body's own shell (the user points
past the tiller and basket, not at them). Group 2 (transparent objects) is ignored on
purpose: a 650 nm beam mostly passes through clear plastic and glass, and the spot a camera
sees is where it lands behind, on the table. The depth sensor does not see group 2 either, so
the spot and the depth it is deprojected with agree. The arm is not excluded: a beam that
hits the arm lands on the arm.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from laserpick.description import dims
from laserpick.robot.pointer import DualBeamPointer
from laserpick.robot.sim.model import LASER_SITE, SCOOTER_BODY
from laserpick.robot.sim.objects import GROUP_OPAQUE, GROUP_ROBOT, GROUP_SPECULAR

__all__ = ["LASER_GEOMGROUP", "LaserHit", "SimLaser"]

#: Geom groups a beam can land on (0, 1, 3); group 2, transparent, lets the beam through.
LASER_GEOMGROUP = np.array(
    [int(g in (GROUP_OPAQUE, GROUP_ROBOT, GROUP_SPECULAR)) for g in range(6)], dtype=np.uint8
)


@dataclass(frozen=True)
class LaserHit:
    """Where one beam landed: world point (m), its `base` point (m), and the geom it hit.

    The geom id is simulator ground truth: for bench/ and tests, never for the pipeline.
    """

    point_world: np.ndarray
    point_base: np.ndarray
    geom: int
    distance: float  #: m from the beam's origin


class SimLaser(DualBeamPointer):
    """The pointer on the simulated scooter: its aim, and ray casts of its beams."""

    def __init__(self, model: mujoco.MjModel) -> None:
        site = model.site(LASER_SITE).id
        self._body = model.body(SCOOTER_BODY).id
        if model.site_bodyid[site] != self._body:
            raise ValueError(f"site {LASER_SITE!r} must be fixed to body {SCOOTER_BODY!r}")
        # The site is a direct child of the scooter body, so its local position is in `base`.
        super().__init__(model.site_pos[site])

    def beams(self, data: mujoco.MjData) -> list[tuple[np.ndarray, np.ndarray]]:
        """(origin m, unit direction) in `world` of each lit beam, at the scooter's pose in data.

        Needs `data.xpos`/`data.xmat` current (after `mj_kinematics` or `mj_forward`).
        """
        R = data.xmat[self._body].reshape(3, 3)
        p = data.xpos[self._body]
        return [(p + R @ o, R @ d) for o, d in self.beams_base()]

    def cast_hits(self, model: mujoco.MjModel, data: mujoco.MjData) -> list[LaserHit | None]:
        """Ray-cast each lit beam; a `LaserHit` per beam, None if nothing within range."""
        R = data.xmat[self._body].reshape(3, 3)
        p = data.xpos[self._body]
        geomid = np.array([-1], dtype=np.int32)
        out: list[LaserHit | None] = []
        for origin, direction in self.beams(data):
            dist = mujoco.mj_ray(
                model,
                data,
                origin,
                direction,
                LASER_GEOMGROUP,
                True,  # static geoms too: tables and shelves are static
                self._body,
                geomid,
            )
            if dist < 0 or dist > dims.LASER_MAX_RANGE:
                out.append(None)
                continue
            hit = origin + dist * direction
            out.append(LaserHit(hit, R.T @ (hit - p), int(geomid[0]), float(dist)))
        return out

    def cast(self, model: mujoco.MjModel, data: mujoco.MjData) -> list[np.ndarray | None]:
        """World hit point (m) of each lit beam, None where nothing lies within
        `dims.LASER_MAX_RANGE`. Needs the kinematics in `data` current."""
        return [None if h is None else h.point_world for h in self.cast_hits(model, data)]
