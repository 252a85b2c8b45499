"""One scripted pick-and-drop trial, as 004 section 8.1 ran them: the operator marks an object
with the laser, the robot perceives, finds grasps, picks and drops the object in the basket,
and the referee scores it. Shared by the picking benchmarks.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from laserpick.behaviours import Behaviours
from laserpick.bench.operator import Referee, mark_and_capture
from laserpick.description import dims
from laserpick.pipeline.grasping import GraspSet, Strategy, find_grasps
from laserpick.pipeline.perceive import Perception, perceive
from laserpick.pipeline.types import Failure, Grasp
from laserpick.robot.sim_robot import SimRobot

#: The columns of the failure table: 004's kinds (Table 1), and "precondition" (e.g. no object
#: at the mark).
#: Marks the operator makes again after the mark itself failed (a missed dot, no object).
REMARKS = 2
FAILURE_KINDS = (
    "detect_laser",
    "precondition",
    "detect_grasp",
    "ik_plan",
    "wrong_object",
    "execute",
)


@dataclass
class Attempt:
    """The record of one marked object."""

    instance: str
    model: str
    detected: bool = False  #: the grasp chosen was on the marked object
    success: bool = False  #: the marked object ended up in the basket
    failure: str | None = None  #: a FailureKind, when it did not succeed
    message: str = ""
    timings: dict[str, float] = field(default_factory=dict)  #: s per pipeline stage
    stuck: bool = False  #: the arm found no way home afterwards and was moved by hand

    @property
    def decide_time(self) -> float:
        """Grasp detection, filter, selection and planning (s): 004's 4.7 + 1.6 + 2.9 s."""
        return sum(self.timings.get(k, 0.0) for k in ("detect", "filter", "select", "plan"))


def stow(robot: SimRobot, behaviours: Behaviours) -> Failure | None:
    """Empty the hand and fold the arm out of the cameras' view for the next capture.

    When the arm finds no way back, the experimenter moves it home by hand (the simulator
    sets the joints), so that one stuck attempt does not end the experiment; the failure is
    returned for the attempt's record.
    """
    if robot.gripper_state().closed:
        robot.gripper(False)
        robot.sleep(1.0)
    behaviours.held = None
    out = behaviours.stow()
    if out.ok:
        return None

    def home(m, d) -> None:
        d.qpos[robot.sim.info.arm_qpos] = dims.UR5_HOME_Q
        d.qvel[robot.sim.info.arm_dof] = 0.0

    robot.sim.call(home)
    robot.sim.halt()
    robot.sleep(0.5)
    return Failure("execute", f"the arm could not return home ({out.failure})")


def mark_target(
    robot: SimRobot, referee: Referee, instance: str, rng: np.random.Generator
) -> Perception | Failure:
    """The user marks `instance` and the robot perceives it. When the mark fails (the dot
    missed, or no object under it), the user sees why and marks again, up to REMARKS times,
    as 004's users re-aimed."""
    aim = referee.aim_point(instance)
    if aim is None:
        return Failure("detect_laser", "no camera sees the object")
    for _ in range(REMARKS + 1):
        perception = perceive(mark_and_capture(robot, aim, rng))
        if perception.ok:
            return perception
    assert perception.failure is not None
    return perception.failure


def mark_and_pick(
    robot: SimRobot,
    behaviours: Behaviours,
    referee: Referee,
    instance: str,
    rng: np.random.Generator,
    *,
    strategy: Strategy = "gpd",
    choose: str = "auto",
) -> Attempt:
    """Mark `instance` and pick it; on success the hand holds it 10 cm up.

    choose: "auto" tries the grasps in score order (004 section 7.4); "manual" plays a user
    who steps through the clusters to the first whose best grasp is on the marked object
    (004 section 7.2), and tries that cluster's grasps.
    """
    placements = robot.sim.scene.placements  # type: ignore[union-attr]
    names = [p.instance for p in placements]
    model = next(p.model.name for p in placements if p.instance == instance)
    rec = Attempt(instance, model)
    perception = mark_target(robot, referee, instance, rng)
    if isinstance(perception, Failure):
        rec.failure, rec.message = perception.kind, perception.message
        return rec
    rec.timings.update(perception.timings)
    found = find_grasps(
        perception, dims.UR5_READY_Q, q_capture=robot.joint_state().q, strategy=strategy, rng=rng
    )
    if isinstance(found, Failure):
        rec.failure, rec.message = found.kind, found.message
        return rec
    rec.timings.update(found.timings)
    before = referee.all_object_points()  # judge the grasp against the scene it was made for
    outcome = behaviours.pick(found, choose_order(found, choose, referee, instance, before))
    rec.timings.update(outcome.timings)
    if outcome.grasp is not None:
        rec.detected = referee.grasped_object(outcome.grasp, names, before) == instance
    if outcome.grasp is not None and not rec.detected:
        rec.failure, rec.message = "wrong_object", "the chosen grasp was on another object"
    elif outcome.failure is not None:
        rec.failure, rec.message = outcome.failure.kind, outcome.failure.message
    return rec


