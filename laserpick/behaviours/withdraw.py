"""Drawing the hand back out along its approach: after a lift from the side, level out of a
shelf's gap; after a place, off the object it let go of."""

from __future__ import annotations

import itertools

import numpy as np

from laserpick.behaviours.guarded_motion import GuardedMotion
from laserpick.description.kinematics import tcp_pose
from laserpick.pipeline.collision import CollisionChecker
from laserpick.pipeline.lines import cartesian_line
from laserpick.pipeline.motion_limits import timed
from laserpick.transforms import rotz
from laserpick.types import Failure

__all__ = ["Withdrawing"]


class Withdrawing(GuardedMotion):
    """The hand drawn back along its approach: the way found (`withdrawal_path`), then run
    (`run_withdrawal`)."""

    def run_withdrawal(
        self, path: np.ndarray, speed: float | None = None, *, guard: float | None = None
    ) -> Failure | None:
        """Run a way back (N, 6) that `withdrawal_path` found, at TCP `speed` (m/s; default:
        the approach's); with a `guard` (N), stopped where the hand feels more than it (the
        failure then says "unexpected contact")."""
        s = self.settings.motion
        speed = s.approach_speed if speed is None else speed
        return self.run(timed(path, s, tcp_speed=speed).guarded(guard), "drawing back")

    def withdrawal_path(
        self,
        approach: np.ndarray,
        checker: CollisionChecker,
        payload: np.ndarray | None = None,
        *,
        level: bool = True,
        q_from: np.ndarray | None = None,
    ) -> np.ndarray | None:
        """The joint path (N, 6) that draws the hand straight back along its `approach`
        (unit, `base`) by `approach_distance` (or half that where the whole is not clear of
        `checker`, with `payload` in the hand), from q_from (6,) rad (default: where the arm
        stands); None where none is clear.

        level: after a lift from the side, back level, out of a shelf's gap before the arm
        swings anywhere (a swing planned from inside a shelf finds no way out, or meets the
        board above): along the approach, else turned by each of `withdraw_turns`; a grasp
        from above (within `withdraw_steep` of the vertical) leaves by rising instead.
        Not level: after a place, back along the approach itself, the fingers sliding off
        the object they let go of the way they came (drawn back level from 43 deg above the
        side, they drag a plush toy's head over).

        A hand that starts within the checker's margin of something still leaves, if the
        whole way keeps the clearance it starts with: half the margin, or none short of
        touching. The arm keeps its own, lest the elbow end where no way home can start."""
        b = self.settings.behaviour
        across = float(np.hypot(*approach[:2]))
        if level and across < np.sin(b.withdraw_steep):
            return None
        s = self.settings.motion
        backs = (
            [rotz(turn) @ -np.append(approach[:2] / across, 0.0) for turn in b.withdraw_turns]
            if level
            else [-approach]
        )
        q = self.current_q() if q_from is None else q_from
        margins = (checker.margin, checker.margin / 2, 0.0)
        margin = next(
            (m for m in margins if checker.clearance_ok(q, payload=payload, margin=m)[0]), None
        )
        if margin is None:  # touching already: no level way out is known to be clear
            return None
        # The arm's own: the largest margin it starts clear of, never less than the hand's.
        arm_margin = next(
            m for m in margins if m <= margin or checker.clearance_ok(q, hand=False, margin=m)[0]
        )
        here = tcp_pose(q)
        for back, distance in itertools.product(
            backs, (s.approach_distance, s.approach_distance / 2)
        ):
            T = here.copy()
            T[:3, 3] += distance * back
            path = cartesian_line(q, T, s.cartesian_step)
            if (
                path is None
                or not checker.all_clear(path, payload=payload, margin=margin)
                or not checker.all_clear(path, hand=False, margin=arm_margin)
            ):
                continue
            return path
        return None
