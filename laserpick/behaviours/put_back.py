"""The put-back: set what the hand holds back down where it was picked up, the way it came
up, and take the open hand off it: for when no way out holding it is found."""

from __future__ import annotations

from laserpick.behaviours.leave import Leaving
from laserpick.behaviours.messages import NOT_HOLDING
from laserpick.behaviours.outcome import Outcome
from laserpick.description.kinematics import tcp_pose
from laserpick.pipeline.recall import moved
from laserpick.pipeline.surface import on_floor
from laserpick.types import Failure

__all__ = ["PuttingBack"]


class PuttingBack(Leaving):
    """Setting the held object back down where it was picked up (`put_back`)."""

    def put_back(self) -> Outcome:
        """Set what the hand holds back down where it was picked up, and take the open hand
        off it: for when no way out holding it is found. Left holding it, an arm can stand
        in a shelf's gap with the object in hand, and the task ends there; set back down,
        it can be tried again.

        Down the way it came up: every motion run since the hand closed (`WayIn`), backwards,
        guarded as a place's descent is. Nothing else has moved since, so that way is clear.
        An object that slid down in the pads meets its surface early: within `place_above`
        of where it stood it is let go there, eased off it; met higher, it is something
        else, and the hand keeps the object. The open hand then leaves it as it leaves a
        placed object (`leave_object`), unchecked at worst along the way it came in.
        Refused where that way back is not known: a motion was stopped since the grasp, or
        the scooter has moved (`put_back_moved`, `put_back_turned`)."""
        s, b = self.settings.motion, self.settings.behaviour
        held, way = self.held, self.way_in
        if held is None or not self.robot.gripper_state().holding:
            return Outcome(Failure("precondition", NOT_HOLDING))
        if way is None or not way.driven:
            msg = "I can't put the object back: the way the arm came with it is not known."
            return Outcome(Failure("precondition", msg))
        if moved(way.base, self.robot.base_pose(), b.put_back_moved, b.put_back_turned):
            msg = "I can't put the object back: the scooter has moved since the pick."
            return Outcome(Failure("precondition", msg))
        self.progress("Putting the object back where it was.")
        back = way.way_back()
        T_grasp = tcp_pose(back[-1])
        failure = self.descend(back, s.approach_speed, "putting the object back")
        if failure is not None:
            if "unexpected contact" not in failure.message:
                return Outcome(failure, held.grasp)
            early = float(tcp_pose(self.current_q())[2, 3] - T_grasp[2, 3])
            if early > s.place_above:
                msg = (
                    f"Putting the object back, it met something {early * 100:.0f} cm above"
                    " where it stood, so I kept it."
                )
                return Outcome(Failure("execute", msg), held.grasp)
            self.ease_off_surface()
        self.release()
        # Out along the approach, as far above the way in as the hand stands above the grasp.
        T_out = tcp_pose(way.approach[0])
        T_out[:3, 3] += tcp_pose(self.current_q())[:3, 3] - T_grasp[:3, 3]
        stood_on = float(T_grasp[2, 3]) - held.height_above_support
        failure = self.leave_object(T_out, held.surroundings, on_floor=on_floor(stood_on))
        if failure is not None:
            return Outcome(failure, held.grasp)
        self.progress("Put back.")
        return Outcome(None, held.grasp)
