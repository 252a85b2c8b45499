"""Open3D against our numpy and scipy code, on our own clouds: median times and agreement.

For each seed the scene is captured headless and fused (`fuse`: ~214k points in `isolation`).
Each operation runs `--repeats` times our way and Open3D's on the same input; the script
prints each one's median time (all seeds' runs pooled) and whether the results agree:

- normals: our whole `fuse` (points and depth-image normals) against Open3D's
  `estimate_normals` alone (1 cm, 30 neighbours) on the fused points;
- voxel thinning at 1 cm (`obstacle_mask`'s `thin`): `voxel_first` against Open3D's
  `voxel_down_sample` (centroids, no indices) and `voxel_down_sample_and_trace` (indices, which
  a FusedCloud needs to keep each point's camera and pixel); voxel counts on the same grid;
- horizontal plane removal (`remove_horizontal_planes`) against the same loop with Open3D's
  `segment_plane` as the plane finder; normals and heights of the planes;
- Euclidean clusters at 5 mm around each object's mark (`euclidean_clusters`) against
  `cluster_dbscan(eps, min_points=1)`, the same definition; identical partitions;
- KD-trees, build and query: the collision checker's nearest obstacle to the arm's spheres
  (k=1 within a bound), GPD's local-frame neighbours (k=32 within 1 cm) and `self_filter`'s
  ball per sphere (one radius each), against Open3D's `core.nns.NearestNeighborSearch`.

Every Open3D timing includes copying our float32 arrays into Open3D's types; orienting
Open3D's normals toward the cameras is left out of its time.

    MUJOCO_GL=egl .venv/bin/python bench/open3d_vs_ours.py [--scene isolation] [--seeds 1 2 3]
        [--repeats 7]

laserpick does not install Open3D: `pip install 'open3d>=0.18,<0.21'` first.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import open3d as o3d
from scipy.spatial import cKDTree

from laserpick.description import dims
from laserpick.description.shapes import body_frames
from laserpick.pipeline.cloud import fuse, voxel_first
from laserpick.pipeline.collision.arm_spheres import SPHERES, sphere_centres
from laserpick.pipeline.collision.obstacles import obstacle_mask
from laserpick.pipeline.gpd.frames import sample_indices
from laserpick.pipeline.planes import (
    plane_distance,
    remove_horizontal_planes,
)
from laserpick.pipeline.segment import euclidean_clusters
from laserpick.robot.sim.truth import capture
from laserpick.settings import get_settings
from laserpick.types import FusedCloud, SupportSurface

#: (operation, ours or Open3D) -> seconds of every run; operation -> agreement notes.
TIMES: dict[tuple[str, str], list[float]] = {}
AGREE: dict[str, list[str]] = {}


def timed(op: str, who: str, fn: Callable[[], Any], repeats: int) -> Any:
    """Run fn `repeats` times, adding each run's seconds to TIMES[op, who]; its last result."""
    out = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        TIMES.setdefault((op, who), []).append(time.perf_counter() - t0)
    return out


def o3d_cloud(points: np.ndarray) -> o3d.geometry.PointCloud:
    return o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points.astype(np.float64)))


