"""To the ready pose, folded away beside the scooter (stowed), or standing by between picks."""

from __future__ import annotations

import numpy as np

from laserpick.behaviours.guarded_motion import GuardedMotion
from laserpick.behaviours.outcome import Outcome
from laserpick.description import dims
from laserpick.description.kinematics import tcp_pose
from laserpick.pipeline.collision import CollisionChecker
from laserpick.pipeline.lines import cartesian_line
from laserpick.pipeline.motion_limits import timed
from laserpick.pipeline.rest_poses import at_pose, at_rest

__all__ = ["Stowing"]


class Stowing(GuardedMotion):
    """Going to ready (`go_ready`), stowing (`stow`) and standing by (`stand_by`,
    `go_stand_by`)."""

    def go_ready(self, checker: CollisionChecker | None = None) -> Outcome:
        """To the ready pose, raised in front with the gripper down, or to the high ready
        pose where the checker's cloud fills the ready pose. Without a `checker`
        (no fresh cloud), a hand below the ready height first rises straight up to it, so
        that the move does not sweep it through what stands around it."""
        if checker is None:
            checker = CollisionChecker(np.zeros((0, 3)))
            T = tcp_pose(self.current_q())
            ready_z = tcp_pose(dims.UR5_READY_Q)[2, 3]
            if T[2, 3] < ready_z - 0.01 and T[0, 3] > self.settings.behaviour.workspace_x:
                T[2, 3] = ready_z
                up = cartesian_line(self.current_q(), T, self.settings.motion.cartesian_step)
                # Only when the whole rise is clear: rising into the scooter's camera heads
                # would leave the planner no collision-free start.
                if up is not None and checker.all_clear(up):
                    failure = self.run(timed(up, self.settings.motion), "rising")
                    if failure is not None:
                        return Outcome(failure)
        # Before a surface above the ready hand (the 87 cm counter), the high ready pose.
        high = not checker.clearance_ok(dims.UR5_READY_Q)[0]
        if high and checker.clearance_ok(dims.UR5_HIGH_READY_Q)[0]:
            return self.go_to(dims.UR5_HIGH_READY_Q, checker, "going to ready")
        return self.go_to(dims.UR5_READY_Q, checker, "going to ready", via=(dims.UR5_HIGH_READY_Q,))

    def stow(self, checker: CollisionChecker | None = None) -> Outcome:
        """Fold the arm down beside the scooter, out of the cameras' view: through ready,
        then the way out of the stowed pose backwards (`fold_away`). checker: what stands
        around the arm, when a fresh cloud shows it (see `go_ready`)."""
        if at_pose(self.current_q(), dims.UR5_HOME_Q):
            return Outcome()
        out = self.go_ready(checker)
        if out.failure is not None and out.failure.kind == "ik_plan" and checker is not None:
            # No way to either ready pose (a hand that let go above the 108 cm table, which
            # fills both): fold away from where it is, by a checked search.
            direct = self.fold_away(checker)
            return direct if direct.ok else out
        if not out.ok:
            return out
        return self.fold_away(checker)

    def stand_by(self, checker: CollisionChecker | None = None) -> Outcome:
        """Wait for the next pick folded back beside the scooter (`dims.UR5_STANDBY_Q`):
        out of the cameras' view, and a way to the ready poses that keeps the elbow up.
        Stowed instead where no way there is found. checker: as for `go_ready`. An arm
        already at rest stays there: from the stowed pose (where `fold_away` left a drop that
        found neither ready pose clear) the way to standing by turns the elbow over."""
        if at_rest(self.current_q()):
            return Outcome()
        out = self.go_stand_by(checker)
        if out.failure is not None and out.failure.kind == "ik_plan":
            return self.stow(checker)
        return out

    def go_stand_by(self, checker: CollisionChecker | None = None) -> Outcome:
        """To the pose the arm stands by in (`dims.UR5_STANDBY_Q`), directly or through the
        high ready pose, around what `checker` holds (None: an empty cloud; the scooter
        is always checked)."""
        around = checker or CollisionChecker(np.zeros((0, 3)))
        return self.go_to(dims.UR5_STANDBY_Q, around, "standing by", via=(dims.UR5_HIGH_READY_Q,))

    def fold_away(self, checker: CollisionChecker | None = None) -> Outcome:
        """To the unstow pose, then straight home: the way out of the stowed pose, backwards,
        which keeps the hand beside the scooter (`dims.UR5_UNSTOW_Q`). checker: what stands
        around the arm (none: an empty cloud; the scooter is always checked)."""
        checker = checker or CollisionChecker(np.zeros((0, 3)))
        out = self.go_to(dims.UR5_UNSTOW_Q, checker, "stowing")
        return out if not out.ok else self.go_to(dims.UR5_HOME_Q, checker, "stowing")
