"""surfaces (000 section 5.1): the phone and the pill on each of the twelve surfaces of the
`surfaces` scene, with EL-E's overhead grasp."""

from __future__ import annotations

import numpy as np

from laserpick.bench.attempts import Attempt
from laserpick.bench.driving import drive_to
from laserpick.bench.parking import parking_pose
from laserpick.bench.protocols.trials import Options, protocol_scene, scripted_operator
from laserpick.robot.sim.scenes import Scene, Surface

#: m the user parks behind the `surfaces` scene's start row: there EL-E's objects stand
#: 5-15 cm from the front edges, 20-30 cm in front of the arm's base, where few arm postures
#: reach down; a user soon learns to stop short.
SURFACES_BACK = 0.15


def surfaces(trial: int, seed: int, opt: Options) -> list[Attempt]:
    """One surfaces trial: the objects of each surface in turn, parked before it."""
    scene = protocol_scene("surfaces", seed, opt)
    out = []
    with scripted_operator(scene, trial, seed, opt) as op:
        start = op.base_pose().copy()
        first = scene.surfaces[0]
        for surface in scene.surfaces:
            names = [p.instance for p in scene.placements if p.surface == surface.name]
            if not names:
                continue
            if opt.scene is None:  # the surfaces stand in a row along +y, each set out alike
                goal = start + [-SURFACES_BACK, surface.xy[1] - first.xy[1], 0.0]
            else:
                goal = parking_pose(surface, _local_y(surface, scene, names[0]))
            if np.linalg.norm(op.base_pose()[:2] - goal[:2]) > 0.03:
                drive_to(op, goal, reverse_first=0.6)
            for name in names:
                out.append(op.pick_and_drop(op.new_attempt(name, opt.selection, opt.strategy)))
                if opt.objects is not None and len(out) >= opt.objects:
                    return out
    return out


def _local_y(surface: Surface, scene: Scene, instance: str) -> float:
    """The object's position across the surface's width (m, the surface's frame)."""
    return float(surface.to_local(scene.placement(instance).pos[:2])[1])
