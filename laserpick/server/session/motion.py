"""Driving the base (a dead-man command) and the e-stop with its reset.

Units: m/s and rad/s for the base; seconds.
"""

from __future__ import annotations

import time

from laserpick.server.session.kept_views import KeptViews
from laserpick.server.session.states import AIMABLE, HOLDING_STATES, Actor, TaskState
from laserpick.types import Failure

ESTOP_REASON = "Stopped by the e-stop; the arm stays where it is."
#: What the user hears the moment the hand is found empty while they drive with an object.
FELL_WHILE_DRIVING = (
    "The object fell from the hand while the scooter drove: it lies on the way here. Mark it"
    " again to pick it up."
)


class MotionCommands(KeptViews):
    """Drive and stop."""

    def _init_drive(self) -> None:
        self._drive_token: str | None = None
        self._drive_until = 0.0
        #: (token, seq) of the last numbered drive applied: older ones are dropped.
        self._drive_seq: tuple[str | None, int] = (None, -1)

    @property
    def drive_seq(self) -> tuple[str | None, int]:
        """(token, seq) of the last numbered drive command applied ((None, -1) before one)."""
        return self._drive_seq

    def drive(
        self, actor: Actor, v: float, w: float, duration: float, seq: int | None = None
    ) -> None:
        """Drive the base at v (m/s) and w (rad/s) for at most `duration` s (<= 0.5 s: a
        dead-man; send it again to keep going). What was perceived is stale afterwards.

        `seq` numbers a client's drive commands. Requests on different connections can be
        handled out of order, and a drive overtaking the stop sent after it would move the
        base for another half second; so a numbered command older than the last one applied
        from the same token is dropped."""
        with self._lock:
            self._require(actor, "drive", AIMABLE)
            self._require_motion(actor, "drive")
            if seq is not None:
                last_token, last_seq = self._drive_seq
                if actor.token == last_token and seq <= last_seq:
                    return
                self._drive_seq = (actor.token, seq)
            self._check_hold()
            self.robot.drive(v, w, duration)
            self._drive_token = actor.token
            self._drive_until = time.monotonic() + duration
            if self.state in (TaskState.PERCEIVED, TaskState.GRASPS_READY):
                self._forget_task()
                aiming = self.robot.laser.state.on
                self._set(TaskState.AIMING if aiming else TaskState.IDLE, "Driving.")
            self._capture = None
        self._keep_view()

    def _check_hold(self) -> None:
        """While the user drives with an object in hand, read the gripper at each drive
        command: found empty, the object fell on the way, and the user hears it at once
        (`FELL_WHILE_DRIVING`), where the place mark would have told them only at its
        destination. Traced: a TV remote held 6 cm off its middle turned slowly in the pads
        over a minute of driving, then fell, the grip steady until then."""
        if self.state in HOLDING_STATES and not self.robot.gripper_state().holding:
            self.behaviours.held = None
            self._fail(Failure("execute", FELL_WHILE_DRIVING), TaskState.IDLE)

    def _await_estop(self, latched: bool, timeout: float = 0.5) -> None:
        """Wait (briefly) until the robot has applied an e-stop or its reset, so that the
        next command sees it: commands reach the controller at its next step."""
        end = time.monotonic() + timeout
        while self.estopped != latched and time.monotonic() < end:
            time.sleep(0.001)

    def stop(self, actor: Actor) -> None:
        """E-stop: arm and base halt within one control tick and stay halted until reset."""
        self.robot.stop()
        self._cancel_reason = ESTOP_REASON
        self._cancel.set()
        self._await_estop(True)
        with self._lock:
            self._drive_until = 0.0
            self.message = "E-STOP. Motion is halted until the stop is reset."
            self._emit("estop", message=self.message)
            self._record(actor, "stop", "ok")

    def reset_stop(self, actor: Actor) -> None:
        with self._lock:
            if self.busy:
                raise self._refuse(actor, "stop/reset", "the stopped job is still winding down")
            self.robot.reset_stop()
            self._await_estop(False)
            self.message = "Stop reset."
            self._emit("estop_reset", message=self.message)
            self._record(actor, "stop/reset", "ok")