def angle_deg(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angles (deg) between the rows of a and b, unit vectors (N, 3)."""
    return np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", a, b), -1.0, 1.0)))


def bench_normals(frames: list, cloud: FusedCloud, repeats: int) -> None:
    s = get_settings().perception
    timed("normals", "ours", lambda: fuse(frames, s), repeats)

    def theirs() -> np.ndarray:
        pcd = o3d_cloud(cloud.points)
        pcd.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=0.01, max_nn=30))
        return np.asarray(pcd.normals)

    n = timed("normals", "open3d", theirs, repeats)
    eye = np.stack([f.T_base_cam[:3, 3] for f in frames])[cloud.camera]
    n *= np.where(np.einsum("ij,ij->i", n, eye - cloud.points) < 0, -1.0, 1.0)[:, None]
    err = angle_deg(cloud.normals.astype(np.float64), n)
    # On the largest horizontal plane (the table or the floor), the plane's own normal is the
    # truth: how far each way's normals stray from it.
    plane = remove_horizontal_planes(cloud, s)[1][0].plane
    on = np.abs(plane_distance(cloud.points, plane)) <= 0.005
    up = np.broadcast_to(plane[:3], (int(on.sum()), 3))
    AGREE.setdefault("normals", []).append(
        f"median {np.median(err):.1f} deg apart; off the largest plane's normal on it:"
        f" ours {np.median(angle_deg(cloud.normals[on].astype(np.float64), up)):.1f} deg,"
        f" Open3D {np.median(angle_deg(n[on], up)):.1f} deg (medians)"
    )


def bench_voxels(points: np.ndarray, repeats: int, size: float = 0.01) -> None:
    ours = timed("voxel 1 cm", "ours", lambda: voxel_first(points, size), repeats)
    cent = timed("voxel 1 cm", "open3d", lambda: o3d_cloud(points).voxel_down_sample(size), repeats)

    def traced() -> np.ndarray:
        pcd = o3d_cloud(points)
        lo = pcd.get_min_bound() - size / 2  # voxel_down_sample's grid
        _, _, members = pcd.voxel_down_sample_and_trace(size, lo, pcd.get_max_bound())
        return np.array([m[0] for m in members])

    idx = timed("voxel 1 cm, indices", "open3d", traced, repeats)
    TIMES[("voxel 1 cm, indices", "ours")] = TIMES[("voxel 1 cm", "ours")]
    # Open3D's grid starts half a voxel below the cloud's lowest corner, ours at multiples of
    # the size: count ours on Open3D's grid.
    p = points.astype(np.float64)
    same_grid = len(voxel_first(p - (p.min(axis=0) - size / 2), size))
    AGREE.setdefault("voxel 1 cm", []).append(
        f"{len(cent.points)} voxels, ours {same_grid} on its grid ({len(ours)} on ours)"
    )
    AGREE.setdefault("voxel 1 cm, indices", []).append(f"{len(idx)} voxels")


def o3d_planes(cloud: FusedCloud, s: Any) -> list[SupportSurface]:
    """`remove_horizontal_planes` with Open3D's segment_plane finding each plane among the
    up-facing points left; a plane tilted over plane_max_tilt_deg ends the loop."""
    o3d.utility.random.seed(0)

    def segment_plane(pts: np.ndarray, cand: np.ndarray) -> np.ndarray | None:
        model, _ = o3d_cloud(pts[cand]).segment_plane(s.plane_distance, 3, s.ransac_iterations)
        plane = np.asarray(model) * (1.0 if model[2] >= 0 else -1.0)
        return plane if plane[2] >= math.cos(math.radians(s.plane_max_tilt_deg)) else None

    return remove_horizontal_planes(cloud, s, find_plane=segment_plane)[1]


def bench_planes(cloud: FusedCloud, repeats: int) -> None:
    s = get_settings().perception
    _, ours = timed("plane removal", "ours", lambda: remove_horizontal_planes(cloud, s), repeats)
    theirs = timed("plane removal", "open3d", lambda: o3d_planes(cloud, s), repeats)
    if len(ours) != len(theirs):
        note = f"{len(ours)} planes, Open3D {len(theirs)}"
    else:
        a = np.stack([p.plane[:3] for p in ours])
        b = np.stack([p.plane[:3] for p in theirs])
        dh = max(abs(p.height - q.height) for p, q in zip(ours, theirs, strict=True))
        note = (
            f"{len(ours)} planes, normals within {angle_deg(a, b).max():.2f} deg,"
            f" heights within {dh * 1000:.1f} mm"
        )
    AGREE.setdefault("plane removal", []).append(note)


def same_partition(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two labellings (N,) group the points the same way."""
    pairs = np.unique(np.stack([a, b], axis=1), axis=0)
    return len(pairs) == len(np.unique(a)) == len(np.unique(b))


def bench_clusters(cloud: FusedCloud, marks: list[np.ndarray], repeats: int) -> None:
    s = get_settings().perception
    keep, _ = remove_horizontal_planes(cloud, s)
    same, tol = 0, s.cluster_tolerance
    for mark in marks:
        d = cloud.points - mark.astype(np.float32)
        crop = cloud.points[keep & (np.einsum("ij,ij->i", d, d) <= s.cluster_crop_radius**2)]

        def theirs(crop: np.ndarray = crop) -> np.ndarray:
            return np.asarray(o3d_cloud(crop).cluster_dbscan(tol, 1))

        ours = timed("clusters 5 mm", "ours", lambda c=crop: euclidean_clusters(c, tol), repeats)
        theirs = timed("clusters 5 mm", "open3d", theirs, repeats)
        same += same_partition(ours, theirs)
    AGREE.setdefault("clusters 5 mm", []).append(f"{same}/{len(marks)} crops identical")


def nns(points: np.ndarray) -> o3d.core.nns.NearestNeighborSearch:
    return o3d.core.nns.NearestNeighborSearch(o3d.core.Tensor(np.ascontiguousarray(points)))


def bench_nearest(cloud: FusedCloud, repeats: int, margin: float = 0.01) -> None:
    """The collision checker's query: nearest obstacle to each of the arm's spheres at 200
    configurations about the ready pose, within the largest sphere's reach."""
    obstacles = cloud.points[obstacle_mask(cloud.points, voxel=0.01)]
    q = dims.UR5_READY_Q + np.random.default_rng(0).uniform(-1.0, 1.0, (200, 6))
    centres = sphere_centres(body_frames(q)).reshape(-1, 3)
    bound = float(SPHERES.radius.max() + margin)

    def ours() -> np.ndarray:
        tree = cKDTree(obstacles.astype(np.float64))
        return tree.query(centres, k=1, distance_upper_bound=bound)[0]

    def theirs() -> np.ndarray:
        search = nns(obstacles)
        search.hybrid_index(bound)
        _, d2, _ = search.hybrid_search(o3d.core.Tensor(centres.astype(np.float32)), bound, 1)
        return d2.numpy()[:, 0]

    d_ours = timed("kd nearest (collision)", "ours", ours, repeats)
    d2 = timed("kd nearest (collision)", "open3d", theirs, repeats)
    found = np.isfinite(d_ours)
    err = np.abs(np.sqrt(d2[found]) - d_ours[found]).max() if found.any() else 0.0
    AGREE.setdefault("kd nearest (collision)", []).append(
        f"{len(centres)} spheres on {len(obstacles)} points, distances within {err * 1e6:.1f} um"
    )


def bench_neighbours(targets: list[np.ndarray], repeats: int) -> None:
    """GPD's local frames: for 500 samples of each object, up to 32 neighbours within 1 cm."""
    g = get_settings().grasp
    r, k = g.gpd_nn_radius, g.gpd_frame_neighbours
    same = total = 0
    for tgt in targets:
        tgt = tgt.astype(np.float64)
        query = tgt[sample_indices(len(tgt), g.gpd_samples, np.random.default_rng(0))]

        def ours(tgt: np.ndarray = tgt, query: np.ndarray = query) -> np.ndarray:
            return cKDTree(tgt).query(query, k=k, distance_upper_bound=r)[1]

        def theirs(tgt: np.ndarray = tgt, query: np.ndarray = query) -> np.ndarray:
            search = nns(tgt.astype(np.float32))
            search.hybrid_index(r)
            return search.hybrid_search(o3d.core.Tensor(query.astype(np.float32)), r, k)[2]

        nb = timed("kd 32 within 1 cm (GPD)", "ours", ours, repeats)
        counts = timed("kd 32 within 1 cm (GPD)", "open3d", theirs, repeats).numpy()
        same += int(np.count_nonzero(np.count_nonzero(nb < len(tgt), axis=1) == counts))
        total += len(query)
    AGREE.setdefault("kd 32 within 1 cm (GPD)", []).append(f"{same}/{total} same counts")


def bench_balls(cloud: FusedCloud, repeats: int, padding: float = 0.03) -> None:
    """`self_filter`'s query: the cloud points within each arm sphere (grown by `padding`) at
    the ready pose, one radius per sphere, on the points within the arm's reach thinned to
    1 cm, as `obstacle_mask` passes them."""
    pts = cloud.points[obstacle_mask(cloud.points, voxel=0.01)]
    centres = sphere_centres(body_frames(dims.UR5_READY_Q))[0]
    radii = SPHERES.radius + padding

    def ours() -> np.ndarray:
        near = cKDTree(pts.astype(np.float64)).query_ball_point(centres, radii)
        return np.unique(np.concatenate([np.asarray(i, np.int64) for i in near]))

    def theirs() -> np.ndarray:
        search = nns(pts)
        search.multi_radius_index()
        query = o3d.core.Tensor(centres.astype(np.float32))
        idx, _, _ = search.multi_radius_search(query, o3d.core.Tensor(radii.astype(np.float32)))
        return np.unique(idx.numpy())

    a = timed("kd balls (self filter)", "ours", ours, repeats)
    b = timed("kd balls (self filter)", "open3d", theirs, repeats)
    AGREE.setdefault("kd balls (self filter)", []).append(
        f"{len(a)} points in {len(centres)} balls of {len(pts)}, {len(np.setxor1d(a, b))} differ"
    )


def run_seed(scene: str, seed: int, repeats: int) -> None:
    c = capture(scene, seed=seed)
    cloud = fuse(c.frames)
    marks, targets = [], []
    for p in c.scene.placements:
        top = c.visible_top(cloud, p.instance)
        if top is not None:
            marks.append(top)
            targets.append(cloud.points[c.object_points(cloud, p.instance)])
    print(f"{scene} seed {seed}: {len(cloud)} points, {len(marks)} objects seen", flush=True)
    bench_normals(c.frames, cloud, repeats)
    bench_voxels(cloud.points, repeats)
    bench_planes(cloud, repeats)
    bench_clusters(cloud, marks, repeats)
    bench_nearest(cloud, repeats)
    bench_neighbours(targets, repeats)
    bench_balls(cloud, repeats)
    c.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="isolation")
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    print(f"Open3D {o3d.__version__}, {os.cpu_count()} CPUs")
    for seed in args.seeds:
        run_seed(args.scene, seed, args.repeats)
    print(f"\n{'median of every run':26s} {'ours ms':>8s} {'Open3D ms':>10s} {'Open3D/ours':>12s}")
    for op in AGREE:
        ours = statistics.median(TIMES[(op, "ours")]) * 1000
        theirs = statistics.median(TIMES[(op, "open3d")]) * 1000
        print(f"{op:26s} {ours:8.2f} {theirs:10.2f} {theirs / ours:11.1f}x")
    print("\nagreement, seed by seed:")
    for op, notes in AGREE.items():
        print(f"{op}:")
        for seed, note in zip(args.seeds, notes, strict=True):
            print(f"  {seed}: {note}")


if __name__ == "__main__":
    main()
