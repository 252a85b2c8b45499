"""The record of one grasp attempt (`Attempt`, JSON-ready), and its stage timings from the
session's job reports.

Units: s for timings, m for grip widths and the lever.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any


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
        "execute_sim": execute_sim,
    }
    timings = {k: float(v) for k, v in out.items() if v is not None}
    if "fuse" not in raw:
        timings.pop("acquire_cloud")
    timings["attempt_total"] = math.fsum(timings.values())
    return timings
