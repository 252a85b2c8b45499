"""The place (004 section 7.3, EL-E 000 section 4.5): carry what the hand holds over a
place mark, lower it until the surface is felt, let go, leave it, and stand by around it."""

from __future__ import annotations

import logging
import time
from dataclasses import replace

import numpy as np

from laserpick.behaviours.carry import Carrying, holding_pose
from laserpick.behaviours.held import Held
from laserpick.behaviours.leave import Leaving
from laserpick.behaviours.messages import NOT_HOLDING
from laserpick.behaviours.outcome import SEARCH, Outcome
from laserpick.behaviours.place_poses import PlacePoses, front_wall, place_poses
from laserpick.behaviours.stow import Stowing
from laserpick.description import dims
from laserpick.description.kinematics import tcp_pose
from laserpick.pipeline.cloud import fuse
from laserpick.pipeline.collision import CollisionChecker, not_carried, obstacle_mask
from laserpick.pipeline.surface import on_floor, place_target
from laserpick.types import Failure, FusedCloud

__all__ = ["Placing"]

log = logging.getLogger(__name__)


class Placing(Carrying, Leaving, Stowing):
    """The place at a mark (`place`)."""

    def place(self, cloud: FusedCloud, mark: np.ndarray) -> Outcome:
        """Set what the hand holds down at a place mark (004 section 7.3, EL-E 000 4.5).

        cloud: a fresh capture's fused cloud (the held object and the arm in it are ignored);
        mark: the place mark (m, `base`). The mark must be on a flat surface (moved back from
        its front edge if it is too close). The object goes down with the grasp's orientation
        kept, so that it stands as it stood, its grasp height above the surface: straight
        down from 10 cm above until the surface is felt (`place_contact_force`), eased
        `place_ease` back up, then the hand opens and leaves it (drawn back along its
        approach where that way is clear, else straight up), and the arm stands by for the
        next pick around the object where it now stands (stowed where no way there is
        found). Felt more than `place_above` early, it is something on the surface: the hand
        keeps the object and rises. Nothing felt by `place_below` under the rest: the hand
        keeps it. The outcome's timings give the carry's planning (`CARRY_PLANNING`: the
        place poses and the path, wall-clock s).
        """
        s = self.settings.motion
        if self.held is None or not self.robot.gripper_state().holding:
            self.held = None
            return Outcome(Failure("precondition", NOT_HOLDING))
        held = self.held
        spot = place_target(cloud, mark, self.settings.perception)
        if isinstance(spot, Failure):
            return Outcome(Failure("precondition", f"I can't place there: {spot.message}."))
        q_now = self.current_q()
        t0 = time.perf_counter()
        obstacles = cloud.points[not_carried(cloud.points, held.at(tcp_pose(q_now)))]
        checker = CollisionChecker(obstacles, margin=s.clearance, q_self=q_now)
        poses = place_poses(held, spot, checker, self.settings)
        planning = time.perf_counter() - t0
        if isinstance(poses, Failure):
            return Outcome(poses).planned_for(planning)
        self.progress("Carrying the object to the place mark.")
        out = self._carry_over_spot(poses.q_above, checker, spot, held)
        planning += out.timings[SEARCH]
        if not out.ok:
            return out.planned_for(planning)
        lost = self.dropped_on_the_way("the place")
        if lost is not None:
            return lost.planned_for(planning)
        failure = self._lower_and_let_go(poses)
        if failure is not None:
            return Outcome(failure).planned_for(planning)
        T_release = tcp_pose(self.current_q())
        failure = self.leave_object(poses.T_above, checker, on_floor=on_floor(float(spot[2])))
        if failure is not None:
            return Outcome(failure, held.grasp, spot=spot).planned_for(planning)
        placed = self._stand_by_around_placed(held, T_release, checker, spot)
        return placed.planned_for(planning)

    def _carry_over_spot(
        self, q_above: np.ndarray, checker: CollisionChecker, spot: np.ndarray, held: Held
    ) -> Outcome:
        """Carry what the hand holds to q_above (6,) rad, over the place `spot` (m, `base`),
        around `checker`, first also around a wall under the spot's surface's seen front
        (`surface_front`), then without it; its timings give the searches' seconds
        (`SEARCH`). An object that hangs below the hand, carried up to a counter around what
        the cameras saw, is swept through the counter's unseen front, and turns in the
        pads."""
        front = front_wall(checker.points, float(spot[2]))
        tries = [checker.with_points(front), checker] if len(front) else [checker]  # floor: none
        turns, searched = self.settings.behaviour.hold_turns, 0.0
        for around in tries:
            out = self.go_to(
                q_above,
                around,
                "carrying to the place",
                via=(holding_pose(dims.UR5_HIGH_READY_Q, around, held.points_tcp, turns),),
                payload=held.points_tcp,
            )
            searched += out.timings[SEARCH]
            if out.failure is None or out.failure.kind != "ik_plan":
                break
        return replace(out, timings={SEARCH: searched})

    def _lower_and_let_go(self, poses: PlacePoses) -> Failure | None:
        """Lower the object along `poses.down` until the surface is felt, ease off it and
        let go: None when it did. Nothing felt (EL-E 000 section 4.5: the surface is not
        where it was seen), or met more than `place_above` early (something on the surface
        the cameras missed), the hand keeps the object and rises to wait for another mark."""
        s = self.settings.motion
        failure = self.descend(poses.down, s.approach_speed, "lowering the object")
        if failure is None:
            self.rise_straight(poses.T_above, "rising from the place")
            past = f"{s.place_below * 100:.0f} cm past where it should touch the surface"
            return Failure("execute", f"I lowered the object {past}, felt nothing, and kept it.")
        if "unexpected contact" not in failure.message:
            return failure
        # How far above the rest (T_above is approach_distance above it) the descent stopped.
        early = float(tcp_pose(self.current_q())[2, 3] - poses.T_above[2, 3] + s.approach_distance)
        if early > s.place_above:
            self.rise_straight(poses.T_above, "rising from what it met")
            return Failure(
                "execute",
                f"The object met something {early * 100:.0f} cm above the surface there,"
                " so I kept it. Mark another spot.",
            )
        # The guard stop is the surface met: let go there, eased off it.
        self.ease_off_surface()
        self.release()
        return None

    def _stand_by_around_placed(
        self, held: Held, T_release: np.ndarray, checker: CollisionChecker, spot: np.ndarray
    ) -> Outcome:
        """Stand by (`stand_by`: stowed where no way there is found) around the object
        `held` where it now stands (let go with the TCP at T_release, `base`), as held and as
        the cameras now see it: an object that slid or turned in the pads stands off where
        it was held, and unchecked, the way sweeps the hand through it. `checker`: what the
        place went around; `spot`: where it was set down (m, `base`)."""
        s = self.settings.motion
        standing = held.standing_at(T_release)
        seen = np.vstack([checker.points, self.seen_without_arm()])
        around = CollisionChecker(np.vstack([seen, standing]), margin=s.clearance, filtered=True)
        without = CollisionChecker(seen, margin=s.clearance, filtered=True)
        # A guard stop short of the surface (the wrist met the floor) leaves the straight
        # rise short of clearing the object.
        failure = self.rise_clear(around, hand_on_the_way=without)
        if failure is not None:
            return Outcome(failure, held.grasp, spot=spot)
        # First around a wall under the surface's seen front (`surface_front`: a counter's
        # front runs out of the cameras' view before its top does), then without it.
        front = front_wall(seen, float(spot[2]))
        back = self.stand_by(around.with_points(front))
        if back.failure is not None and back.failure.kind == "ik_plan" and len(front):
            back = self.stand_by(around)
        if back.failure is not None and back.failure.kind == "ik_plan":
            # The object as held can stand for more than it is (a plush toy's mirrored
            # back), and the hand drawn back out of it still stands inside it: around what
            # the cameras see alone, a way home is found.
            back = self.stand_by(without)
        if back.failure is not None:
            msg = back.failure.message
            failure = Failure(back.failure.kind, f"Set down; then {msg[:1].lower()}{msg[1:]}")
            return Outcome(failure, held.grasp, spot=spot)
        self.progress("Placed.")
        return Outcome(None, held.grasp, spot=spot, standing=standing)

    def seen_without_arm(self) -> np.ndarray:
        """What the cameras see around the arm now (m, `base`), thinned, the arm's own
        points left out; none if the capture fails (the caller still has what it saw
        before)."""
        try:
            points = fuse(self.robot.capture(), self.settings.perception).points
        except Exception:
            log.exception("No fresh capture; going on with the last one.")
            return np.zeros((0, 3))
        return points[obstacle_mask(points, q_self=self.current_q())]
