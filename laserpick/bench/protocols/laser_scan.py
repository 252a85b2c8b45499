"""laser-scan (002 section II.D): the laser stepped across each object of an `isolation`
scene on a 1.5 cm grid; one grasp attempt per point, the object put back after each."""

from __future__ import annotations

import numpy as np

from laserpick.bench.attempts import Attempt
from laserpick.bench.protocols.trials import (
    Options,
    instances,
    limit,
    protocol_scene,
    scripted_operator,
)
from laserpick.robot.sim.truth import Captured
from laserpick.transforms import planar_pose

#: The laser-scan protocol's step between aim points (m), 002's "about 1.5 cm".
SCAN_STEP = 0.015


def scan_points(captured: Captured, instance: str, step: float = SCAN_STEP) -> np.ndarray:
    """Aim points across the object's visible top (m, `base`): one seen point per `step`
    square of its footprint, the one nearest the square's centre, in scan order (rows along
    x, then y). Empty when no camera sees the object."""
    from laserpick.pipeline.cloud import fuse

    cloud = fuse(captured.frames)
    pts = cloud.points[captured.object_points(cloud, instance)]
    if len(pts) == 0:
        return np.zeros((0, 3))
    top = pts[pts[:, 2] > pts[:, 2].max() - 0.02]  # what the laser can land on from above
    cells = np.floor(top[:, :2] / step).astype(np.int64)
    centres = (cells + 0.5) * step
    dist = np.linalg.norm(top[:, :2] - centres, axis=1)
    best: dict[tuple[int, int], int] = {}
    for i, key in enumerate(map(tuple, cells)):
        if key not in best or dist[i] < dist[best[key]]:
            best[key] = i
    return np.array([top[best[k]] for k in sorted(best)])


def laser_scan(trial: int, seed: int, opt: Options) -> list[Attempt]:
    """One laser-scan trial: one attempt per aim point of each object, put back after each."""
    scene = protocol_scene("isolation", seed, opt)
    out = []
    with scripted_operator(scene, trial, seed, opt) as op:
        frames, labels = op.robot.capture_with_labels()
        captured = Captured(op.robot, frames, labels)
        T_world_base = planar_pose(*op.base_pose())
        for name in limit(instances(scene), opt):
            home = op.referee.free_joint(name)
            for point in scan_points(captured, name):
                # The points are fixed on the object, in `world`: the arm's pushes turn the
                # parked scooter a little with each pick (2.4 degrees over 40 attempts, 6 cm
                # at a TV remote).
                aim = op.referee.to_base((T_world_base @ np.append(point, 1.0))[:3])
                rec = op.new_attempt(name, opt.selection, opt.strategy)
                out.append(op.pick_and_drop(rec, aim=aim))
                op.referee.put_back(name, home)  # the next point finds it where it stood
    return out
