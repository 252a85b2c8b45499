"""How a job ends on the arm: stand by and rest after a drop or a place (checking first that
a placed object still stands), and the retreat after a failure, a cancel or the e-stop, which
keeps an object in the hand, tucks it in, or puts it back where it was picked up.

Frames: points in `base` (m).
"""

from __future__ import annotations

import math
from dataclasses import replace

from laserpick.behaviours import Outcome, wait_for_gripper
from laserpick.description.kinematics import tcp_pose
from laserpick.pipeline.collision import CollisionChecker, not_carried, self_filter
from laserpick.pipeline.recall import moved, moved_points
from laserpick.pipeline.rest_poses import at_rest
from laserpick.pipeline.surface import still_standing
from laserpick.robot.interface import DEADMAN_STOP
from laserpick.server.session.captures import Capture
from laserpick.server.session.kept_views import KeptViews
from laserpick.server.session.motion import ESTOP_REASON
from laserpick.server.session.states import TaskState
from laserpick.server.session.watchdog import SILENT_REASON, STALLED_REASON, WATCHDOG_TICK
from laserpick.types import Failure

#: What the user hears when a place's post-condition fails (`_placed_object_gone`).
PLACED_NOT_STANDING = (
    "I set the object down, but I no longer see it where I let go of it: it may have fallen"
    " off the spot. Mark it again to pick it up."
)
#: Said after a failure for which the arm found no way out holding the object.
PUT_BACK = "I found no way out holding it, so I set it back down where it was."
#: The scooter has moved since the pick once the odometry says this far (m) or this turn
#: (rad): the planner's clearance. What stood around the held object is then taken anew.
HELD_MOVED = 0.01
HELD_TURNED = math.radians(1.0)
#: Why a job may end after which the arm stays where it stopped: the e-stop and the dead-man.
_STAYS = (ESTOP_REASON, SILENT_REASON, STALLED_REASON)


class Retreat(KeptViews):
    """The end of a job on the arm: stand by, or retreat, and rest."""

    def _retake_held_surroundings(self) -> None:
        """Where the scooter has moved since the pick with the object in hand, take anew what
        stands around the hand (`Held.surroundings`, which the tuck and the drop are planned
        around): the pick's stand where they stood before the scooter then, and the tuck
        must go around what stands before the hand now. A capture here, with the views of
        the drive (`surroundings`), less the held object's own points; where the cameras
        fail, the pick's, carried here by the odometry."""
        held, now = self.behaviours.held, self.robot.base_pose()
        if held is None or held.seen_from is None:
            return
        if not moved(held.seen_from, now, HELD_MOVED, HELD_TURNED):
            return
        q = self.robot.joint_state().q
        around = self.surroundings(self.capture_or_none())
        if around is None:
            pts = moved_points(held.surroundings.points, held.seen_from, now)
            around = CollisionChecker(pts, margin=held.surroundings.margin, filtered=True)
        else:
            around = around.without(~not_carried(around.points, held.at(tcp_pose(q))))
        self.behaviours.held = replace(held, surroundings=around, seen_from=now)

    def stand_by_and_rest(self, message: str, placed: Outcome | None = None) -> None:
        """Stand by for the next pick (`Behaviours.stand_by`: stowed where no way there is
        found) and rest, saying `message`; after a place (`placed`), first check from the
        same capture that the object still stands where it was let go. A job's last step: it
        moves the arm, so call it only while no job runs."""
        capture = self.capture_or_none()
        gone = (
            placed is not None and capture is not None and self._placed_object_gone(capture, placed)
        )
        around = self.surroundings(capture)
        out = self.behaviours.stand_by(around)
        with self._lock:
            self._forget_task()
            if out.failure is not None:  # the arm not home is said first; a fall with it
                said = out.failure.message + (f" {PLACED_NOT_STANDING}" if gone else "")
                self._fail(Failure(out.failure.kind, said), TaskState.IDLE)
            elif gone:
                self._fail(Failure("execute", PLACED_NOT_STANDING), TaskState.IDLE)
            else:
                self._set(TaskState.IDLE, f"{message} Ready.")

    def _placed_object_gone(self, capture: Capture, placed: Outcome) -> bool:
        """Whether the cameras see the surface bare where the place let the object go: it
        fell off the spot, or the opened hand took it along (an object clinging to a pad
        rises with it). Nothing is said where they cannot tell."""
        if placed.standing is None or placed.spot is None:
            return False
        points = capture.cloud.points
        points = points[self_filter(points, self.robot.joint_state().q)]
        return still_standing(points, placed.standing, float(placed.spot[2])) is False

    def _retreat(self, failure: Failure, tucked: Outcome | None = None) -> None:
        """After a failed or cancelled step: retreat to a safe pose and rest. An object in the
        hand is kept (never dropped from height): the arm tucks it in and the session holds;
        where no way to tuck it in is found, it is put back where it was picked up, if the
        arm can go back down the way it came (`Behaviours.put_back`). The empty arm then
        stands by for the next try (`Behaviours.stand_by`: stowed where no way there is
        found; an arm still at rest, stowed or standing by, stays there).
        After the e-stop or the dead-man the arm stays where it stopped.
        tucked: how the tuck that failed just now went (not tried again)."""
        if DEADMAN_STOP in failure.message:
            self._cancel.wait(4 * WATCHDOG_TICK)  # the watchdog ends the job, saying why
        cancelled = self._cancel.is_set()
        if self.estopped or (cancelled and self._cancel_reason in _STAYS):
            # After the e-stop or the dead-man nothing moves until the operator commands it.
            reason = ESTOP_REASON if self.estopped else self._cancel_reason
            with self._lock:
                self._fail(Failure("execute", reason), self._resting_state())
            return
        if cancelled:
            failure = Failure("execute", self._cancel_reason)
        self._cancel.clear()  # the retreat itself must be allowed to move
        b = self.behaviours
        if b.held is not None and self.robot.gripper_state().holding:
            if tucked is None:
                self._progress("Tucking in what the hand holds.")
                self._retake_held_surroundings()
                tucked = b.tuck()
            if tucked.failure is not None and tucked.failure.kind == "ik_plan":
                put = b.put_back()
                if put.ok:
                    failure = Failure(failure.kind, f"{failure.message} {PUT_BACK}")
                elif put.failure is not None and put.failure.kind != "precondition":
                    # Tried and stopped on the way down: the user hears why it is still held.
                    failure = Failure(failure.kind, f"{failure.message} {put.failure.message}")
        if b.held is None or not self.robot.gripper_state().holding:
            if self.robot.gripper_state().closed:
                self.robot.gripper(False)
                wait_for_gripper(self.robot)
            b.held = None
            if not at_rest(self.robot.joint_state().q):  # a pick that found no way: stays
                self._progress("Returning the arm.")
                b.stand_by(self.surroundings(self.capture_or_none()))
        with self._lock:
            if cancelled:
                self._cancel.set()  # so the journal records the job as cancelled
            state = self._resting_state()
            if state == TaskState.IDLE:
                self._forget_task()
            self._fail(failure, state)

    def _resting_state(self) -> TaskState:
        holding = self.behaviours.held is not None and self.robot.gripper_state().holding
        return TaskState.HOLDING if holding else TaskState.IDLE
