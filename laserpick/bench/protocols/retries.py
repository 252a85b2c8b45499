"""When the scripted user tries an object again (in-situ and pick-place), and where they park
for each try."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from laserpick.bench.attempts import Attempt
from laserpick.bench.parking import go_to_object
from laserpick.bench.picking import ScriptedOperator
from laserpick.robot.sim.scenes import Scene

#: Tries per object in the in-situ and pick-place protocols (004 section 8.2 retried until
#: retrieved; in section 8.3 a task could take more than one pick-and-place attempt, 150
#: grasp and 104 place attempts for 84 tasks in Table 5), and place marks per pick.
MAX_TRIES = 3
#: An object still within this (m) of where it stood, across and in height, can be tried
#: again: a failed attempt left it in place, or only nudged it.
STILL_THERE = (0.05, 0.02)
#: m the user parks farther back for each try after the arm could not take the object (an
#: ik_plan failure), as a person told that the arm cannot reach moves the scooter: under a
#: shelf's board the arm needs room to come in level.
RETRY_BACK = 0.10


def next_try(rec: Attempt, back: float, across: float) -> tuple[float, float]:
    """Where the user parks for the next try after `rec` (back, across: m, as in
    `go_to_object`): where the arm could not take the object, farther back (RETRY_BACK).
    Where the robot asked to park to a side, the user did so within the try
    (`TaskSpot.park_left`)."""
    if rec.failure != "ik_plan":
        return back, across
    return back + RETRY_BACK, across


@dataclass
class TaskSpot:
    """Where the user parks for one task's tries: `back` m farther back than at first and
    `across` m to the arm's left (as in `go_to_object`). Its `back_up` is how the user backs
    up when the robot asks (the protocol hands it to `ScriptedOperator.back_up`)."""

    op: ScriptedOperator
    scene: Scene
    instance: str
    back: float = 0.0
    across: float = 0.0

    def go(self) -> bool:
        """Drive there; whether the user parked."""
        return go_to_object(self.op, self.scene, self.instance, self.back, self.across)

    def back_up(self, distance: float) -> bool:
        """Park `distance` m farther back, as the robot asked; whether the user parked."""
        self.back += distance
        return self.go()

    def park_left(self, distance: float) -> bool:
        """Park `distance` m farther to the scooter's left (negative: right), as the robot
        asked: the object then lies that much farther to the arm's right. Whether the user
        parked."""
        self.across -= distance
        return self.go()

    def after(self, rec: Attempt) -> None:
        """Where the next try parks after `rec` (`next_try`)."""
        self.back, self.across = next_try(rec, self.back, self.across)


def still_there(op: ScriptedOperator, name: str, stood: np.ndarray) -> bool:
    """Whether the object is still where it stood (m, `world`), within STILL_THERE: not
    fallen, carried off or taken out, so the user can try it again."""
    now = op.referee.world_position(name)
    across, height = STILL_THERE
    return bool(np.linalg.norm(now[:2] - stood[:2]) < across and abs(now[2] - stood[2]) < height)
