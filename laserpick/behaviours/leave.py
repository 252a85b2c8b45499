"""Letting go of what the hand set down, and taking the open hand off it: eased off the
surface first, then drawn back along the approach or risen straight up, freeing a pad that
something still leans on or presses."""

from __future__ import annotations

import numpy as np

from laserpick.behaviours.guarded_motion import nearest_on
from laserpick.behaviours.hand import pad_force, peak_pad_force
from laserpick.behaviours.withdraw import Withdrawing
from laserpick.description.kinematics import tcp_pose
from laserpick.pipeline.collision import CollisionChecker
from laserpick.pipeline.lines import cartesian_line
from laserpick.pipeline.motion_limits import timed
from laserpick.transforms import turn_between
from laserpick.types import Failure

__all__ = ["Leaving"]


class Leaving(Withdrawing):
    """Easing off the surface (`ease_off_surface`) and leaving what the hand let go of
    (`leave_object`)."""

    def ease_off_surface(self) -> None:
        """Rise `place_ease` straight up from where a guarded descent felt the surface under
        what the hand holds: let go there, with no drop to roll from, but not pressed into
        the surface (`MotionSettings.place_ease`)."""
        eased = tcp_pose(self.current_q())
        eased[2, 3] += self.settings.motion.place_ease
        self.rise_straight(eased, "easing off the surface")

    def leave_object(
        self, T_above: np.ndarray, checker: CollisionChecker, *, on_floor: bool = False
    ) -> Failure | None:
        """Take the open hand off what it has just set down: drawn back along its approach
        if that way is clear of `checker` (which leaves the object out: the fingers start
        about it), else straight up to the TCP pose T_above (4, 4, `base`), the way it came
        down. Risen straight up from the side, the hand stays about a tall box's top, and no
        way to ready is found.

        A hand within `leave_level` of level with a clear way back is first lowered
        `leave_drop` (`_lower_open_hand`), so that a pad under a lip of the object leaves
        it. Only with a clear way back: lowered first, a hand with none can find one lower,
        close along the surface, from where no way to ready is found. A hand whose open
        pads still press something (`pads_clear`) is lowered first from any approach: a
        finger that drags a mug by its handle as it opens lifts it 9 cm by it, and lowered
        first, comes free. Pads that still feel anything then are eased off it sideways
        (`_slide_pads_off`), and the hand leaves from there: risen straight up, it goes up
        beside the way it came down, by as much as it was eased (at most `leave_shift`),
        unchecked as that way is.

        on_floor: it was let go on the floor, which is then its support, as on the way down
        (`place_poses`): held to the floor's margin, a hand that let go of a tall box 6 cm
        above the floor found no way back, rose with its fingers still about the box, and
        the way to stand by dragged the box 60 cm. Drawn back off it low, the hand still
        stands within the floor's margin, where no way to stand by can start: it then rises
        as high as T_above, where that way up is clear."""
        if on_floor:
            checker = checker.floor_as_support()
        start = tcp_pose(self.current_q())
        approach = start[:3, 2]
        back = self.withdrawal_path(approach, checker, level=False)
        level = abs(approach[2]) < np.sin(self.settings.behaviour.leave_level)
        pressed = self._pads_still_pressed()
        if pressed or (back is not None and level):
            self._lower_open_hand(start)
            back = self.withdrawal_path(approach, checker, level=False)
        eased = np.zeros(3)
        if pressed:  # even if lowered they feel nothing: what leaned on a pad still leans
            eased = self._slide_pads_off(checker)
            back = self.withdrawal_path(approach, checker, level=False)
        if back is None:
            T_up = T_above.copy()
            T_up[:3, 3] += eased
            self.rise_straight(T_up, "rising from the object")
            return None
        failure = self._draw_back_by_touch(back, approach, checker)
        if failure is None and on_floor:
            self._rise_to(float(T_above[2, 3]), checker)
        return failure

    def _draw_back_by_touch(
        self, back: np.ndarray, approach: np.ndarray, checker: CollisionChecker
    ) -> Failure | None:
        """Draw the open hand back along `back` (N, 6) rad, guarded at `leave_nudge` over
        what the pads bear: where a pad brushes what it let go of, the hand stops, eases
        the pads off it sideways (`_slide_pads_off`) and draws back from there along its
        `approach` (unit, `base`), clear of `checker`. After `leave_touches` such stops it
        draws back unguarded. A spice jar let go 1 cm off the hand's middle, its top
        between the pads, was dragged over by a pad's 0.04-1.2 N as the hand drew back."""
        b = self.settings.behaviour
        for _ in range(b.leave_touches):
            guard = pad_force(self.robot) + b.leave_nudge
            failure = self.run_withdrawal(back, guard=guard)
            if failure is None or "unexpected contact" not in failure.message:
                return failure
            self._slide_pads_off(checker)
            again = self.withdrawal_path(approach, checker, level=False)
            if again is None:  # eased where no way back is clear: on along the first one
                q = self.current_q()
                rest = back[nearest_on(back, q) + 1 :]
                return self.run_withdrawal(np.vstack([q, rest])) if len(rest) else None
            back = again
        return self.run_withdrawal(back)

    def _rise_to(self, height: float, checker: CollisionChecker) -> None:
        """Rise straight up to `height` (m, `base` z of the TCP), at the approach speed, if
        the way up keeps the clearance from `checker` that the hand starts with."""
        s = self.settings.motion
        q = self.current_q()
        T = tcp_pose(q)
        kept = checker.clearance_kept(q)
        if kept is None or T[2, 3] >= height:
            return
        T[2, 3] = height
        up = cartesian_line(q, T, s.cartesian_step)
        if up is not None and checker.all_clear(up, margin=kept):
            self.run(timed(up, s, tcp_speed=s.approach_speed), "rising off the floor")

    def free_the_pads(self, checker: CollisionChecker) -> bool:
        """Where the open hand's pads still press what it let go of (`pads_clear`), lower
        it `leave_drop` (a pad under a lip leaves it) and ease the pads off sideways
        (`_slide_pads_off`), so that the hand can rise without it; where they still press
        then, tip it off them (`_tip_off`, clear of `checker`). Say whether they were
        pressed. Over the basket, a spray bottle wedged against a pad at 27 N was lifted 4
        cm by the rising hand and flung out on the way to ready. The easing goes only as far
        as the arm keeps its clearance from `checker` (`_arm_keeps_clear`)."""
        if not self._pads_still_pressed():
            return False
        self._lower_open_hand(tcp_pose(self.current_q()))
        self._slide_pads_off(checker)
        if self._pads_still_pressed():
            self._tip_off(checker)
        return True

    def _tip_off(self, checker: CollisionChecker) -> None:
        """Turn the open hand about its TCP toward pointing straight down, as far as that
        turn is clear of `checker`, guarded, and back: what hangs from a tilted pad's edge
        slides off it. A pill bottle let go from a hand tilted 30 deg hung from the lower
        pad by its cap's lip, and eased sideways, went with the pad; turned 14 deg (upright,
        the wrist would have come within the keep-out ahead of the rider's hands) and back,
        the hand let it fall. Turned back, it leaves from the posture it let go in, which
        the carry's search found clear."""
        s = self.settings.motion
        start = self.current_q()
        T = tcp_pose(start)
        upright = T.copy()
        upright[:3, :3] = turn_between(T[:3, 2], np.array([0.0, 0.0, -1.0])) @ T[:3, :3]
        turn = cartesian_line(start, upright, s.cartesian_step / 5)
        turn = None if turn is None else _clear_start(turn, checker.clearance_ok(turn))
        if turn is None:
            return
        guard = pad_force(self.robot) + s.place_contact_force
        for path in (turn, turn[::-1]):
            timing = timed(path, s, tcp_speed=self.settings.behaviour.leave_speed)
            if self.run(timing.guarded(guard), "tipping it off"):
                return

    def _pads_still_pressed(self) -> bool:
        """Whether the open hand's pads still press what they let go of (or anything): more
        than `pads_clear` over `leave_settle`."""
        b = self.settings.behaviour
        return peak_pad_force(self.robot, b.leave_settle, b.feel_period) > b.pads_clear

    def _slide_pads_off(self, checker: CollisionChecker) -> np.ndarray:
        """Ease the open hand sideways off what its pads touched, and say how far it moved
        (3,) (m, `base`).

        Along the closing axis by `leave_shift`, one way and, where the pads still feel
        something there, the other, slowly and guarded at `leave_nudge` over what the pads
        bear: the gripper feels only the pads' summed force, not which pad, so the way into
        the object is found by touch, and stopped before it pushes the object over. Each way
        only as far as the arm keeps its clearance from `checker` (`_arm_keeps_clear`)."""
        s, b = self.settings.motion, self.settings.behaviour
        start = tcp_pose(self.current_q())
        for sign in (1.0, -1.0):
            T = start.copy()
            T[:3, 3] += sign * b.leave_shift * start[:3, 1]
            path = cartesian_line(self.current_q(), T, s.cartesian_step / 5)
            path = None if path is None else self._arm_keeps_clear(path, checker)
            if path is None:
                continue
            aside = timed(path, s, tcp_speed=b.leave_speed)
            guard = pad_force(self.robot) + b.leave_nudge
            # Stopped at the guard is how the way into the object is found: not a failure.
            self.run(aside.guarded(guard), "easing the pads off")
            if not self._pads_still_pressed():
                break
        # Touching either way, it leaves from where it is: pushed back between, unguarded,
        # the hand pushes what followed the pad.
        return tcp_pose(self.current_q())[:3, 3] - start[:3, 3]

    def _lower_open_hand(self, start: np.ndarray) -> None:
        """Lower the open hand `leave_drop` straight down from TCP pose `start` (4, 4,
        `base`), guarded as the place's descent: a pad whose top edge is under a lip of what
        it let go of leaves it, rather than lifting it by it on the way out. A hand that
        comes down on something instead (a shoulder of the object, the surface) goes back up
        to `start`: drawn back from there, a finger drags what it met."""
        s, b = self.settings.motion, self.settings.behaviour
        T = start.copy()
        T[2, 3] -= b.leave_drop
        down = cartesian_line(self.current_q(), T, s.cartesian_step / 5)
        if down is None:
            return
        felt = pad_force(self.robot)
        met = self.descend(down, b.leave_speed, "freeing the fingers", felt=felt)
        self.robot.sleep(b.leave_settle)  # the servos lag the trajectory's clock
        if met is not None:
            self.rise_straight(start, "rising off what the fingers met")

    @staticmethod
    def _arm_keeps_clear(path: np.ndarray, checker: CollisionChecker) -> np.ndarray | None:
        """The part of `path` (N, 6) rad from its start along which the arm, the hand left
        out (the open hand starts about what it let go of), keeps the clearance from
        `checker` it starts with; None where that is no move. Eased 1 cm sideways over the
        basket, the arm came within the margin of a sensor post, and no way left from
        there. An arm that already touches something (no clearance kept) is not held."""
        kept = checker.clearance_kept(path[0], hand=False)
        if kept is None:
            return path
        return _clear_start(path, checker.clearance_ok(path, hand=False, margin=kept))


def _clear_start(path: np.ndarray, clear: np.ndarray) -> np.ndarray | None:
    """The part of `path` (N, 6) rad before its first configuration that `clear` (N,) marks
    blocked; None where that is no move (fewer than two configurations)."""
    blocked = np.flatnonzero(~clear)
    start = path[: blocked[0]] if len(blocked) else path
    return start if len(start) >= 2 else None
