"""The operator session: the one task state machine behind every input.

Console buttons, REST calls, the switch and joystick adapters and the benchmarks all call the
methods of one `Session`; nothing else changes task state (rule 2 of the design). The states
and which may follow which are in `states`. The session works on any `Robot`
(`laserpick.robot.interface`) and never reaches behind it.

Long work (perception, grasp detection, every arm motion) runs on one worker thread (`core`),
so no caller waits on it and the API stays responsive; views on the way are captured on a
thread of their own (`kept_views`), and clicked marks worked out ahead of their confirm on
another (`foresight`). A failure returns to a safe resting state with a typed `Failure`
(`retreat`); cancel aborts the job, halts the arm and retreats; the e-stop halts at once and
latches. The watchdog halts motion commanded by a lease holder who goes silent (`watchdog`).

Frames: points in `base` (m) unless a method says `world`; angles in radians.
"""

from laserpick.server.session.captures import CAPTURE_MAX_AGE, CamerasUnavailable, Capture
from laserpick.server.session.core import Findings
from laserpick.server.session.foresight import Foreseen
from laserpick.server.session.motion import ESTOP_REASON, FELL_WHILE_DRIVING
from laserpick.server.session.retreat import HELD_MOVED, HELD_TURNED, PLACED_NOT_STANDING, PUT_BACK
from laserpick.server.session.session import Session
from laserpick.server.session.states import (
    AIMABLE,
    HOLDING_STATES,
    RESTING_STATES,
    SYSTEM,
    TRANSITIONS,
    Actor,
    Conflict,
    IllegalTransition,
    Mode,
    Selection,
    Source,
    StrategyName,
    TaskState,
    check_transition,
)
from laserpick.server.session.status import grasp_summary
from laserpick.server.session.watchdog import SILENT_REASON, STALLED_REASON, WATCHDOG_TICK

__all__ = [
    "AIMABLE",
    "CAPTURE_MAX_AGE",
    "ESTOP_REASON",
    "FELL_WHILE_DRIVING",
    "HELD_MOVED",
    "HELD_TURNED",
    "HOLDING_STATES",
    "PLACED_NOT_STANDING",
    "PUT_BACK",
    "RESTING_STATES",
    "SILENT_REASON",
    "STALLED_REASON",
    "SYSTEM",
    "TRANSITIONS",
    "WATCHDOG_TICK",
    "Actor",
    "CamerasUnavailable",
    "Capture",
    "Conflict",
    "Findings",
    "Foreseen",
    "IllegalTransition",
    "Mode",
    "Selection",
    "Session",
    "Source",
    "StrategyName",
    "TaskState",
    "check_transition",
    "grasp_summary",
]
