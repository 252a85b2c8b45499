"""Executed behaviours on any `Robot`: pick, drop in the basket, place at a mark, go ready.

Each checks its preconditions before it moves and its postconditions after (EL-E, 000
section 4.6; the re-grip of 002), and ends in one `Outcome`: done, or a typed `Failure` with
a sentence the user can read. A failed behaviour leaves the arm at rest, and never holding
the gripper half closed on nothing.

The pick (004 section 7.4): try the grasps in score order and execute the first that plans;
move to the pre-grasp; approach in a straight, guarded line (an unexpected contact stops the
arm, which then backs off); close; lift 2 cm and close again; lift 10 cm; check the hold.
"""

from __future__ import annotations

import functools
import itertools
import logging
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from laserpick.description import dims
from laserpick.description.kinematics import ik_tcp, tcp_pose
from laserpick.pipeline.approach import centroid_approach
from laserpick.pipeline.cloud import fuse
from laserpick.pipeline.collision import (
    CollisionChecker,
    held_at,
    not_carried,
    obstacle_mask,
    surface_front,
)
from laserpick.pipeline.grasp_choice import GraspSet, at_pose, plan_first
from laserpick.pipeline.perceive import Perception, perceive
from laserpick.pipeline.plan import PickPlan, cartesian_line, joint_path, timed
from laserpick.pipeline.reach import pregrasp_pose
from laserpick.pipeline.recall import moved
from laserpick.pipeline.surface import SURFACE_BAND, on_floor, place_target
from laserpick.robot.interface import PROTECTIVE_STOP, Robot
from laserpick.settings import Settings, get_settings
from laserpick.transforms import invert, planar_pose, roty, rotz
from laserpick.types import Failure, FusedCloud, Grasp, Trajectory

log = logging.getLogger(__name__)

#: Time (s) the gripper gets to close or open: the full 85 mm stroke at 0.15 m/s, plus margin.
GRIPPER_TIME = dims.GRIPPER_STROKE / dims.GRIPPER_SPEED + 0.3
#: Seconds between the centroid approach's control steps (each re-perceives the target).
APPROACH_PERIOD = 0.25
APPROACH_MAX_STEPS = 240
#: Beyond this x (m, `base`) the hand is over the workspace in front of the scooter.
WORKSPACE_X = 1.25
#: TCP heights (m) over the basket's rim to release at: the low ones for most objects, the
#: high ones for a tall object held near its top, which hangs deep below the hand.
DROP_HEIGHTS = (0.06, 0.10, 0.14, 0.20, 0.26)
#: Drop postures tried in turn when no path to the better ones is found.
DROP_TRIES = 3
#: Falls (m) that differ by less than this rank alike when choosing a drop posture.
FALL_STEP = 0.04
#: Where no posture holds the whole object over the basket's opening, upright and tilted
#: ones rank together: by the fall in steps of OVERHANG_FALL_STEP (m), then by how far they
#: hold the object past the opening, in steps of OVERHANG_STEP (m), then as those that hold
#: it inside. A cereal box held at its top, let go from an upright posture 12 cm past a
#: wall, toppled across the opening onto both walls (in-situ), where the next carry to the
#: basket met it (154 N); let go tilted 3.7 cm past, from as high, it fell in. Ranked by
#: the reach past alone, the box went from 6 cm higher and bounced out (isolation).
OVERHANG_FALL_STEP = 0.08
OVERHANG_STEP = 0.01
#: Highest extra lift (m) to bring a held object clear before carrying it, in steps of
#: RISE_STEP (m).
RISE_MAX = 0.20
RISE_STEP = 0.05
#: m a step of that lift also reaches out, away from the arm's mount, where straight up
#: would bring the arm near something: a remote picked from the 31 cm table, 23 cm before
#: the mount, rose 15 cm and stopped 1 cm over the cereal box beside it; a fourth straight
#: step swung the elbow into the sensor post, and no tuck could leave from there.
RISE_OUT = 0.05
#: rad: a grasp whose approach leans farther than this from the vertical is from the side,
#: and is drawn back out along it after the lift (`Behaviours._withdraw`).
WITHDRAW_STEEP = np.radians(30.0)
#: Turns (rad) about the vertical of the level way back from a side grasp, tried in order
#: when straight back along the approach is not clear: a pill bottle lifted in the 69 cm
#: shelf, reached into at 35 deg, brought the elbow into the scooter's sensor post drawn
#: straight back, and left clear turned 15 deg; from inside the gap no tuck was found.
WITHDRAW_TURNS = tuple(np.radians([0.0, 15.0, -15.0, 30.0, -30.0]))
#: A place whose hand is within LEAVE_LEVEL (rad) of level, and has a clear way back, first
#: lowers the open hand by LEAVE_DROP (m) at LEAVE_SPEED (m/s) (`Behaviours._leave_placed`):
#: a pill bottle let go leaned on one pad, whose top edge was under its cap's 2 mm lip, and
#: the hand drawn back along its approach, 7.6 deg up, dragged it 6 cm off its spot. Slowly:
#: lowered at the approach's 8 cm/s onto a spice jar's shoulder, a finger met it with 140 N
#: before the guard stopped it.
LEAVE_LEVEL = np.radians(20.0)
LEAVE_DROP = 0.005
LEAVE_SPEED = 0.02
LEAVE_SETTLE = 0.3  #: s the lowered hand is given to get there
#: An open hand whose pads still feel more than PADS_CLEAR (N) before it leaves is lowered
#: (LEAVE_DROP), then eased LEAVE_SHIFT (m) sideways along its closing axis, one way and, if
#: the pads still feel something, the other, stopped where they feel LEAVE_NUDGE (N) more
#: than when it started (`Behaviours._ease_pads_off`). A pill bottle let go on the floor
#: from the side sprang 1.6 cm onto the right pad and hung on its top edge by the cap's lip
#: (0.4 N): the hand, risen straight up, took it 10 cm up; eased sideways unlowered, it
#: dragged it along. Far under `GRIPPER_HOLD_FORCE`: the simulated pads read exactly nothing
#: when they touch nothing; a real gripper's reading needs PADS_CLEAR above its noise.
PADS_CLEAR = 0.2
FEEL_PERIOD = 0.05  #: s between the pad readings taken while the hand stands still
LEAVE_SHIFT = 0.015
LEAVE_NUDGE = 0.5
#: Times the tuck searches for a way before it raises the object in front instead: each
#: search is random, and from a hand just drawn out of the 69 cm shelf's gap the second found
#: the way the first had not (the session's retreat then tucked it in, the task failed).
TUCK_SEARCHES = 2
#: Height (m) above the surface an object stood on up to which points are the surface's own:
#: its seen points scatter by a few millimetres (`carried_shape` fills down to this height).
SUPPORT_SCATTER = 0.01
#: Turns (rad) of the last wrist joint tried, in order, for a pose the arm holds an object in
#: on the way (tucked in, raised in front): an object held by one end reaches back along the
#: hand, and at one turn it comes within the margin of the upper arm where at another it
#: hangs clear (a banana held 8 cm off its middle could be neither tucked in nor raised).
HOLD_TURNS = (0.0, np.pi, np.pi / 2, -np.pi / 2)
#: Which way (unit vector, `base` xy) a refused place mark should move, by the words the
#: refusal ends with (`crowded_message`).
MARK_MOVES = {
    "farther left": (0.0, 1.0),
    "farther right": (0.0, -1.0),
    "nearer you": (-1.0, 0.0),
    "farther from you": (1.0, 0.0),
}
#: Turns (rad) about the vertical tried, in order, when the object cannot be set down as held.
PLACE_YAWS = tuple(np.radians([0, 30, -30, 60, -60, 90, -90, 135, -135, 180]))
#: How far (rad) the arm may be from a trajectory's start when it is sent, and how long (s)
#: it is waited for to get there (the controller refuses a start 0.05 rad off).
START_TOLERANCE = 0.02
START_WAIT = 1.0
#: Still this far (rad) from the start after the wait, the arm is held back: by contact.
START_STUCK = 0.05
#: Extra time (s) a motion may take beyond its planned duration before it counts as failed.
MOTION_SLACK = 3.0
#: Spacing (rad, largest joint) of the waypoints kept on the way back from a protective stop.
BACK_STEP = 0.1
#: How far (m, rad) the scooter may have gone since a pick for the object still to be put
#: back the way it came (`Behaviours.put_back`): parked, the odometry stays put.
PUT_BACK_MOVED = 0.005
PUT_BACK_TURNED = np.radians(0.5)


