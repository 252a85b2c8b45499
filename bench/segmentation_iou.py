"""Segmentation IoU against the simulator's true object points, in `isolation` or the kitchen.

The mark for each object is the middle of its visible top (from the simulator's labels, as a
person would aim). In the kitchen (`--scene kitchen`: `pick-place`'s coin-flip kitchen of
each seed) the scooter stands where the scripted user first parks for each object, one
capture per object. Prints every object under 0.9 and the share at or above it.

    MUJOCO_GL=egl .venv/bin/python bench/segmentation_iou.py [--seeds 1 2 ... 8] [--method cluster]
    MUJOCO_GL=egl .venv/bin/python bench/segmentation_iou.py --scene kitchen --seeds 7201 7202
"""

from __future__ import annotations

import argparse
import dataclasses
from collections.abc import Iterator

import numpy as np

from laserpick.bench.parking import parking_pose
from laserpick.bench.protocols.pick_place import coin_flip_kitchen
from laserpick.bench.scoring import iou
from laserpick.pipeline.cloud import fuse
from laserpick.pipeline.segment import segment_target
from laserpick.robot.sim.scenes import Scene
from laserpick.robot.sim.truth import Captured, capture
from laserpick.settings import get_settings
from laserpick.types import Failure


def _parked_at(scene: Scene, instance: str) -> Scene:
    """`scene` with the scooter where the scripted user first parks to pick `instance`."""
    p = scene.placement(instance)
    surface = scene.surface(p.surface)
    x, y = (float(v) for v in surface.to_local(np.asarray(p.pos[:2])))
    pose = parking_pose(surface, y, surface.levels[p.level], x)  # x counts on a floor only
    return dataclasses.replace(scene, scooter_pose=tuple(float(v) for v in pose))


def _captures(scene: str, seed: int) -> Iterator[tuple[Captured, list[str]]]:
    """Each capture of `scene` at `seed` and the objects to score in it."""
    if scene == "isolation":
        c = capture("isolation", seed=seed)
        yield c, [p.instance for p in c.scene.placements]
        return
    kitchen = coin_flip_kitchen(np.random.default_rng(seed))
    for p in kitchen.placements:
        if p.model.optical == "opaque":
            yield capture(_parked_at(kitchen, p.instance)), [p.instance]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=list(range(1, 9)))
    parser.add_argument("--method", choices=["cluster", "grid"], default="cluster")
    parser.add_argument("--scene", choices=["isolation", "kitchen"], default="isolation")
    args = parser.parse_args()
    s = get_settings().perception
    scores = []
    for seed in args.seeds:
        for c, names in _captures(args.scene, seed):
            cloud = fuse(c.frames, s)
            for name in names:
                truth = c.object_points(cloud, name)
                mark = c.visible_top(cloud, name)
                seg = None if mark is None else segment_target(cloud, mark, s, method=args.method)
                if seg is None or isinstance(seg, Failure):
                    score, how = 0.0, "not seen" if seg is None else seg.message
                else:
                    found = np.zeros(len(cloud), bool)
                    found[seg.indices] = True
                    score, how = iou(found, truth), seg.method
                scores.append(score)
                if score < 0.9:
                    print(f"  seed {seed} {name}: IoU {score:.3f} ({how})", flush=True)
            c.close()
    v = np.array(scores)
    print(
        f"\n{args.method}, {args.scene}: {len(v)} objects, IoU >= 0.9 for {np.mean(v >= 0.9):.1%};"
        f" median {np.median(v):.3f}, min {v.min():.3f}"
    )


if __name__ == "__main__":
    main()
