"""pick-place (004 section 8.3): every `kitchen` object, upright or on its side by coin flip;
the user drives to it, the robot picks it (manual selection), the user drives to another
surface and marks a free spot, and the robot sets it down there. As in in-situ, the user
tries again (at most MAX_TRIES picks, and as many place marks) while that can still finish
the task.
"""

from __future__ import annotations

import math
import re

import numpy as np
import yaml

from laserpick.bench.attempts import Attempt
from laserpick.bench.parking import NO_PARKING, park
from laserpick.bench.picking import Placed, ScriptedOperator
from laserpick.bench.protocols.place_spots import aim_as_told, aims_in_sight, free_spot, room_for
from laserpick.bench.protocols.retries import MAX_TRIES, TaskSpot, still_there
from laserpick.bench.protocols.trials import (
    Options,
    instances,
    limit,
    protocol_scene,
    scripted_operator,
    shuffled,
)
from laserpick.bench.referee import Referee
from laserpick.description import dims
from laserpick.description.kinematics import tcp_pose
from laserpick.robot.sim.objects import ObjectModel
from laserpick.robot.sim.scenes import Scene, SceneError, Surface, parse_scene, scene_config
from laserpick.server.session import HOLDING_STATES, TaskState
from laserpick.transforms import matrix_from_quat
from laserpick.types import Failure

#: A placed object counts as upright when its up axis is tilted under this (rad) from how it
#: stood before, and as on target within this distance (m) of the mark plus its offset
#: (`set_down_error`).
UPRIGHT_TILT = math.radians(15.0)
PLACE_TOLERANCE = 0.03


def pick_place(trial: int, seed: int, opt: Options) -> list[Attempt]:
    """One pick-place trial: every object picked and set down on another surface."""
    rng = np.random.default_rng(seed)
    scene = protocol_scene("", seed, opt) if opt.scene else coin_flip_kitchen(rng)
    out = []
    with scripted_operator(scene, trial, seed, opt) as op:
        for task, name in enumerate(limit(shuffled(op, instances(scene)), opt)):
            op.begin_task(task)
            spot = TaskSpot(op, scene, name)
            op.back_up, op.park_left = spot.back_up, spot.park_left
            for _ in range(MAX_TRIES):
                rec = op.new_attempt(name, opt.selection, opt.strategy)
                rec.task = task
                stood = op.referee.world_position(name)
                out.append(_move_object(op, scene, rec, spot))
                op.tidy()
                if rec.success or rec.message == NO_PARKING or not still_there(op, name, stood):
                    break
                spot.after(rec)
    return out


def coin_flip_kitchen(rng: np.random.Generator) -> Scene:
    """The `kitchen` scene with each object upright or on its side by a coin flip. An object
    that does not fit its spot on its side (a cereal box lying on a shelf's edge), or does
    not rest on its side (a banana's curve tips it over, `objects.at_rest`), stands upright
    instead, as the experimenter would set it."""
    config = scene_config("kitchen")
    objects = config["objects"]
    for obj in objects:
        obj["lying"] = bool(rng.integers(2))
    while True:
        try:
            return parse_scene(yaml.safe_dump(config, sort_keys=False))
        except SceneError as e:
            misfits = [int(m[1]) for path, _ in e.problems if (m := _OBJECT_PATH.match(path))]
            lying = [i for i in misfits if objects[i]["lying"]]
            if not lying:
                raise
            for i in lying:
                objects[i]["lying"] = False


_OBJECT_PATH = re.compile(r"objects\[(\d+)\]")


def _up_in_object(quat: np.ndarray) -> np.ndarray:
    """The world's up in the frame of an object at orientation `quat` (w, x, y, z): it stays
    put when the object turns about the vertical. (The object's own z axis does not: by it a
    can lying on its side, set down turned a quarter turn, as a place may turn it, would
    count as tipped 90 degrees.)"""
    return matrix_from_quat(quat).T @ np.array([0.0, 0.0, 1.0])


