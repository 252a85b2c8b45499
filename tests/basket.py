"""Judging a pick-and-drop that the API or an adapter drove, from the simulator's truth.

The session reports "Dropped in the basket" when it has opened the hand over the basket; it
cannot see whether the object landed inside. The simulator can: a pick-and-drop test passes
only when the object lies in the basket. The tests pick the isolation scene's mug, which the
isolation benchmark lands in the basket on every attempt (bench-results/isolation.md).
"""

from __future__ import annotations

import numpy as np

from laserpick.robot.sim.scenes import load_scene


def assert_in_basket(result: dict, scene: str = "isolation") -> None:
    """`result`: the object's `GET /sim/objects` record after the drop. AssertionError unless
    it lies in the basket, saying where it ended (world, m) and how far it moved from where
    it stood in `scene`."""
    if result["in_basket"]:
        return
    start = next(p.pos for p in load_scene(scene).placements if p.instance == result["name"])
    moved = float(np.linalg.norm(np.subtract(result["position_world"][:2], start[:2])))
    where = "never left the table" if moved <= 0.10 else "is not in the basket"
    raise AssertionError(
        f"{result['name']} {where}: it lies at {result['position_world']} (world, m),"
        f" {moved * 100:.1f} cm from where it stood; upright {result['upright']:.2f}"
    )