def turned_hand_xy(spot_xy: np.ndarray, middle_xy: np.ndarray, dyaw: float) -> np.ndarray:
    """Where the hand goes (m, `base` xy) to set an object down turned by dyaw (rad) about
    the vertical, so that its middle lands where it would unturned with the hand at
    spot_xy. middle_xy: the object's middle from the hand, unturned (m). The turn is about
    the object's middle: about the hand, an object held 7 cm off its middle would land
    14 cm from where it should when turned a half turn."""
    return np.asarray(spot_xy, float) + middle_xy - rotz(dyaw)[:2, :2] @ middle_xy


@dataclass(frozen=True)
class Outcome:
    """How a behaviour ended. attempts: grasps tried in planning; timings: seconds per stage;
    spot: where a place set the object down (the surface point under the TCP, m, `base`);
    standing: the object there as the hand let it go (its carried shape, m, `base`);
    closed_width: a pick's finger gap once it has squeezed again after the first lift (m),
    beside `grasp.width`, the width it planned: an object turned in the pads shows less;
    caution: a sentence for the user about what went otherwise than planned, which no sensor
    can confirm (an object let go partly past the basket's opening)."""

    failure: Failure | None = None
    grasp: Grasp | None = None
    attempts: int = 0
    timings: dict[str, float] = field(default_factory=dict)
    spot: np.ndarray | None = None
    standing: np.ndarray | None = None
    closed_width: float | None = None
    caution: str | None = None

    @property
    def ok(self) -> bool:
        return self.failure is None


@dataclass
class Held:
    """What the hand holds after a pick: the grasp, its height above the support surface (m)
    (for placing, 004 section 7.3), the object's points in the TCP frame (m, thinned, its
    unseen back filled in by `carried_shape`: the planner carries them with the hand), its
    middle in the TCP frame (m; `object_middle`: a place that turns it turns it about this),
    the obstacles around it (`base`), and the odometry's pose (x, y, yaw; m, rad) where they
    were seen (None: not tied to a place). Once the scooter has moved, the obstacles must be
    taken anew (`Session._held_here`). seen_tcp: where the cameras' view cut the object off,
    its points (TCP frame) without the part `beyond_view` stood in for (None: as
    points_tcp); what is left standing where the hand lets it go (`standing_at`)."""

    grasp: Grasp
    height_above_support: float
    points_tcp: np.ndarray
    middle_tcp: np.ndarray
    surroundings: CollisionChecker
    seen_from: np.ndarray | None = None
    seen_tcp: np.ndarray | None = None

    def at(self, T_tcp: np.ndarray) -> np.ndarray:
        """The object's points (m, `base`) with the TCP at pose T_tcp (4, 4), `base`."""
        return self.points_tcp @ T_tcp[:3, :3].T + T_tcp[:3, 3]

    @property
    def as_seen_tcp(self) -> np.ndarray:
        """The object's points in the TCP frame (m) less what stood in for a part the view
        cut off: where it will be once let go. The part guessed for a carry's safety is no
        part of where it stands or falls."""
        return self.points_tcp if self.seen_tcp is None else self.seen_tcp

    def standing_at(self, T_tcp: np.ndarray) -> np.ndarray:
        """The object as it stands once let go with the TCP at pose T_tcp (4, 4), `base`
        (m, `base`): `as_seen_tcp` there. The part guessed for a carry's safety is space the
        open hand must not be kept out of: a juice bottle and two pill bottles, set down with
        it taken for part of them, were no longer on their spots once the hand had gone; set
        down as seen, they stood."""
        return self.as_seen_tcp @ T_tcp[:3, :3].T + T_tcp[:3, 3]


@dataclass(frozen=True)
class WayIn:
    """How the hand came to hold what it holds, for setting it back down (`put_back`): the
    odometry's pose at the grasp (x, y, yaw; m, rad), the approach's joint path (N, 6, rad)
    from the pre-grasp pose to the grasp, and the joint paths run to the end since the hand
    closed there, in order."""

    base: np.ndarray
    approach: np.ndarray
    driven: tuple[np.ndarray, ...] = ()

    def way_back(self) -> np.ndarray:
        """Every joint path driven since the grasp, backwards, as one (N, 6)."""
        back = np.vstack([p[::-1] for p in reversed(self.driven)])
        keep = np.r_[True, np.abs(np.diff(back, axis=0)).max(axis=1) > 1e-9]
        return back[keep]


def front_wall(points: np.ndarray, height: float) -> np.ndarray:
    """The points (m, `base`) of a wall under the seen front of the surface at `height` (m)
    in the cloud `points` (N, 3; `base`), as a checker takes them (`surface_front`,
    `obstacle_mask`): none for the floor."""
    front = surface_front(points, height, SURFACE_BAND)
    return front[obstacle_mask(front, voxel=0.0)]


def crowded_message(points: np.ndarray, spot: np.ndarray) -> str:
    """What the user hears when every way down to a place `spot` (m, `base`) comes too close
    to something: on which side of the spot the `points` (N, 3; m, `base`) it came too
    close to lie, and which way a mark should move (`MARK_MOVES`), as the user sees it from
    the seat (`base` +x ahead, +y left). A pill bottle held level from a shelf's edge goes
    down with the wrist 22 cm to the right of it, low: beside what had been set down there
    before, twelve marks on four surfaces were refused with "too close to something there",
    each about where the user had marked before."""
    if len(points) == 0:
        return "The arm would come down too close to something there."
    dx, dy = np.mean(points[:, :2], axis=0) - spot[:2]
    if abs(dy) >= abs(dx):
        where, move = (
            ("to the left of", "farther right") if dy > 0 else ("to the right of", "farther left")
        )
    else:
        where, move = ("beyond", "nearer you") if dx > 0 else ("in front of", "farther from you")
    return f"The arm would come down too close to something {where} that spot: mark one {move}."


@functools.cache
def drop_candidates(tilted: bool = False) -> tuple[np.ndarray, ...]:
    """Joint configurations for releasing over the basket, the arm clear of the scooter (rad).

    Upright (the default): the TCP over (or just inside) the basket's opening, the gripper
    pointing down or tilted up to 30 deg. Tilted: the gripper tilted 45-90 deg from down,
    toward any side, its TCP up to 20 cm beside the opening: for a tall object held at its
    top, which hangs too deep below a downward hand for any reachable height (the arm
    reaches at most 26 cm above the rim pointing down), so it is laid over the opening
    instead. Computed once each: the basket is fixed to the scooter.
    """
    centre, inner = dims.BASKET_CENTER, dims.BASKET_INNER
    rim = centre[2] + inner[2] / 2
    free = CollisionChecker(np.zeros((0, 3)))
    if tilted:
        offsets = np.linspace(-0.2, 0.2, 5)
        grid = itertools.product(
            offsets,
            offsets,
            DROP_HEIGHTS,
            np.radians(np.arange(0, 360, 30)),
            np.radians((45, 60, 75, 90)),
        )
    else:
        grid = itertools.product(
            np.linspace(-0.3, 0.3, 3) * inner[0],
            np.linspace(-0.3, 0.3, 3) * inner[1],
            DROP_HEIGHTS,
            np.radians(np.arange(0, 180, 30)),
            np.radians((0, 15, 30)),
        )
    out = []
    for dx, dy, dz, yaw, tilt in grid:
        T = np.eye(4)
        T[:3, :3] = rotz(yaw) @ roty(tilt) @ np.diag([1.0, -1.0, -1.0])  # approach down
        T[:3, 3] = [centre[0] + dx, centre[1] + dy, rim + dz]
        Q = ik_tcp(T, dims.UR5_READY_Q)
        out += [q for q, ok in zip(Q, free.clearance_ok(Q), strict=True) if ok]
    return tuple(out)


#: What the user is told when the hand let go of an object partly past the basket's opening
#: (no posture held it wholly over it): no camera sees the basket, and a cereal box let go so
#: lay across both walls, where the next carry to the basket met it (in-situ, 154 N).
PAST_THE_OPENING = (
    "Part of it reached past the basket's opening when the hand let go, so it may lie on"
    " the rim or beside the basket: please check before the next drop."
)


