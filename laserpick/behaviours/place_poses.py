"""Where to set an object down at a place spot: the pose above it and the straight way down,
with the grasp's orientation kept (turned about the vertical where it must be), and why
there is none when there is none."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from laserpick.behaviours.held import Held
from laserpick.behaviours.messages import crowded_message
from laserpick.description import dims
from laserpick.description.kinematics import ik_tcp
from laserpick.pipeline.collision import CollisionChecker, obstacle_mask, surface_front
from laserpick.pipeline.lines import cartesian_line
from laserpick.pipeline.surface import SURFACE_BAND, on_floor
from laserpick.settings import Settings
from laserpick.transforms import rotz
from laserpick.types import Failure

__all__ = ["PlacePoses", "front_wall", "place_poses", "turned_hand_xy"]


class PlacePoses(NamedTuple):
    """How a place sets the object down: q_above, the joint angles (6,) (rad) above the
    spot; down, the straight joint path (N, 6) from there to `place_below` under the
    object's rest, where the descent looks for the surface; T_above, the TCP pose (4, 4,
    `base`) above the spot."""

    q_above: np.ndarray
    down: np.ndarray
    T_above: np.ndarray


def turned_hand_xy(spot_xy: np.ndarray, middle_xy: np.ndarray, dyaw: float) -> np.ndarray:
    """Where the hand goes (m, `base` xy) to set an object down turned by dyaw (rad) about
    the vertical, so that its middle lands where it would unturned with the hand at
    spot_xy. middle_xy: the object's middle from the hand, unturned (m). The turn is about
    the object's middle: about the hand, an object held 7 cm off its middle would land
    14 cm from where it should when turned a half turn."""
    return np.asarray(spot_xy, float) + middle_xy - rotz(dyaw)[:2, :2] @ middle_xy


def front_wall(points: np.ndarray, height: float) -> np.ndarray:
    """The points (m, `base`) of a wall under the seen front of the surface at `height` (m)
    in the cloud `points` (N, 3; `base`), as a checker takes them (`surface_front`,
    `obstacle_mask`): none for the floor."""
    front = surface_front(points, height, SURFACE_BAND)
    return front[obstacle_mask(front, voxel=0.0)]


@dataclass
class _Obstruction:
    """What the arm came too near on the ways down tried: kinds ("floor", "surface", or what
    `CollisionChecker.what_hits` names) and the cloud's points it came near (m, `base`)."""

    kinds: set[str] = field(default_factory=set)
    points: list[np.ndarray] = field(default_factory=lambda: [np.zeros((0, 3))])


def place_poses(
    held: Held, spot: np.ndarray, checker: CollisionChecker, settings: Settings
) -> PlacePoses | Failure:
    """Where to set the object `held` down at `spot` (m, `base`), or why it cannot be.

    The grasp's orientation is kept, so that the object stands as it stood, turned about
    the vertical if the arm cannot reach it unturned (`place_yaws`): a turned object still
    stands upright, and where it would have stood unturned (the hand over the mark, 004
    section 7.3). The arm (not the hand and what it holds, which go down onto the surface)
    must keep clear of `checker` on the way down to the rest: unchecked, a wrist can come
    down on an object set down earlier beside the spot, and leave the open hand no way out.
    The surface itself (its points within `surface.SURFACE_BAND` of its height) it must
    only not reach into, and may come nearer than the margin: a jar held from the side a
    few centimetres above its support goes down with the wrist's spheres millimetres over
    the surface, as they were at the pick. So with the floor, for a spot on it."""
    s = settings.motion
    reached = False
    obstruction = _Obstruction()
    if on_floor(float(spot[2])):
        checker = checker.floor_as_support()
    surface = np.abs(checker.points[:, 2] - spot[2]) < SURFACE_BAND
    around, support = checker.without(surface), checker.without(~surface)
    # The middle of the held object, from the hand (m, `base` axes at the grasp).
    middle = held.grasp.pose[:3, :3] @ held.middle_tcp
    rest = spot[2] + held.height_above_support  # the hand's height with the object down
    for dyaw in settings.behaviour.place_yaws:
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
            down = _way_down(
                q_above, T_place, T_rest, around, support, s.cartesian_step, obstruction
            )
            if down is not None:
                return PlacePoses(q_above, down, T_above)
    return _refusal(reached, obstruction, spot)


def _way_down(
    q_above: np.ndarray,
    T_place: np.ndarray,
    T_rest: np.ndarray,
    around: CollisionChecker,
    support: CollisionChecker,
    step: float,
    obstruction: _Obstruction,
) -> np.ndarray | None:
    """The straight joint path (N, 6) from q_above down to TCP pose T_place, where the arm
    keeps clear of `around` and out of `support` down to T_rest; None where it does not,
    with what it came too near added to `obstruction`. step: waypoint spacing (m)."""
    down = cartesian_line(q_above, T_place, step)
    to_rest = cartesian_line(q_above, T_rest, step)
    if down is None or to_rest is None:
        return None
    near = around.clearance_ok(to_rest, hand=False)
    into = support.clearance_ok(to_rest, hand=False, margin=0.0)
    if near.all() and into.all():
        return down
    k = int(np.argmin(near & into))  # the first posture that fails
    hits = around.what_hits(to_rest[k], hand=False) if not near[k] else []
    obstruction.kinds.update(["floor"] if "floor" in hits else hits or ["surface"])
    if "cloud" in hits:
        obstruction.points.append(around.points_near(to_rest[k], hand=False))
    return None


def _refusal(reached: bool, obstruction: _Obstruction, spot: np.ndarray) -> Failure:
    """Why no way down to `spot` was found, in words the user can act on."""
    if not reached:
        return Failure("ik_plan", "The arm cannot reach above that spot.")
    crowded = obstruction.kinds
    if crowded and crowded <= {"floor", "surface"}:
        # A place keeps the grasp's orientation: a jar held with the hand tilted up would
        # take the wrist into the floor mark after mark, and "too close to something"
        # tells the user nothing they can see.
        floor = on_floor(float(spot[2])) or "surface" not in crowded
        into_what = "the floor" if floor else "the surface"
        return Failure(
            "ik_plan",
            f"Held as it is, the arm would reach into {into_what} to set it down there.",
        )
    if crowded:
        return Failure("ik_plan", crowded_message(np.vstack(obstruction.points), spot))
    return Failure("ik_plan", "The arm cannot lower the object there.")