def round_about_z(model: ObjectModel) -> bool:
    """Whether `model` is a body of revolution about its frame's z axis: only cylinders,
    capsules and spheres, centred on that axis, the cylinders and capsules along it."""
    for part in model.parts:
        if part.kind not in ("cylinder", "capsule", "sphere") or np.hypot(*part.pos[:2]) > 1e-6:
            return False
        if part.kind != "sphere" and abs(matrix_from_quat(np.array(part.quat))[2, 2]) < 1 - 1e-9:
            return False
    return True


def placed_tilt(model: ObjectModel, before: np.ndarray, after: np.ndarray) -> float:
    """How far (rad) an object of `model` was tipped between orientations `before` and
    `after` (w, x, y, z): the angle between the world's up in its frame then and now. A
    turn about the vertical is no tilt. Nor, for a body of revolution, is a roll about its
    own axis, which leaves it looking as it was: a can set down on its side that rolls a
    little rests as it rested. Its tilt is then the change in its axis' angle to the
    vertical."""
    up_before, up_after = _up_in_object(before), _up_in_object(after)
    if round_about_z(model):
        angles = np.arccos(np.clip([up_before[2], up_after[2]], -1.0, 1.0))
        return float(abs(angles[1] - angles[0]))
    return math.acos(float(np.clip(up_before @ up_after, -1.0, 1.0)))


def set_down_error(
    referee: Referee, instance: str, anchor: np.ndarray, hit: np.ndarray, offset: np.ndarray
) -> float:
    """How far (m, level) `instance` rests from where its place mark puts it: its footprint's
    middle as it stood before the pick (`anchor`, `Referee.footprint_middle`, m, its own
    frame) from the laser's dot `hit` (m, `base`) plus `offset`, that point's offset from
    the hand as held (m, `base` xy, the grasp's orientation)."""
    return float(np.linalg.norm(referee.body_point(instance, anchor)[:2] - hit[:2] - offset))


def _move_object(op: ScriptedOperator, scene: Scene, rec: Attempt, spot: TaskSpot) -> Attempt:
    """One 004 section 8.3 attempt: pick `rec.instance`, parked at the task's `spot`, and set
    it down on another surface."""
    session, referee = op.session, op.referee
    if not spot.go():
        return rec.fail("precondition", NO_PARKING)
    session.set_mode(op.actor, mode="pick_and_place")
    quat_before = referee.world_quat(rec.instance)
    anchor = referee.footprint_middle(rec.instance)
    room = room_for(op, rec.instance)
    if not op.pick(rec) or rec.failure is not None:
        return rec
    if session.state != TaskState.AWAITING_PLACE:
        return rec.fail("execute", f"the session is {session.state.value}, not awaiting a mark")
    offset = _held_offset(op, rec.instance, anchor)
    here = scene.placement(rec.instance).surface
    placed, dest, refused = _place_elsewhere(op, scene, rec, _destinations(scene, here), room)
    if placed is None:
        return rec.fail("precondition", "; ".join(refused) or "no surface to put it on")
    if placed.failure is not None or placed.hit is None:
        failure = placed.failure or Failure("detect_laser", "the laser lit nothing")
        return rec.fail(failure.kind, failure.message)
    assert dest is not None  # placed there
    op.robot.sleep(0.5)
    error = set_down_error(referee, rec.instance, anchor, placed.hit, offset)
    model = scene.placement(rec.instance).model
    tilt = placed_tilt(model, quat_before, referee.world_quat(rec.instance))
    rec.surface = f"{here} -> {dest.name}"
    if tilt > UPRIGHT_TILT:
        return rec.fail("execute", f"set down tilted {math.degrees(tilt):.0f} deg")
    if error > PLACE_TOLERANCE:
        return rec.fail("execute", f"set down {error * 100:.1f} cm from the mark")
    rec.success = True
    return rec