def basket_opening() -> tuple[np.ndarray, np.ndarray]:
    """The basket's opening, 1 cm in from its walls: its lower and upper corners (m, `base`
    xy)."""
    half = dims.BASKET_INNER[:2] / 2
    return dims.BASKET_CENTER[:2] - half + 0.01, dims.BASKET_CENTER[:2] + half - 0.01


def past_the_opening(held: np.ndarray) -> np.ndarray:
    """How far (m) each point of `held` (..., 3) (m, `base`) lies past the basket's opening,
    across: 0 over it."""
    lo, hi = basket_opening()
    xy = held[..., :2]
    return np.maximum(np.maximum(lo - xy, xy - hi), 0.0).max(axis=-1)


class Behaviours:
    """The robot's behaviours, run one at a time from the caller's thread.

    progress: called with a short sentence at each step, for the console and logs.
    should_stop: polled before every motion; once it returns True (the operator cancelled,
    or the watchdog fired) no new motion starts and the behaviour ends with a failure.
    """

    def __init__(
        self,
        robot: Robot,
        settings: Settings | None = None,
        rng: np.random.Generator | None = None,
        progress: Callable[[str], None] | None = None,
        should_stop: Callable[[], bool] | None = None,
    ) -> None:
        self.robot = robot
        self.should_stop = should_stop or (lambda: False)
        self.settings = settings or get_settings()
        self.rng = rng if rng is not None else np.random.default_rng(0)
        self.progress = progress or (lambda msg: log.info(msg))
        self.held: Held | None = None
        self.way_in: WayIn | None = None

    # --- motion primitives -------------------------------------------------------------------

    def _run(self, traj: Trajectory, what: str) -> Failure | None:
        if self.should_stop():
            return Failure("execute", f"Stopped before {what}: the motion was cancelled.")
        # A trajectory ends by its clock while the servos may still lag; the controller
        # refuses one that starts more than 0.05 rad from where the arm is. So let the arm
        # catch up with the start first (a few tenths of a second at most).
        waited = 0.0
        while np.max(np.abs(self._q() - traj.q[0])) > START_TOLERANCE and waited < START_WAIT:
            self.robot.sleep(0.05)
            waited += 0.05
        if np.max(np.abs(self._q() - traj.q[0])) > START_STUCK:
            self.robot.halt()
            self.way_in = None
            return Failure(
                "execute",
                f"The arm stopped short of where {what} starts: it may be touching something.",
            )
        handle = self.robot.execute(traj)
        status = self.robot.wait(handle, traj.duration + MOTION_SLACK)
        if status == "done":
            if self.way_in is not None and self.held is not None:
                self.way_in = replace(self.way_in, driven=(*self.way_in.driven, traj.q))
            return None
        self.way_in = None  # stopped part way: the way back is no longer known
        if status == "running":
            self.robot.halt()  # not the latching e-stop: that one stays the user's
            return Failure("execute", f"The arm did not finish {what} in time; it was stopped.")
        if handle.message.startswith(PROTECTIVE_STOP):
            felt = handle.message.removeprefix(PROTECTIVE_STOP)
            done = "stopped and backed away" if self._back_away(traj) else "stopped"
            return Failure("execute", f"The arm was pushed back while {what} ({felt}): {done}.")
        return Failure("execute", f"The arm stopped while {what}: {handle.message}.")

    def _back_away(self, traj: Trajectory) -> bool:
        """After a protective stop on `traj`, go back the way it came to where it started:
        the arm was there a moment ago, so that way is clear, and the arm is then neither
        pressed against what it met nor left standing in the cameras' view (left there, it
        hid the next mark's object from them). Not when the user has cancelled: the arm then
        stays where it stopped. Returns whether it got back."""
        if self.should_stop():
            return False
        q = self._q()
        reached = int(np.argmin(np.max(np.abs(traj.q - q), axis=1)))
        back = np.vstack([q, traj.q[reached::-1]])
        # Keep the turning points, about BACK_STEP apart: a trajectory is sampled densely.
        moved = np.concatenate([[0.0], np.cumsum(np.max(np.abs(np.diff(back, axis=0)), axis=1))])
        keep = np.flatnonzero(np.diff(np.floor(moved / BACK_STEP), prepend=-1) > 0)
        path = back[np.union1d(keep, [len(back) - 1])]
        if len(path) < 2 or np.max(np.abs(path[-1] - q)) < START_TOLERANCE:
            return True
        way_back = timed(path, self.settings.motion)
        handle = self.robot.execute(way_back)
        return self.robot.wait(handle, way_back.duration + MOTION_SLACK) == "done"

    def _q(self) -> np.ndarray:
        return self.robot.joint_state().q

    def go_to(
        self,
        q_goal: np.ndarray,
        checker: CollisionChecker,
        what: str,
        via: Sequence[np.ndarray] = (),
        **kw,
    ) -> Outcome:
        """A collision-free joint move to q_goal (6,) rad; when no path is found, through
        each configuration of `via` in turn (two shorter searches instead of one long)."""
        s, q = self.settings.motion, self._q()
        path = joint_path(q, q_goal, checker, self.rng, s, **kw)
        for q_via in via:
            if path is not None:
                break
            first = joint_path(q, q_via, checker, self.rng, s, **kw)
            second = (
                joint_path(q_via, q_goal, checker, self.rng, s, **kw) if first is not None else None
            )
            path = None if second is None else np.vstack([first, second[1:]])
        if path is None:
            return Outcome(Failure("ik_plan", f"No collision-free path was found for {what}."))
        carrying = kw.get("payload") is not None
        speed = s.carry_joint_speed if carrying else None
        return Outcome(self._run(timed(path, s, joint_speed=speed), what))

    def go_ready(self, checker: CollisionChecker | None = None) -> Outcome:
        """To the ready pose, raised in front with the gripper down, or to the high ready
        pose where the checker's cloud fills the ready pose. Without a `checker`
        (no fresh cloud), a hand below the ready height first rises straight up to it, so
        that the move does not sweep it through what stands around it."""
        if checker is None:
            checker = CollisionChecker(np.zeros((0, 3)))
            T = tcp_pose(self._q())
            ready_z = tcp_pose(dims.UR5_READY_Q)[2, 3]
            if T[2, 3] < ready_z - 0.01 and T[0, 3] > WORKSPACE_X:
                T[2, 3] = ready_z
                up = cartesian_line(self._q(), T, self.settings.motion.cartesian_step)
                # Only when the whole rise is clear: rising into the scooter's camera heads
                # would leave the planner no collision-free start.
                if up is not None and checker.clearance_ok(up).all():
                    failure = self._run(timed(up, self.settings.motion), "rising")
                    if failure is not None:
                        return Outcome(failure)
        # Before a surface above the ready hand (the 87 cm counter), the high ready pose.
        high = not checker.clearance_ok(dims.UR5_READY_Q)[0]
        if high and checker.clearance_ok(dims.UR5_HIGH_READY_Q)[0]:
            return self.go_to(dims.UR5_HIGH_READY_Q, checker, "going to ready")
        return self.go_to(dims.UR5_READY_Q, checker, "going to ready", via=(dims.UR5_HIGH_READY_Q,))

    def stow(self, checker: CollisionChecker | None = None) -> Outcome:
        """Fold the arm down beside the scooter, out of the cameras' view: through ready,
        then the way out of the stowed pose backwards (`_fold_away`). checker: what stands
        around the arm, when a fresh cloud shows it (see `go_ready`)."""
        if at_pose(self._q(), dims.UR5_HOME_Q):
            return Outcome()
        out = self.go_ready(checker)
        if out.failure is not None and out.failure.kind == "ik_plan" and checker is not None:
            # No way to either ready pose (the hand set an object down on the 108 cm table,
            # which fills both): fold away from where it is, by a checked search.
            direct = self._fold_away(checker)
            return direct if direct.ok else out
        if not out.ok:
            return out
        return self._fold_away(checker)

    def _fold_away(self, checker: CollisionChecker | None = None) -> Outcome:
        """To the unstow pose, then straight home: the way out of the stowed pose, backwards,
        which keeps the hand beside the scooter (`dims.UR5_UNSTOW_Q`). checker: what stands
        around the arm (none: an empty cloud; the scooter is always checked)."""
        checker = checker or CollisionChecker(np.zeros((0, 3)))
        out = self.go_to(dims.UR5_UNSTOW_Q, checker, "stowing")
        return out if not out.ok else self.go_to(dims.UR5_HOME_Q, checker, "stowing")

    # --- pick ------------------------------------------------------------------------------

    def pick(self, grasps: GraspSet, order: Sequence[Grasp] | None = None) -> Outcome:
        """Pick with the first grasp of `order` (default: all, in score order) that plans."""
        s = self.settings.motion
        if self.robot.gripper_state().holding:
            return Outcome(Failure("precondition", "The hand is already holding something."))
        order = list(order) if order is not None else grasps.ordered()
        self.way_in = None
        t0 = time.perf_counter()
        plan, grasp, attempts = plan_first(grasps, self._q(), self.rng, order, s)
        timings = {"plan": time.perf_counter() - t0}
        if isinstance(plan, Failure):
            msg = f"None of the {attempts} grasps could be planned ({plan.message})"
            return Outcome(Failure("ik_plan", msg), attempts=attempts, timings=timings)
        self.progress(f"Grasp {attempts} of {len(order)} planned; moving to it.")
        self.robot.gripper(False)
        failure = self._run(plan.transit, "moving to the grasp")
        if failure:
            return Outcome(failure, grasp, attempts, timings)
        guarded = Trajectory(
            plan.approach.times, plan.approach.q, plan.approach.gripper, guard_force=s.guard_force
        )
        failure = self._run(guarded, "approaching the object")
        if failure and "unexpected contact" in failure.message:
            self._back_off()
            touched = failure.message.split("unexpected contact: ", 1)[1].rstrip(".")
            msg = f"The hand touched something on its way in ({touched}), stopped and backed off."
            return Outcome(Failure("execute", msg), grasp, attempts, timings)
        if failure:
            return Outcome(failure, grasp, attempts, timings)
        self.progress("Closing the gripper.")
        self.robot.gripper(True)
        self.robot.sleep(GRIPPER_TIME)
        if not self._gripping():
            self._release_and_retreat(plan)
            return Outcome(
                Failure("execute", "The gripper closed on nothing."), grasp, attempts, timings
            )
        # Held from here on, so that a cancel or an e-stop while lifting still knows what
        # the hand has (the object's points travel with it in later collision checks).
        support = grasps.stands_on
        pts = grasps.carried
        pts_tcp = grasp.in_hand(pts)
        around = self._without_leftovers(grasps.surroundings, pts, support)
        height = float(grasp.position[2] - support)
        middle = grasp.in_hand(grasps.middle[None])[0]
        seen_tcp = grasp.in_hand(grasps.carried_as_seen) if len(grasps.cut_off) else None
        self.held = Held(grasp, height, pts_tcp, middle, around, self.robot.base_pose(), seen_tcp)
        self.way_in = WayIn(self.robot.base_pose(), plan.approach.q)
        # 002's re-grip: lift a little, so the object hangs in the hand, and squeeze again.
        failure = self._run(plan.regrip, "lifting") if s.regrip_lift > 0 else None
        self.robot.gripper(True)
        self.robot.sleep(0.3)
        closed = self.robot.gripper_state().width
        failure = failure or self._run(plan.lift, "lifting")
        self.robot.sleep(0.3)
        if failure is None and not self.robot.gripper_state().holding:
            failure = Failure("execute", "The object slipped out of the hand while lifting.")
        if failure:
            if not self.should_stop():  # a cancel or an e-stop keeps what the hand holds
                self._let_go()
            return Outcome(failure, grasp, attempts, timings, closed_width=closed)
        failure = self._withdraw(grasp.approach, around, pts_tcp)
        if failure:  # the hand keeps what it holds: the session tucks it in
            return Outcome(failure, grasp, attempts, timings, closed_width=closed)
        self.progress("Holding the object.")
        return Outcome(None, grasp, attempts, timings, closed_width=closed)

    def _withdraw(
        self,
        approach: np.ndarray,
        checker: CollisionChecker,
        payload: np.ndarray | None = None,
        *,
        level: bool = True,
    ) -> Failure | None:
        """Draw the hand back the way `_withdrawal` finds; stay where it finds none."""
        path = self._withdrawal(approach, checker, payload, level=level)
        return None if path is None else self._draw_back(path)

    def _draw_back(self, path: np.ndarray) -> Failure | None:
        """Run a way back (N, 6) that `_withdrawal` found, at the approach's speed."""
        s = self.settings.motion
        return self._run(timed(path, s, tcp_speed=s.approach_speed), "drawing back")

    def _descend(
        self, path: np.ndarray, tcp_speed: float, what: str, *, felt: float = 0.0
    ) -> Failure | None:
        """Run the straight way down `path` (N, 6) at `tcp_speed` (m/s), guarded: where the
        hand or what it holds feels more than `place_contact_force` over the `felt` (N) it
        already bears at the start, it stops there, and the failure says what it met."""
        s = self.settings.motion
        down = timed(path, s, tcp_speed=tcp_speed)
        guard = s.place_contact_force + felt
        return self._run(Trajectory(down.times, down.q, guard_force=guard), what)

    def _withdrawal(
        self,
        approach: np.ndarray,
        checker: CollisionChecker,
        payload: np.ndarray | None = None,
        *,
        level: bool = True,
    ) -> np.ndarray | None:
        """The joint path (N, 6) that draws the hand straight back along its `approach`
        (unit, `base`) by `approach_distance` (or half that where the whole is not clear of
        `checker`, with `payload` in the hand); None where none is clear.

        level: after a lift from the side, back level, out of a shelf's gap before the arm
        swings anywhere (a swing planned from inside the 69 cm shelf found no way out, or
        met the board above): along the approach, else turned by each of WITHDRAW_TURNS; a
        grasp from above (within WITHDRAW_STEEP of the vertical) leaves by rising instead.
        Not level: after a place, back along the approach itself, the fingers sliding off
        the object they let go of the way they came (drawn back level from 43 deg above the
        side, they dragged a plush toy's head over).

        A hand that starts within the checker's margin of something (set down beside other
        objects, say) still leaves, if the whole way keeps the clearance it starts with:
        half the margin, or none short of touching. The arm keeps its own: drawn back
        within the hand's clearance from a bottle set down on the 73 cm table, the elbow
        came within the margin of the sensor post, and no way home could start there."""
        across = float(np.hypot(*approach[:2]))
        if level and across < np.sin(WITHDRAW_STEEP):
            return None
        s = self.settings.motion
        backs = (
            [rotz(turn) @ -np.append(approach[:2] / across, 0.0) for turn in WITHDRAW_TURNS]
            if level
            else [-approach]
        )
        q = self._q()
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
                or not checker.clearance_ok(path, payload=payload, margin=margin).all()
                or not checker.clearance_ok(path, hand=False, margin=arm_margin).all()
            ):
                continue
            return path
        return None

    def _pads_feel(self) -> float:
        """What the pads press on (N): the gripper's own sensing."""
        return self.robot.gripper_state().force

    def _pads_feel_over(self, seconds: float) -> float:
        """The most the pads feel (N) over the next `seconds` of robot time. One reading
        flickers: a pad pressed against a rail read 0 N, then 0.95 N a tenth of a second
        later."""
        most = self._pads_feel()
        for _ in range(round(seconds / FEEL_PERIOD)):
            self.robot.sleep(FEEL_PERIOD)
            most = max(most, self._pads_feel())
        return most

    def _caught(self) -> bool:
        """Whether the open hand's pads still press what they let go of (or anything): more
        than PADS_CLEAR over LEAVE_SETTLE."""
        return self._pads_feel_over(LEAVE_SETTLE) > PADS_CLEAR

    def _gripping(self) -> bool:
        state = self.robot.gripper_state()
        return state.closed and state.width > dims.GRIPPER_EMPTY_GAP

    def _let_go(self) -> None:
        """Open the hand and give it the time to open: it holds nothing from here."""
        self.robot.gripper(False)
        self.robot.sleep(GRIPPER_TIME)
        self.held = None
        self.way_in = None

    def _ease_off_surface(self) -> None:
        """Rise `place_ease` straight up from where a guarded descent felt the surface under
        what the hand holds: let go there, with no drop to roll from, but not pressed into
        the surface (`MotionSettings.place_ease`)."""
        eased = tcp_pose(self._q())
        eased[2, 3] += self.settings.motion.place_ease
        self._rise_straight(eased, "easing off the surface")

    def _back_off(self) -> None:
        """After a stopped approach: straight back along the approach axis."""
        q = self._q()
        T = tcp_pose(q)
        T_back = pregrasp_pose(T, self.settings.motion.backoff)
        path = cartesian_line(q, T_back, self.settings.motion.cartesian_step)
        if path is not None:
            self._run(timed(path, self.settings.motion, tcp_speed=0.05), "backing off")

    def _release_and_retreat(self, plan: PickPlan) -> None:
        self.robot.gripper(False)
        self.robot.sleep(GRIPPER_TIME)
        back = cartesian_line(
            self._q(), tcp_pose(plan.approach.q[0]), self.settings.motion.cartesian_step
        )
        if back is not None:
            self._run(timed(back, self.settings.motion, tcp_speed=0.1), "retreating")

    # --- drop and place -------------------------------------------------------------------

    def drop_configurations(
        self,
        q_ref: np.ndarray,
        checker: CollisionChecker,
        payload: np.ndarray,
        falls: np.ndarray | None = None,
    ) -> list[np.ndarray]:
        """Clear joint configurations that hold the object over the basket's opening, best
        first (rad): those of `drop_candidates()`, and where fewer than DROP_TRIES of them
        hold the whole object inside, the tilted ones after them (a cereal box held at its
        top fitted inside from one upright posture only, which no path reached).

        payload (P, 3), TCP frame (m): the points kept clear of everything, as carried.
        falls (F, 3), TCP frame (m): the object as it falls when let go (default `payload`):
        less the part that stands in for what the view cut off (`Held.as_seen_tcp`), which
        would pull the middle it is held by off the real object's (in-situ lost a juice
        bottle and a cereal box beside the basket that way).

        Postures that hold every point of the object inside the opening (1 cm in from the
        walls) come first, upright before tilted, each by the shortest fall (in FALL_STEP
        steps: a long fall bounces the object out), then the nearest to q_ref. Then those
        that hold its middle there, upright and tilted together (see OVERHANG_STEP).
        A posture that does not hold even the middle over the opening is left out: an object
        let go there would fall beside the basket, onto the scooter or the floor. Empty when
        none is left.
        The basket sits close beside the arm's base, between the tiller, the sensor posts and
        the projector, so few postures reach over it: they are searched, not assumed.
        """
        falls = payload if falls is None else falls
        ranked = self._rank_drops(drop_candidates(), q_ref, checker, payload, falls)
        if sum(key[0] == 0 for key, _ in ranked) < DROP_TRIES:
            tilted = drop_candidates(tilted=True)
            ranked += self._rank_drops(tilted, q_ref, checker, payload, falls)
            inside = [kq for kq in ranked if kq[0][0] == 0]
            past = sorted((kq for kq in ranked if kq[0][0] != 0), key=lambda kq: kq[0])
            ranked = inside + past
        return [q for _, q in ranked]

    @staticmethod
    def _rank_drops(
        candidates: Sequence[np.ndarray],
        q_ref: np.ndarray,
        checker: CollisionChecker,
        payload: np.ndarray,
        falls: np.ndarray,
    ) -> list[tuple[tuple[int, int, int, int, float], np.ndarray]]:
        """The clear `candidates` (clear with `payload`) that hold the object's middle over
        the opening, each with its rank key (see `drop_configurations`; of `falls`), sorted."""
        if not candidates:
            return []
        floor = dims.BASKET_CENTER[2] - dims.BASKET_INNER[2] / 2
        Q = np.array(candidates)
        T = tcp_pose(Q)
        pts = falls if len(falls) else np.zeros((1, 3))
        held = held_at(T, pts)  # (B, P, 3)
        middle_in = past_the_opening(held.mean(axis=1)) == 0
        Q, held = Q[middle_in], held[middle_in]
        # In chunks: the check's arrays grow with candidates x payload points x spheres.
        clear = np.concatenate(
            [checker.clearance_ok(Q[i : i + 64], payload=payload) for i in range(0, len(Q), 64)]
            or [np.zeros(0, bool)]
        )
        past = past_the_opening(held).max(axis=1)
        # In steps, 0 where wholly inside; the 1e-9 keeps float noise from adding a step.
        past = np.ceil(past / OVERHANG_STEP - 1e-9).astype(int)
        drop = held[..., 2].min(axis=1) - floor
        fall = (drop // FALL_STEP).astype(int)
        coarse = (drop // OVERHANG_FALL_STEP).astype(int)
        near = np.max(np.abs(Q - q_ref), axis=1)
        ranked = [
            (
                (0, 0, 0, int(fall[i]), float(near[i]))
                if past[i] == 0
                else (1, int(coarse[i]), int(past[i]), int(fall[i]), float(near[i])),
                Q[i],
            )
            for i in np.flatnonzero(clear)
        ]
        ranked.sort(key=lambda kq: kq[0])
        return ranked

    def _rise_clear(
        self,
        checker: CollisionChecker,
        payload: np.ndarray | None = None,
        *,
        hand_on_the_way: bool = True,
    ) -> Failure | None:
        """Lift straight up, RISE_STEP at a time and at most RISE_MAX, until the arm, the
        hand and what it holds (`payload`, in the TCP frame) are clear of `checker`: a
        planner cannot start among obstacles. Just after a lift the held object may still be
        near its neighbours or the parts of itself the segmentation missed; just after a
        place the open hand is still about the object it let go of.
        A step that would bring the arm itself near anything is not taken: a hand held out
        level and raised swings the elbow back over the scooter, into the tiller and the
        sensor posts, and no path leaves from there. Where straight up does, a held object
        may instead rise and reach out RISE_OUT, away from the arm's mount, which keeps the
        elbow forward: only where that step ends with the object clear (out of a shelf's
        gap, it would carry the object deeper in). hand_on_the_way: whether the hand is kept
        clear on each step too (not when it starts among what it let go of)."""
        s = self.settings.motion
        risen = 0.0
        while not checker.clearance_ok(self._q(), payload=payload)[0]:
            if risen >= RISE_MAX:
                return None  # let the planner say it found no way
            path = self._rise_step(checker, payload, hand_on_the_way)
            if path is None:
                return None
            failure = self._run(timed(path, s, tcp_speed=s.approach_speed), "lifting clear")
            if failure is not None:
                return failure
            risen += RISE_STEP
        return None

    def _rise_step(
        self, checker: CollisionChecker, payload: np.ndarray | None, hand: bool
    ) -> np.ndarray | None:
        """The joint path (N, 6) of one RISE_STEP up that keeps the arm (and the hand, if
        `hand`) clear of `checker`: straight, or, holding `payload`, reaching out RISE_OUT
        from the arm's mount where that brings the payload clear. None when neither does.
        Clear, where the arm starts within the checker's margin, means keeping at least the
        clearance it starts with (`clearance_kept`): cereal boxes set down on the 31 cm
        table and the 87 cm counter left the forearm 2-4 mm above the top, and a rise held
        to the full margin could not leave (2 of 195 pick-place tasks ended with the arm
        out over the surface)."""
        q = self._q()
        kept = checker.clearance_kept(q, hand=hand)
        if kept is None:
            return None
        here = tcp_pose(q)
        out = here[:2, 3] - dims.ARM_MOUNT_POS[:2]
        out = out / max(float(np.linalg.norm(out)), 1e-6)
        for reach in (0.0, RISE_OUT) if payload is not None else (0.0,):
            T = here.copy()
            T[:2, 3] += reach * out
            T[2, 3] += RISE_STEP
            path = cartesian_line(q, T, self.settings.motion.cartesian_step)
            if path is None or not checker.clearance_ok(path, hand=hand, margin=kept).all():
                continue
            if reach == 0.0 or checker.clearance_ok(path[-1], payload=payload)[0]:
                return path
        return None

    def _lost_on_the_way(self, where: str) -> Outcome | None:
        """After a carry to `where`: the failure to end with if the hand no longer holds the
        object (it fell on the way), else None."""
        if self.robot.gripper_state().holding:
            return None
        self.held = None
        msg = f"The object fell from the hand while it was carried to {where}."
        return Outcome(Failure("execute", msg))

    def tuck(self) -> Outcome:
        """Hold what the hand holds folded back beside the scooter (`dims.UR5_CARRY_Q`) while
        the user drives and marks where it goes: out of the cameras' view, the laser's way and
        the furniture's (raised in front, the object hangs 1.6 m ahead of the rear axle, into
        a shelf the scooter parks at). Where TUCK_SEARCHES searches find no way there, raised
        in front (the high ready pose)."""
        held = self.held
        if held is None:
            return Outcome(Failure("precondition", "The hand is not holding anything."))
        failure = self._rise_clear(held.surroundings, held.points_tcp)
        if failure is not None:
            return Outcome(failure)
        high = self._holding_pose(dims.UR5_HIGH_READY_Q, held.surroundings, held.points_tcp)
        carry = self._holding_pose(dims.UR5_CARRY_Q, held.surroundings, held.points_tcp)
        for _ in range(TUCK_SEARCHES):
            out = self.go_to(
                carry, held.surroundings, "tucking it in", via=(high,), payload=held.points_tcp
            )
            if out.ok or out.failure is None or out.failure.kind != "ik_plan":
                return out  # it went there, or a motion was stopped: no second one
        return self.go_to(high, held.surroundings, "raising", payload=held.points_tcp)

    def put_back(self) -> Outcome:
        """Set what the hand holds back down where it was picked up, and take the open hand
        off it: for when no way out holding it is found. Left holding it, the arm stood in
        the bookshelf's gap with a pill bottle in hand, and the task ended there (pick-place,
        trial seed 102); set back down, it can be tried again.

        Down the way it came up: every motion run since the hand closed (`WayIn`), backwards,
        guarded as a place's descent is. Nothing else has moved since, so that way is clear.
        An object that slid down in the pads meets its surface early: within `place_above`
        of where it stood it is let go there, eased off it; met higher, it is something
        else, and the hand keeps the object. The open hand then leaves it as it leaves a
        placed object (`_leave_placed`), unchecked at worst along the way it came in.
        Refused where that way back is not known: a motion was stopped since the grasp, or
        the scooter has moved."""
        s = self.settings.motion
        held, way = self.held, self.way_in
        if held is None or not self.robot.gripper_state().holding:
            return Outcome(Failure("precondition", "The hand is not holding anything."))
        if way is None or not way.driven:
            msg = "I can't put the object back: the way the arm came with it is not known."
            return Outcome(Failure("precondition", msg))
        if moved(way.base, self.robot.base_pose(), PUT_BACK_MOVED, PUT_BACK_TURNED):
            msg = "I can't put the object back: the scooter has moved since the pick."
            return Outcome(Failure("precondition", msg))
        self.progress("Putting the object back where it was.")
        back = way.way_back()
        T_grasp = tcp_pose(back[-1])
        failure = self._descend(back, s.approach_speed, "putting the object back")
        if failure is not None:
            if "unexpected contact" not in failure.message:
                return Outcome(failure, held.grasp)
            early = float(tcp_pose(self._q())[2, 3] - T_grasp[2, 3])
            if early > s.place_above:
                msg = (
                    f"Putting the object back, it met something {early * 100:.0f} cm above"
                    " where it stood, so I kept it."
                )
                return Outcome(Failure("execute", msg), held.grasp)
            self._ease_off_surface()
        self._let_go()
        # Out along the approach, as far above the way in as the hand stands above the grasp.
        T_out = tcp_pose(way.approach[0])
        T_out[:3, 3] += tcp_pose(self._q())[:3, 3] - T_grasp[:3, 3]
        failure = self._leave_placed(T_out, held.surroundings)
        if failure is not None:
            return Outcome(failure, held.grasp)
        self.progress("Put back.")
        return Outcome(None, held.grasp)

    @staticmethod
    def _holding_pose(q: np.ndarray, checker: CollisionChecker, payload: np.ndarray) -> np.ndarray:
        """`q` (6,) rad with the last wrist joint turned by the first of HOLD_TURNS at which
        the arm and what it holds (`payload`, TCP frame) keep clear of `checker`; `q` itself
        where none does (the planner then says it found no way)."""
        for turn in HOLD_TURNS:
            turned = q.copy()
            turned[5] += turn
            if checker.clearance_ok(turned, payload=payload)[0]:
                return turned
        return q

    def drop_in_basket(self) -> Outcome:
        """Carry what the hand holds to the basket, release it, and return to ready (stowed
        where neither ready pose is clear). Let go partly past the basket's opening, the
        outcome says so (`PAST_THE_OPENING`): as its caution, or in its failure."""
        if self.held is None or not self.robot.gripper_state().holding:
            self.held = None
            return Outcome(Failure("precondition", "The hand is not holding anything."))
        held = self.held
        drops = self.drop_configurations(
            self._q(), held.surroundings, held.points_tcp, held.as_seen_tcp
        )
        if not drops:
            msg = "The arm cannot hold the object over the basket; it keeps it."
            return Outcome(Failure("ik_plan", msg))
        self.progress("Carrying the object to the basket.")
        failure = self._rise_clear(held.surroundings, held.points_tcp)
        if failure is not None:
            return Outcome(failure)
        high = self._holding_pose(dims.UR5_HIGH_READY_Q, held.surroundings, held.points_tcp)
        for q_drop in drops[:DROP_TRIES]:
            out = self.go_to(
                q_drop,
                held.surroundings,
                "carrying to the basket",
                via=(high,),
                payload=held.points_tcp,
            )
            if out.ok or out.failure is None or out.failure.kind != "ik_plan":
                break  # there, or a motion was stopped: no other posture is tried
        if not out.ok:
            return out
        lost = self._lost_on_the_way("the basket")
        if lost is not None:
            return lost
        self._let_go()
        self.progress("Released into the basket.")
        # The open hand rises off the object before it turns away: a tall bottle stands up
        # out of the basket, and a straight way to ready swept the fingers through it (152 N,
        # a protective stop). The object can only have fallen from where the hand let go.
        T = tcp_pose(self._q())
        let_go = held.standing_at(T)
        caution = PAST_THE_OPENING if past_the_opening(let_go).any() else None

        def said(out: Outcome) -> Outcome:
            if caution is None:
                return out
            if out.failure is None:
                return replace(out, caution=caution)
            failure = Failure(out.failure.kind, f"{out.failure.message} {caution}")
            return replace(out, failure=failure)

        around = CollisionChecker(
            np.vstack([held.surroundings.points, let_go]),
            margin=self.settings.motion.clearance,
            filtered=True,
        )
        failure = self._rise_clear(around, hand_on_the_way=False)
        if failure is not None:
            return said(Outcome(failure))
        # Around the object as it was let go, else as it fell, lower (no way around it). To
        # ready; parked at a shelf or a high table, whose boards fill both ready poses (10 of
        # 67 in-situ attempts once ended there, the object in the basket), folded away from
        # the basket instead, as the session's stow would do next.
        for leave in (self.go_ready, self._fold_away):
            for checker in (around, held.surroundings):
                back = leave(checker)
                if back.failure is None or back.failure.kind != "ik_plan":
                    return said(back)
        return said(back)

    def place(self, cloud: FusedCloud, mark: np.ndarray) -> Outcome:
        """Set what the hand holds down at a place mark (004 section 7.3, EL-E 000 4.5).

        cloud: a fresh capture's fused cloud (the held object and the arm in it are ignored);
        mark: the place mark (m, `base`). The mark must be on a flat surface (moved back from
        its front edge if it is too close). The object goes down with the grasp's orientation
        kept, so that it stands as it stood, its grasp height above the surface: straight
        down from 10 cm above until the surface is felt (`place_contact_force`), eased
        `place_ease` back up, then the hand opens and leaves it (drawn back along its
        approach where that way is clear, else straight up), and the arm stows around the
        object where it now stands. Felt more than `place_above` early, it is something on
        the surface: the hand keeps the object and rises. Nothing felt by `place_below`
        under the rest: the hand keeps it.
        """
        s = self.settings.motion
        if self.held is None or not self.robot.gripper_state().holding:
            self.held = None
            return Outcome(Failure("precondition", "The hand is not holding anything."))
        held = self.held
        spot = place_target(cloud, mark, self.settings.perception)
        if isinstance(spot, Failure):
            return Outcome(Failure("precondition", f"I can't place there: {spot.message}."))
        q_now = self._q()
        obstacles = cloud.points[not_carried(cloud.points, held.at(tcp_pose(q_now)))]
        checker = CollisionChecker(obstacles, margin=s.clearance, q_self=q_now)
        found = self._place_poses(held, spot, q_now, checker)
        if isinstance(found, Failure):
            return Outcome(found)
        q_above, down, T_above = found
        self.progress("Carrying the object to the place mark.")
        out = self._carry_to(q_above, checker, spot, held)
        if not out.ok:
            return out
        lost = self._lost_on_the_way("the place")
        if lost is not None:
            return lost
        failure = self._descend(down, s.approach_speed, "lowering the object")
        if failure is None:
            # Past the surface's height and nothing felt (EL-E 000 section 4.5): the surface
            # is not where it was seen. Keep the object, and rise to wait for another mark.
            self._rise_straight(T_above, "rising from the place")
            past = f"{s.place_below * 100:.0f} cm past where it should touch the surface"
            return Outcome(
                Failure("execute", f"I lowered the object {past}, felt nothing, and kept it.")
            )
        if "unexpected contact" not in failure.message:
            return Outcome(failure)
        # How far above the rest (T_above is approach_distance above it) the descent stopped.
        early = float(tcp_pose(self._q())[2, 3] - T_above[2, 3] + s.approach_distance)
        if early > s.place_above:
            self._rise_straight(T_above, "rising from what it met")
            return Outcome(
                Failure(
                    "execute",
                    f"The object met something {early * 100:.0f} cm above the surface there,"
                    " so I kept it. Mark another spot.",
                )
            )
        # The guard stop is the surface met: let go there, eased off it.
        self._ease_off_surface()
        self._let_go()
        T_release = tcp_pose(self._q())
        failure = self._leave_placed(T_above, checker)
        if failure is not None:
            return Outcome(failure, held.grasp, spot=spot)
        # Stowed around the object where it now stands: the unchecked moves of a stow swept
        # the hand through it from the 87 cm counter (4 of 39 pick-place tasks ended with
        # the object pushed 12-20 cm away or off the counter). Where it was let go, as held,
        # and as the cameras now see it: a cereal box that had slid and turned in the pads
        # stood 3 cm from where it was held, and the wrist met it on the way home (156 N).
        standing = held.standing_at(T_release)
        seen = np.vstack([checker.points, self._seen_now()])
        around = CollisionChecker(np.vstack([seen, standing]), margin=s.clearance, filtered=True)
        # A guard stop short of the surface (the wrist met the floor: 2 of 39 pick-place
        # tasks) leaves the straight rise short of clearing the object.
        failure = self._rise_clear(around, hand_on_the_way=False)
        if failure is not None:
            return Outcome(failure, held.grasp, spot=spot)
        # First around a wall under the surface's seen front (`surface_front`: a counter's
        # front runs out of the cameras' view before its top does), then without it.
        front = front_wall(seen, float(spot[2]))
        back = self.stow(around.with_points(front))
        if back.failure is not None and back.failure.kind == "ik_plan" and len(front):
            back = self.stow(around)
        if back.failure is not None and back.failure.kind == "ik_plan":
            # The object as held stands for more than it is (a plush toy's mirrored back):
            # the hand drawn 5 cm back out of one still stood 2 mm inside it, and no way
            # home could start. Around what the cameras see alone, the session's own stow
            # then found one.
            back = self.stow(CollisionChecker(seen, margin=s.clearance, filtered=True))
        if back.failure is not None:
            msg = back.failure.message
            failure = Failure(back.failure.kind, f"Set down; then {msg[:1].lower()}{msg[1:]}")
            return Outcome(failure, held.grasp, spot=spot)
        self.progress("Placed.")
        return Outcome(None, held.grasp, spot=spot, standing=standing)

    def _carry_to(
        self, q_above: np.ndarray, checker: CollisionChecker, spot: np.ndarray, held: Held
    ) -> Outcome:
        """Carry what the hand holds to q_above (6,) rad, over the place `spot` (m, `base`),
        around `checker`, first also around a wall under the spot's surface's seen front
        (`surface_front`), then without it. A plush toy held by its head hangs 11 cm below
        the hand: carried up to the 87 cm counter around what the cameras saw, it was
        swept through the counter's unseen front up to 3 cm under its top (19 N), turned
        27° in the pads, and was set down on its side."""
        front = front_wall(checker.points, float(spot[2]))
        tries = [checker.with_points(front), checker] if len(front) else [checker]  # floor: none
        for around in tries:
            out = self.go_to(
                q_above,
                around,
                "carrying to the place",
                via=(self._holding_pose(dims.UR5_HIGH_READY_Q, around, held.points_tcp),),
                payload=held.points_tcp,
            )
            if out.failure is None or out.failure.kind != "ik_plan":
                break
        return out

    def _leave_placed(self, T_above: np.ndarray, checker: CollisionChecker) -> Failure | None:
        """Take the open hand off what it has just set down: drawn back along its approach
        if that way is clear of `checker` (which leaves the object out: the fingers start
        about it), else straight up to the TCP pose T_above (4, 4, `base`), the way it came
        down. Risen straight up from the side, the hand stayed about a tall box's top (a
        cereal box that had slid 3.6 cm down in the pads stood 1 cm above the fingers), and
        no way to ready was found.

        A hand within LEAVE_LEVEL of level with a clear way back is first lowered
        LEAVE_DROP (`_lower_open_hand`), so that a pad under a lip of the object leaves it.
        Only with a clear way back: lowered first, a hand with none found one 5 mm lower,
        close along the 31 cm table's top, and from where it ended no way to ready was
        found, where rising straight up from the cereal box it had set down found one. A
        hand whose open pads still press something (`_caught`) is lowered first from any
        approach (PADS_CLEAR): the finger that had dragged a mug 3.6 cm as it opened then
        lifted it 9 cm by its handle; lowered, it came free. Pads that still feel anything
        then are eased off it sideways (`_ease_pads_off`), and the hand leaves from there:
        risen straight up, it goes up beside the way it came down, by as much as it was
        eased (at most LEAVE_SHIFT), unchecked as that way is."""
        start = tcp_pose(self._q())
        approach = start[:3, 2]
        back = self._withdrawal(approach, checker, level=False)
        level = abs(approach[2]) < np.sin(LEAVE_LEVEL)
        caught = self._caught()
        if caught or (back is not None and level):
            self._lower_open_hand(start)
            back = self._withdrawal(approach, checker, level=False)
        eased = np.zeros(3)
        if caught:  # even if lowered they feel nothing: what leaned on a pad still leans
            eased = self._ease_pads_off()
            back = self._withdrawal(approach, checker, level=False)
        if back is None:
            T_up = T_above.copy()
            T_up[:3, 3] += eased
            self._rise_straight(T_up, "rising from the object")
            return None
        return self._draw_back(back)

    def _ease_pads_off(self) -> np.ndarray:
        """Ease the open hand sideways off what its pads touched, and say how far it moved
        (3,) (m, `base`).

        Along the closing axis by LEAVE_SHIFT, one way and, where the pads still feel
        something there, the other, slowly and guarded at LEAVE_NUDGE over what the pads
        bear: the gripper feels only the pads' summed force, not which pad, so the way into
        the object is found by touch, and stopped before it pushes the object over. Rising
        with a pill bottle leaning on one open pad, the hand lifted it and carried it off."""
        s = self.settings.motion
        start = tcp_pose(self._q())
        for sign in (1.0, -1.0):
            T = start.copy()
            T[:3, 3] += sign * LEAVE_SHIFT * start[:3, 1]
            path = cartesian_line(self._q(), T, s.cartesian_step / 5)
            if path is None:
                continue
            aside = timed(path, s, tcp_speed=LEAVE_SPEED)
            guard = self._pads_feel() + LEAVE_NUDGE
            # Stopped at the guard is how the way into the object is found: not a failure.
            self._run(Trajectory(aside.times, aside.q, guard_force=guard), "easing the pads off")
            if not self._caught():
                break
        # Touching either way, it leaves from where it is: pushed back between, unguarded, a
        # pill bottle that had followed the pad was pushed with 4.8 N.
        return tcp_pose(self._q())[:3, 3] - start[:3, 3]

    def _lower_open_hand(self, start: np.ndarray) -> None:
        """Lower the open hand LEAVE_DROP straight down from TCP pose `start` (4, 4, `base`),
        guarded as the place's descent: a pad whose top edge is under a lip of what it let go
        of leaves it, rather than lifting it by it on the way out. A hand that comes down on
        something instead (a shoulder of the object, the surface) goes back up to `start`:
        drawn back from where it had met a spice jar's shoulder, a finger dragged it (196
        N, a protective stop)."""
        s = self.settings.motion
        T = start.copy()
        T[2, 3] -= LEAVE_DROP
        down = cartesian_line(self._q(), T, s.cartesian_step / 5)
        if down is None:
            return
        met = self._descend(down, LEAVE_SPEED, "freeing the fingers", felt=self._pads_feel())
        self.robot.sleep(LEAVE_SETTLE)  # the servos lag the trajectory's clock
        if met is not None:
            self._rise_straight(start, "rising off what the fingers met")

    def _seen_now(self) -> np.ndarray:
        """What the cameras see around the arm now (m, `base`), thinned, the arm's own
        points left out; none if the capture fails (the caller still has what it saw
        before)."""
        try:
            points = fuse(self.robot.capture(), self.settings.perception).points
        except Exception:
            log.exception("No fresh capture; going on with the last one.")
            return np.zeros((0, 3))
        return points[obstacle_mask(points, q_self=self._q())]

    def _rise_straight(self, T: np.ndarray, what: str) -> None:
        """Rise in a straight line to TCP pose T (4, 4, `base`) at the approach speed, if the
        arm can (no check for collisions: the way back up is the way it came down)."""
        s = self.settings.motion
        up = cartesian_line(self._q(), T, s.cartesian_step)
        if up is not None:
            self._run(timed(up, s, tcp_speed=s.approach_speed), what)

    def _place_poses(
        self, held: Held, spot: np.ndarray, q_now: np.ndarray, checker: CollisionChecker
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | Failure:
        """Where to set the object down at `spot` (m, `base`): the joint angles above it, the
        straight path down (to `place_below` under the object's rest, where the descent
        looks for the surface), and the pose above. The grasp's orientation is kept, so that the
        object stands as it stood, turned about the vertical if the arm cannot reach it
        unturned (PLACE_YAWS): a turned object still stands upright, and where it would have
        stood unturned (the hand over the mark, 004 section 7.3). The arm (not the hand and
        what it holds, which go down onto the surface) must keep clear of `checker` on the
        way down to the rest: unchecked, the wrist came down 3 mm over a mug set down
        earlier beside the spot, and after the release the hand found no way out. The
        surface itself (its points within `surface.SURFACE_BAND` of its height) it must only
        not reach into, and may come nearer than the margin: a spice jar held from the side
        3.8 cm above its support goes down with the wrist's spheres 2 mm over the table, as
        they were over the shelf it was picked from. So with the floor, for a spot on it."""
        s = self.settings.motion
        reached = False
        #: What the arm would come too near on a way down: the floor, the surface, or other
        #: things (a keep-out box, points of the cloud), and those points.
        crowded: set[str] = set()
        crowding = [np.zeros((0, 3))]
        if on_floor(float(spot[2])):
            # On the floor, the floor is the support: held level from the side 8 cm above
            # it, a pill bottle would go down with the wrist's spheres 8 mm over the floor,
            # as over a table top, and was refused three times for the floor's 2 cm margin.
            checker = checker.floor_as_support()
        surface = np.abs(checker.points[:, 2] - spot[2]) < SURFACE_BAND
        around, support = checker.without(surface), checker.without(~surface)
        # The middle of the held object, from the hand (m, `base` axes at the grasp).
        middle = held.grasp.pose[:3, :3] @ held.middle_tcp
        rest = spot[2] + held.height_above_support  # the hand's height with the object down
        for dyaw in PLACE_YAWS:
            T_place = held.grasp.pose.copy()
            T_place[:3, :3] = rotz(dyaw) @ T_place[:3, :3]
            T_place[:3, 3] = [*turned_hand_xy(spot[:2], middle[:2], dyaw), rest - s.place_below]
            T_above = T_place.copy()
            T_above[2, 3] = rest + s.approach_distance
            # Nearest the poses in front first, whether the object is tucked in or raised.
            clear = [
                q
                for q in ik_tcp(T_above, dims.UR5_HIGH_READY_Q)
                if checker.clearance_ok(q, payload=held.points_tcp)[0]
            ]
            reached = reached or bool(clear)
            T_rest = T_place.copy()
            T_rest[2, 3] = rest
            for q_above in clear:
                down = cartesian_line(q_above, T_place, s.cartesian_step)
                to_rest = cartesian_line(q_above, T_rest, s.cartesian_step)
                if down is None or to_rest is None:
                    continue
                near = around.clearance_ok(to_rest, hand=False)
                into = support.clearance_ok(to_rest, hand=False, margin=0.0)
                if not (near.all() and into.all()):
                    k = int(np.argmin(near & into))  # the first posture that fails
                    hits = around.what_hits(to_rest[k], hand=False) if not near[k] else []
                    crowded.update(["floor"] if "floor" in hits else hits or ["surface"])
                    if "cloud" in hits:
                        crowding.append(around.points_near(to_rest[k], hand=False))
                    continue
                return q_above, down, T_above
        if not reached:
            return Failure("ik_plan", "The arm cannot reach above that spot.")
        if crowded and crowded <= {"floor", "surface"}:
            # A place keeps the grasp's orientation: a jar held from a shelf's edge with the
            # hand tilted up would take the wrist into the floor, mark after mark, where
            # "too close to something" told the user nothing they could see.
            floor = on_floor(float(spot[2])) or "surface" not in crowded
            into_what = "the floor" if floor else "the surface"
            return Failure(
                "ik_plan",
                f"Held as it is, the arm would reach into {into_what} to set it down there.",
            )
        if crowded:
            return Failure("ik_plan", crowded_message(np.vstack(crowding), spot))
        return Failure("ik_plan", "The arm cannot lower the object there.")

    @staticmethod
    def _without_leftovers(
        surroundings: CollisionChecker, carried: np.ndarray, support: float
    ) -> CollisionChecker:
        """`surroundings` less the points within CARRIED_PADDING of the object's carried
        shape (`carried`, m, `base`: `carried_shape`, what the cameras saw of it, its guessed
        back and the column down to the surface it stood on, at `support`, m) and more than
        SUPPORT_SCATTER above that surface: the object's own, which leave with it. Parts of
        it the segmentation left out (a spray bottle's trigger head, a pill bottle's lower
        back 2.7 cm above the 69 cm board), or that the views from the way in saw where no
        camera sees now. Kept, they stood where the lifted object then hung, and no carry
        or tuck could start."""
        pts = surroundings.points
        if len(pts) == 0 or len(carried) == 0:
            return surroundings
        return surroundings.without(
            ~not_carried(pts, carried) & (pts[:, 2] > support + SUPPORT_SCATTER)
        )

    def approach(self, perception: Perception) -> Perception | Failure:
        """Jeeves' centroid approach (003 section IV): drive the base until the perceived
        target's centroid sits at the arm's grasping spot, re-perceiving it as the scooter
        moves (where to look comes from the wheel odometry: the target's top, a point on its
        surface). Returns the last perception of the target, for the grasp."""
        if perception.segmentation is None:
            return Failure("precondition", "There is no target to drive to.")
        pose = self.robot.base_pose()
        for _ in range(APPROACH_MAX_STEPS):
            if self.should_stop():
                self.robot.drive(0.0, 0.0, 0.1)
                return Failure("execute", "The drive to the object was cancelled.")
            points = perception.target_points.astype(float)
            centroid = points.mean(axis=0)
            top = points[points[:, 2] > points[:, 2].max() - 0.01].mean(axis=0)
            cmd = centroid_approach(centroid, self.settings.approach)
            if cmd.done:
                self.robot.drive(0.0, 0.0, 0.1)
                self.robot.sleep(1.0)  # the ramp down; then look once more, at rest
            else:
                self.robot.drive(cmd.v, cmd.w, 0.5)
                self.robot.sleep(APPROACH_PERIOD)
            # The scooter moved since the last look (in the ramp down too: turning at 0.46
            # rad/s, by 13 degrees): where the target's top is now comes from the odometry.
            new_pose = self.robot.base_pose()
            moved = invert(planar_pose(*new_pose)) @ planar_pose(*pose)
            pose = new_pose
            perception = perceive(self.robot.capture(), point=(moved @ np.append(top, 1.0))[:3])
            if perception.segmentation is None:
                self.robot.drive(0.0, 0.0, 0.1)
                return Failure("detect_laser", "I lost sight of the object.")
            if cmd.done:
                return perception
        self.robot.drive(0.0, 0.0, 0.1)
        return Failure("execute", "The scooter did not reach the object.")