def pick_and_drop(
    robot: SimRobot,
    behaviours: Behaviours,
    referee: Referee,
    instance: str,
    rng: np.random.Generator,
    *,
    strategy: Strategy = "gpd",
    choose: str = "auto",
) -> Attempt:
    """Mark `instance`, pick it and drop it in the basket; success is the simulator's word
    that the marked object lies in the basket."""
    rec = mark_and_pick(robot, behaviours, referee, instance, rng, strategy=strategy, choose=choose)
    if rec.failure is not None or not rec.detected:
        return rec
    dropped = behaviours.drop_in_basket()
    robot.sleep(1.0)
    rec.success = referee.in_basket(instance)
    if rec.success:
        referee.take_out(instance)
    else:
        failure = dropped.failure or Failure("execute", "the object did not land in the basket")
        rec.failure, rec.message = failure.kind, failure.message
    return rec


def choose_order(
    found: GraspSet,
    choose: str,
    referee: Referee,
    instance: str,
    points: dict[str, np.ndarray] | None = None,
) -> list[Grasp]:
    """The grasps to try, in order, for automatic or (scripted) manual selection."""
    if choose == "auto":
        return found.ordered()
    names = referee.instances()
    grasps, clusters = found.clusters.grasps, found.clusters.clusters
    for members in clusters:  # the user toggles through clusters, best first
        if referee.grasped_object(grasps[members[0]], names, points) == instance:
            return [grasps[i] for i in members]
    return found.ordered()  # no cluster on the target: the user accepts the system's choice


def run_scene(
    robot: SimRobot,
    instances: list[str],
    rng: np.random.Generator,
    *,
    strategy: Strategy = "gpd",
    choose: str = "auto",
    log=lambda line: print(line, flush=True),
) -> list[Attempt]:
    """Pick-and-drop each instance in turn (in the given order) on a running scene."""
    behaviours = Behaviours(robot, rng=rng, progress=lambda _msg: None)
    referee = Referee(robot)
    out = []
    for name in instances:
        t0 = time.perf_counter()
        rec = pick_and_drop(robot, behaviours, referee, name, rng, strategy=strategy, choose=choose)
        stuck = stow(robot, behaviours)
        verdict = "ok" if rec.success else f"{rec.failure}: {rec.message}"
        if stuck is not None:
            rec.stuck = True
            verdict += f"; then {stuck.message}, moved home by hand"
        log(
            f"  {name:<22} {verdict}  (decide {rec.decide_time * 1000:.0f} ms,"
            f" wall {time.perf_counter() - t0:.1f} s)"
        )
        out.append(rec)
    return out


def failure_table(attempts: list[Attempt]) -> str:
    """004's Table 1 layout: per object, attempts, successes and the failures by kind."""
    models = sorted({a.model for a in attempts})
    head = f"{'object':<16}{'tries':>6}{'ok':>5}" + "".join(f"{k:>14}" for k in FAILURE_KINDS)
    lines = [head, "-" * len(head)]
    for m in [*models, "all"]:
        rows = [a for a in attempts if m in ("all", a.model)]
        counts = [sum(a.failure == k for a in rows) for k in FAILURE_KINDS]
        ok = sum(a.success for a in rows)
        lines.append(f"{m:<16}{len(rows):>6}{ok:>5}" + "".join(f"{c:>14}" for c in counts))
    return "\n".join(lines)
