"""Judging a pick-and-drop that the API or an adapter drove, from the simulator's truth.

The session reports "Dropped in the basket" when it has opened the hand over the basket; it
cannot see whether the object landed inside. Landing is the isolation benchmark's grasp
success (004 section 8.1); a drop may slip out while lifted or carried, and the session then
says the object "fell from the hand while it was carried".
So these tests require the object to have left its place on the table; an object that did,
but lies outside the basket, is that known physical failure and is reported as xfail with
where it ended, not as a failure of the input path under test.
"""

from __future__ import annotations

import numpy as np
import pytest

from laserpick.robot.sim.scenes import load_scene

#: How the session says the object fell from the hand on the way to the basket.
LOST_IN_CARRY = "fell from the hand while it was carried"


def lost_in_carry(reported: str | dict | None) -> bool:
    """Whether the session reported the object falling from the hand while carried: in a
    failure record, a state message or an adapter's printed output."""
    text = reported.get("message", "") if isinstance(reported, dict) else (reported or "")
    return LOST_IN_CARRY in text


def judge_drop(result: dict, lost: bool = False, scene: str = "isolation") -> None:
    """`result`: the object's `GET /sim/objects` record after the drop. lost: the session
    reported that the object fell from the hand while carried, which, like a release beside
    the basket, is the drop's known physical failure once the object has left the table."""
    if result["in_basket"]:
        return
    start = next(p.pos for p in load_scene(scene).placements if p.instance == result["name"])
    moved = float(np.linalg.norm(np.subtract(result["position_world"][:2], start[:2])))
    if moved > 0.10:
        how = "fell from the hand while carried" if lost else "was released over the basket"
        pytest.xfail(
            f"known drop failure: {result['name']} was carried off and {how}, and lies outside the"
            f" basket, at {result['position_world']}"
        )
    raise AssertionError(f"{result['name']} never left the table: {result}")
