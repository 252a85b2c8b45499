"""What the arm's trajectories demand of it in a bench episode: per trajectory the arm ran,
its duration, its peak joint speed, acceleration, jerk, velocity change between samples, TCP
speed and the hand's turning speed, and how far the TCP moves, beside the limits (1.0 rad/s,
1.5 rad/s^2, 15 rad/s^3, 0.25 m/s; 0.08 m/s on the approach; the hand turning at most
0.75 rad/s while it carries). Figures by finite differences of the samples, the arm at
rest before and after, as tests/test_executed_trajectories.py checks them.

    MUJOCO_GL=egl .venv/bin/python bench/trajectory_limits.py [--seed 1] [--objects 1]
"""

from __future__ import annotations

import argparse

import numpy as np

from laserpick.behaviours.guarded_motion import GuardedMotion
from laserpick.bench.protocols import PROTOCOLS, Options
from laserpick.description import kinematics as K
from laserpick.pipeline.timing import Limits, excess
from laserpick.robot.sim.robot import SimRobot
from laserpick.types import Trajectory

#: Limits whose turning cap is 1 rad/s: `excess` then gives the hand's turning speed itself.
UNIT_TURN = Limits(1.0, 1.0, 1.0, turn_speed=1.0)


def peaks(traj: Trajectory) -> dict[str, float]:
    """Peak |joint speed|, |acceleration|, |jerk| (rad/s^n), velocity change between samples
    (rad/s), TCP speed (m/s) and the hand's turning speed (rad/s) of the samples of `traj`,
    and how far the TCP moves (m)."""
    h = float(np.diff(traj.times).max())
    rest = np.vstack([traj.q[:1]] * 3 + [traj.q] + [traj.q[-1:]] * 3)
    v = np.diff(rest, axis=0) / h
    a = np.diff(v, axis=0) / h
    p = K.tcp_pose(traj.q)[:, :3, 3]
    step = np.linalg.norm(np.diff(p, axis=0), axis=1)
    return {
        "speed": float(np.abs(v).max()),
        "accel": float(np.abs(a).max()),
        "jerk": float(np.abs(np.diff(a, axis=0)).max() / h),
        "jump": float(np.abs(np.diff(v, axis=0)).max()),
        "tcp": float(step.max() / h),
        "turn": excess(traj.q, h, UNIT_TURN)["turn_speed"],
        "hand": float(step.sum()),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--objects", type=int, default=1)
    args = parser.parse_args()
    ran: list[tuple[str, Trajectory]] = []
    doing = ["-"]
    run, execute = GuardedMotion.run, SimRobot.execute

    def labelled(self: GuardedMotion, traj: Trajectory, what: str):
        doing[0] = what
        return run(self, traj, what)

    def recorded(self: SimRobot, traj: Trajectory):
        ran.append((doing[0], traj))
        return execute(self, traj)

    GuardedMotion.run = labelled  # type: ignore[method-assign]
    SimRobot.execute = recorded  # type: ignore[method-assign]
    attempts = PROTOCOLS["isolation"].run(0, args.seed, Options(objects=args.objects))
    print(f"isolation, seed {args.seed}, {args.objects} object(s)")
    for a in attempts:
        t = a.timings
        print(f"  {a.model}: success {a.success}, execute_sim {t.get('execute_sim', 0):.2f} s")
    head = ("motion", "s", "rad/s", "rad/s^2", "rad/s^3", "jump rad/s", "TCP m/s", "turn", "TCP m")
    print("{:<26} {:>6} {:>6} {:>8} {:>8} {:>10} {:>8} {:>6} {:>6}".format(*head))
    for what, traj in ran:
        f = peaks(traj)
        print(
            f"{what:<26} {traj.duration:6.2f} {f['speed']:6.3f} {f['accel']:8.2f}"
            f" {f['jerk']:8.1f} {f['jump']:10.4f} {f['tcp']:8.3f} {f['turn']:6.3f}"
            f" {f['hand']:6.2f}"
        )
    worst = {k: max(peaks(t)[k] for _, t in ran) for k in ("speed", "accel", "jerk", "tcp")}
    print(
        f"{len(ran)} trajectories, {sum(t.duration for _, t in ran):.2f} s; peaks:"
        f" {worst['speed']:.3f} rad/s, {worst['accel']:.2f} rad/s^2,"
        f" {worst['jerk']:.1f} rad/s^3, TCP {worst['tcp']:.3f} m/s"
    )


if __name__ == "__main__":
    main()
