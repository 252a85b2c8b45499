"""The record of one grasp attempt (`Attempt`, JSON-ready), and its stage timings from the
session's job reports.

Units: s for timings, m for grip widths and the lever.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

from laserpick.bench import MOTION_STAGES

#: The progress messages at which one of MOTION_STAGES ends and the next begins.
MOTION_MARKS = (
    "Approaching the object.",
    "Closing the gripper.",
    "Lifting the object.",
    "Holding the object.",
)


@dataclass
class Attempt:
    """The record of one grasp attempt on one marked object (JSON-ready through `as_dict`)."""

    trial: int
    seed: int
    instance: str
    model: str
    surface: str | None
    selection: str
    strategy: str
    task: int = 0  #: which task of the trial: the tries at one object share it
    marks: int = 0  #: marks made (re-marks after a missed dot count)
    #: m the user backed the scooter up within this try, as the robot asked before the arm
    #: moved (`Failure.back_up`), and marked again from there
    backed_up: float = 0.0
    #: m the user re-parked to the scooter's left (negative: right) within this try, as the
    #: robot asked after its planning found only ways its cameras did not see
    #: (`Failure.park_left`), and marked again from there
    parked_aside: float = 0.0
    places: int = 0  #: place marks confirmed (pick and place)
    detected: bool = False  #: the grasp chosen (or executed) was on the marked object
    #: the marked object was lifted and held (in pick-and-drop: and landed in the basket)
    grasped: bool = False
    success: bool = False  #: the attempt's task was done (in the basket, or placed upright)
    failure: str | None = None  #: one of FAILURE_KINDS when it did not succeed
    message: str = ""
    timings: dict[str, float] = field(default_factory=dict)  #: s per STAGES entry
    #: the executed grasp's planned width and the finger gap it closed to (m): an object
    #: held across an edge or turned in the pads closes narrower than planned
    grip: tuple[float, float] | None = None
    #: how far (m) the executed grasp held the object off its centre of mass (`lever`)
    lever: float | None = None

    def fail(self, kind: str, message: str) -> Attempt:
        self.failure, self.message = kind, message
        return self

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def stage_timings(jobs: list[dict[str, Any]], execute_sim: float | None = None) -> dict[str, float]:
    """The STAGES timings of one attempt from its session jobs' reports (the last report of
    a task holds all its stages)."""
    raw: dict[str, float] = {}
    for job in jobs:
        raw.update(job.get("timings", {}))
    out = {
        "acquire_cloud": raw.get("capture", 0.0) + raw.get("fuse", 0.0),
        "detect_laser": raw.get("detect_laser"),
        "segment": raw.get("segment"),
        "detect_grasp": raw.get("detect"),
        "filter": raw.get("filter"),
        "select": raw.get("select"),
        "plan": raw.get("plan"),
        "plan_carry": raw.get("plan_carry"),
        "execute_sim": execute_sim,
    }
    timings = {k: float(v) for k, v in out.items() if v is not None}
    if "fuse" not in raw:
        timings.pop("acquire_cloud")
    timings["attempt_total"] = math.fsum(timings.values())
    return timings


def motion_timings(
    events: list[dict[str, Any]], start: float, released: float | None
) -> dict[str, float]:
    """execute_sim split into MOTION_STAGES (simulated s), from the session's progress
    `events` (each stamped with its "sim_time"): each stage runs from the first message that
    ends the stage before it (MOTION_MARKS; the first from `start`) to the first that ends
    it, the carry to `released` (None: the hand did not let go). A stage whose ends were
    not both seen is left out."""
    at: dict[str, float] = {}
    for e in events:
        message = e.get("message")
        if e.get("name") == "progress" and message in MOTION_MARKS and message not in at:
            at[message] = float(e["sim_time"])
    ends = [start, *(at.get(m) for m in MOTION_MARKS), released]
    return {
        stage: b - a
        for stage, a, b in zip(MOTION_STAGES, ends[:-1], ends[1:], strict=True)
        if a is not None and b is not None and b >= a
    }
