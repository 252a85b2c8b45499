"""Segmentation IoU against the simulator's true object points, over `isolation` seeds.

The mark for each object is the middle of its visible top (from the simulator's labels, as a
person would aim). Prints every object under 0.9 and the share at or above it.

    MUJOCO_GL=egl .venv/bin/python bench/segmentation_iou.py [--seeds 1 2 ... 8] [--method cluster]
"""

from __future__ import annotations

import argparse

import numpy as np

from laserpick.bench.scoring import iou
from laserpick.pipeline.cloud import fuse
from laserpick.pipeline.segment import segment_target
from laserpick.robot.sim.truth import capture
from laserpick.settings import get_settings
from laserpick.types import Failure


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=list(range(1, 9)))
    parser.add_argument("--method", choices=["cluster", "grid"], default="cluster")
    args = parser.parse_args()
    s = get_settings().perception
    scores = []
    for seed in args.seeds:
        c = capture("isolation", seed=seed)
        cloud = fuse(c.frames, s)
        for p in c.scene.placements:
            truth = c.object_points(cloud, p.instance)
            mark = c.visible_top(cloud, p.instance)
            seg = segment_target(cloud, mark, s, method=args.method)
            if isinstance(seg, Failure):
                score, how = 0.0, seg.message
            else:
                found = np.zeros(len(cloud), bool)
                found[seg.indices] = True
                score, how = iou(found, truth), seg.method
            scores.append(score)
            if score < 0.9:
                print(f"  seed {seed} {p.instance}: IoU {score:.3f} ({how})")
        c.close()
    v = np.array(scores)
    print(
        f"\n{args.method}: {len(v)} objects, IoU >= 0.9 for {np.mean(v >= 0.9):.1%};"
        f" median {np.median(v):.3f}, min {v.min():.3f}"
    )


if __name__ == "__main__":
    main()
