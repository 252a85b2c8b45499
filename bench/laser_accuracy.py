"""Laser mark accuracy on `isolation` scenes: the detected 3D mark against the true hit of
the aiming beam, for marks on the visible surfaces of every opaque object.

For each object: its top centre and five random points the cameras saw on it are marked with
both beams; a failure counts as a miss.

    MUJOCO_GL=egl .venv/bin/python bench/laser_accuracy.py [--seeds 1 2 3 4]
"""

from __future__ import annotations

import argparse

import numpy as np

from laserpick.pipeline.cloud import fuse
from laserpick.pipeline.laser_mark import detect_mark
from laserpick.robot.sim.truth import capture
from laserpick.types import Failure


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4])
    parser.add_argument("--per-object", type=int, default=5, help="random points per object")
    args = parser.parse_args()
    errors: list[float] = []
    for seed in args.seeds:
        c = capture("isolation", seed=seed)
        cloud = fuse(c.frames)
        rng = np.random.default_rng(seed)
        for p in c.scene.placements:
            pts = cloud.points[c.object_points(cloud, p.instance)]
            if p.model.optical != "opaque" or len(pts) <= 50:
                print(f"  seed {seed} {p.instance}: skipped ({p.model.optical}, {len(pts)} points)")
                continue
            picks = pts[rng.choice(len(pts), args.per_object, replace=False)]
            for target in [c.visible_top(cloud, p.instance), *picks]:
                c.robot.laser.aim_at(target)
                c.robot.laser.confirm()
                mark = detect_mark(c.robot.capture())
                hit = c.robot.laser_hits()[0]  # world == base: the scooter is at the origin
                err = (
                    np.inf if isinstance(mark, Failure) else float(np.linalg.norm(mark.point - hit))
                )
                errors.append(err)
                if err > 0.01:
                    why = mark.message if isinstance(mark, Failure) else f"{err * 1000:.0f} mm off"
                    print(f"  seed {seed} {p.instance}: {why}")
        c.close()
    e = np.array(errors)
    finite = e[np.isfinite(e)]
    print(
        f"\nmarks {len(e)}; within 1 cm {np.mean(e < 0.01):.1%}; failures {np.sum(~np.isfinite(e))}"
    )
    print(
        f"error median {np.median(finite) * 1000:.2f} mm,"
        f" p95 {np.percentile(finite, 95) * 1000:.2f} mm"
    )


if __name__ == "__main__":
    main()
