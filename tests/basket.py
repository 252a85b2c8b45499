"""Judging a pick-and-drop that the API or an adapter drove, from the simulator's truth.

The session reports "Dropped in the basket" when it has opened the hand over the basket; it
cannot see whether the object landed inside. Landing is issue 4's grasp success (the
isolation benchmark: about 1 drop in 9 ends beside the basket or falls out while carried).
So these tests require the object to have left its place on the table; an object that did,
but lies outside the basket, is that known physical failure and is reported as xfail with
where it ended, not as a failure of the input path under test.
"""

from __future__ import annotations

import numpy as np
import pytest

from laserpick.robot.scenes import load_scene


def judge_drop(result: dict, scene: str = "isolation") -> None:
    """`result`: the object's `GET /sim/objects` record after the drop."""
    if result["in_basket"]:
        return
    start = next(p.pos for p in load_scene(scene).placements if p.instance == result["name"])
    moved = float(np.linalg.norm(np.subtract(result["position_world"][:2], start[:2])))
    if moved > 0.10:
        pytest.xfail(
            f"issue 4: {result['name']} was carried off and released over the basket but lies"
            f" outside it, at {result['position_world']}"
        )
    raise AssertionError(f"{result['name']} never left the table: {result}")