def _held_offset(op: ScriptedOperator, instance: str, anchor: np.ndarray) -> np.ndarray:
    """Where the middle of the held object's footprint (`anchor`, m, its own frame) sits
    relative to the TCP when it is set down (m, `base` xy): the hand holds it tucked in now,
    and the place turns the hand back to the grasp's orientation. Not its origin, the middle
    of its bottom face, which lies at one end of an object on its side: a place turned about
    the vertical turns the object about its middle (`behaviours.turned_hand_xy`). Nor its
    centre of mass, high in a tall box that may turn in the pads and right itself on the
    surface."""
    T_tcp = tcp_pose(op.robot.joint_state().q)
    in_hand = T_tcp[:3, :3].T @ (op.referee.body_point(instance, anchor) - T_tcp[:3, 3])
    held = op.session.behaviours.held
    assert held is not None  # awaiting a place mark: the session holds it
    return (held.grasp.pose[:3, :3] @ in_hand)[:2]


def _destinations(scene: Scene, here: str) -> list[Surface]:
    """The surfaces the user may set an object from `here` down on: the others they can mark
    from the seat (a top above their hand, such as the 100 cm shelf top or the 108 cm table,
    shows them only its front edge), or `here` itself where there is none."""
    markable = [s for s in scene.surfaces if s.levels[-1] < dims.LASER_ORIGIN[2] - 0.05]
    return [s for s in markable if s.name != here] or [scene.surface(here)]


def _place_elsewhere(
    op: ScriptedOperator, scene: Scene, rec: Attempt, dests: list[Surface], room: float
) -> tuple[Placed | None, Surface | None, list[str]]:
    """Set the held `rec.instance` down on one of `dests`, taken in a random order: where a
    surface has no free spot (`room` m about it), no way to park at it, or the robot refused
    every mark there (held as it is, the arm would reach into the floor), the user takes the
    next, as a person with something in hand would. Returns the last place (None: none was
    tried), the surface it was tried on, and why each surface before it was given up."""
    refused = []
    placed = None
    dest = None
    for dest in (dests[int(k)] for k in op.rng.permutation(len(dests))):
        spot = free_spot(op, dest, room, rec.instance)
        if spot is None:
            refused.append(f"no free spot on {dest.name}")
            continue
        local_y, spot_world = spot
        local_x = float(dest.to_local(spot_world[:2])[0])
        outline = op.referee.outline()  # the object in hand included
        works_at = None if dest.kind == "floor" else dest.name
        if not park(op, scene, dest, local_x, local_y, spot_world[2], works_at, outline):
            refused.append(f"the user could not park at {dest.name}")
            continue
        placed = _mark_until_placed(op, dest, spot_world, room, rec)
        if placed.failure is None or op.session.state not in HOLDING_STATES:
            break
        refused.append(f"{dest.name}: {placed.failure.message}")
    return placed, dest, refused


def _mark_until_placed(
    op: ScriptedOperator, dest: Surface, spot: np.ndarray, room: float, rec: Attempt
) -> Placed:
    """Mark `spot` (m, `world`, on `dest`) for the held `rec.instance`, and mark again (at
    most MAX_TRIES marks in all, each counted in `rec.places`) while the robot refuses and
    the hand still holds it: where the robot said which way to move the mark, that way
    (`aim_as_told`), else the next aim in sight (`aims_in_sight`)."""
    aims = aims_in_sight(op, dest, spot, room, rec.instance)
    aim = next(aims)
    placed = None
    for tries_left in reversed(range(MAX_TRIES)):
        placed = op.place(aim)
        rec.places += 1
        if placed.failure is None or op.session.state not in HOLDING_STATES or not tries_left:
            break
        told = aim_as_told(op, dest, aim, placed.failure.message, room, rec.instance)
        aim = next(aims) if told is None else told
    assert placed is not None  # MAX_TRIES >= 1 marks
    return placed
