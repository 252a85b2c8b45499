"""Per-stage timings of GPD-style grasp detection (`detect_grasps`) on real segmented targets.

By default the `isolation` scene is captured headless (about 10-30 s including the GL context),
each object is segmented by `perceive` from a point at the middle of its visible top (a
"direct" mark, as from a touch screen, so the laser plays no part), and `detect_grasps` runs
on the target's points and normals with the whole fused cloud as the scene. `--synthetic`
uses a 6 cm x 12 cm cylinder on a 60 cm table instead (no simulator, seconds to start).

Prints, per input, the target and scene sizes, the number of grasps (same rng seed every
run) and the median time of each stage over `--repeats` runs, then the medians pooled over
the "typical" inputs (1000-3000 target points). Nothing is cached on disk.

    MUJOCO_GL=egl .venv/bin/python bench/grasp_detect_speed.py [--seeds 1] [--repeats 7]
    .venv/bin/python bench/grasp_detect_speed.py --synthetic
"""

from __future__ import annotations

import argparse
import statistics
from dataclasses import dataclass

import numpy as np

from laserpick.pipeline.gpd import detect_grasps
from laserpick.settings import get_settings

#: detect_grasps' stages, in its order (see its `timings`); a stage that did not run counts 0.
STAGES = (
    "frames",
    "pad_pairs",
    "crop",
    "collision_pairs",
    "deepest_tips",
    "closing_region",
    "recentre",
    "square",
    "total",
)
TYPICAL = (1000, 3000)  #: target sizes (points) of a typical segmented household object


@dataclass
class Input:
    name: str
    target: np.ndarray  #: (M, 3) float32 target points in `base` (m)
    normals: np.ndarray  #: (M, 3) float32 outward unit normals
    scene: np.ndarray  #: (N, 3) float32 full cloud in `base` (m)


def synthetic() -> list[Input]:
    """A vertical cylinder (r 3 cm, 12 cm tall, 3 mm point spacing) standing on a 60 x 60 cm
    table sampled every 4 mm at z = 0, as in tests/test_grasp_detect.py."""
    r, height, spacing = 0.03, 0.12, 0.003
    ang = np.linspace(0, 2 * np.pi, int(2 * np.pi * r / spacing), endpoint=False)
    a, z = np.meshgrid(ang, (np.arange(int(height / spacing)) + 0.5) * spacing)
    side = np.column_stack([r * np.cos(a).ravel(), r * np.sin(a).ravel(), z.ravel()])
    side_n = np.column_stack([np.cos(a).ravel(), np.sin(a).ravel(), np.zeros(a.size)])
    g = np.arange(-r, r, spacing)
    x, y = np.meshgrid(g, g)
    m = x**2 + y**2 <= r * r
    top = np.column_stack([x[m], y[m], np.full(m.sum(), height)])
    pts = np.vstack([side, top])
    normals = np.vstack([side_n, np.tile([0.0, 0.0, 1.0], (len(top), 1))])
    normals += np.random.default_rng(7).normal(0, 0.03, normals.shape)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    t = np.arange(-0.3, 0.3, 0.004)
    tx, ty = np.meshgrid(t, t)
    table = np.column_stack([tx.ravel(), ty.ravel(), np.zeros(tx.size)])
    scene = np.vstack([table, pts])
    return [
        Input(
            "cylinder", pts.astype(np.float32), normals.astype(np.float32), scene.astype(np.float32)
        )
    ]


def captured(seeds: list[int]) -> list[Input]:
    """Every object of the `isolation` scene, segmented from one simulated capture per seed."""
    # Imported here so that --synthetic needs no simulator.
    from laserpick.pipeline.cloud import fuse
    from laserpick.pipeline.perceive import perceive
    from laserpick.robot.sim.truth import capture

    out = []
    for seed in seeds:
        c = capture("isolation", seed=seed)
        c.robot.laser.off()
        frames = c.robot.capture()
        truth_cloud = fuse(frames)
        for p in c.scene.placements:
            top = c.visible_top(truth_cloud, p.instance)
            if top is None:
                print(f"  seed {seed} {p.instance}: not visible to any camera, skipped")
                continue
            result = perceive(frames, point=top)
            if not result.ok or result.segmentation is None:
                print(f"  seed {seed} {p.instance}: not segmented ({result.failure}), skipped")
                continue
            i = result.segmentation.indices
            out.append(
                Input(
                    f"s{seed} {p.instance}",
                    result.cloud.points[i],
                    result.cloud.normals[i],
                    result.cloud.points,
                )
            )
        c.close()
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--synthetic", action="store_true", help="cylinder on a table instead")
    parser.add_argument(
        "--seeds", type=int, nargs="+", default=[1, 2, 3], help="isolation scene seeds"
    )
    parser.add_argument("--repeats", type=int, default=7, help="timed runs per input")
    parser.add_argument("--rng-seed", type=int, default=0, help="detect_grasps' sampling seed")
    args = parser.parse_args()

    s = get_settings().grasp
    inputs = synthetic() if args.synthetic else captured(args.seeds)
    print(
        f"detect_grasps: {s.gpd_samples} samples, {s.gpd_orientations} orientations,"
        f" {s.gpd_finger_placements} placements; median of {args.repeats} runs, ms"
    )
    header = f"{'input':24s} {'M':>5s} {'N':>7s} {'grasps':>6s} " + " ".join(
        f"{name[:14]:>14s}" for name in STAGES
    )
    print(header)
    pooled: dict[str, list[float]] = {name: [] for name in STAGES}
    typical_totals: list[float] = []  # each typical input's median total
    for inp in inputs:
        runs: dict[str, list[float]] = {name: [] for name in STAGES}
        n_grasps = []
        for i in range(args.repeats + 1):
            timings: dict[str, float] = {}
            grasps = detect_grasps(
                inp.target,
                inp.normals,
                inp.scene,
                s,
                np.random.default_rng(args.rng_seed),
                timings=timings,
            )
            n_grasps.append(len(grasps))
            if i == 0:
                continue  # warm-up: first-touch page faults, lazy imports
            for name in STAGES:
                runs[name].append(timings.get(name, 0.0))
        assert len(set(n_grasps)) == 1, "same seed, different grasps"
        typical = TYPICAL[0] <= len(inp.target) <= TYPICAL[1]
        if typical:
            for name in STAGES:
                pooled[name] += runs[name]
            typical_totals.append(statistics.median(runs["total"]))
        print(
            f"{inp.name[:24]:24s} {len(inp.target):5d} {len(inp.scene):7d} {n_grasps[0]:6d} "
            + " ".join(f"{statistics.median(runs[name]) * 1000:14.1f}" for name in STAGES)
            + ("" if typical else "   (not typical)")
        )
    if pooled["total"]:
        print(
            f"{'typical (pooled runs)':24s} {'':5s} {'':7s} {'':6s} "
            + " ".join(f"{statistics.median(pooled[name]) * 1000:14.1f}" for name in STAGES)
        )
        print(
            f"\n{len(typical_totals)} typical inputs ({TYPICAL[0]}-{TYPICAL[1]} target points):"
            f" median total {statistics.median(pooled['total']) * 1000:.1f} ms over all their"
            f" runs; slowest input's median {max(typical_totals) * 1000:.1f} ms"
        )
    print(
        "frames: sampling and local frames; pad_pairs: the pads' contents and the antipodal"
        " bound; crop: the scene around the target, in voxels; collision_pairs + deepest_tips:"
        " hand-vs-scene collisions; closing_region: the antipodal test."
    )


if __name__ == "__main__":
    main()
