"""Time full 5-camera captures: `python -m laserpick.robot.sim.sensors [scene]`."""

from __future__ import annotations

import sys

import numpy as np

from laserpick.description import dims
from laserpick.robot.sim.sensors.cameras import DepthCameras


def demo(scene_name: str | None = "isolation", n: int = 10) -> None:
    """Print the time of `n` captures of all five cameras in `scene_name`, and what they see."""
    import time

    from laserpick.robot.sim.model import ModelInfo, build_sim_model

    scene = None
    if scene_name:
        from laserpick.robot.sim.scenes import load_scene

        scene = load_scene(scene_name)
    model = build_sim_model(scene)
    qpos = model.qpos0.copy()
    qpos[ModelInfo.of(model).arm_qpos] = dims.UR5_HOME_Q
    with DepthCameras(model) as cams:
        t0 = time.perf_counter()
        cams.capture(qpos, 0.0)
        first = time.perf_counter() - t0
        times = []
        for i in range(n):
            t0 = time.perf_counter()
            frames = cams.capture(qpos, float(i))
            times.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        cams.capture_with_labels(qpos, 0.0)
        labelled = time.perf_counter() - t0
    ms = np.array(times) * 1e3
    print(f"scene {scene_name}: first capture {first * 1e3:.0f} ms (GL context, noise pool)")
    print(f"5-camera capture x{n}: mean {ms.mean():.0f} ms, min {ms.min():.0f}, max {ms.max():.0f}")
    print(f"capture_with_labels: {labelled * 1e3:.0f} ms")
    for f in frames:
        valid, ir = np.mean(f.depth > 0), np.median(f.ir)
        print(f"  {f.camera:9s} valid depth {valid:5.1%}  IR median {ir:.0f}")


if __name__ == "__main__":
    demo(sys.argv[1] if len(sys.argv) > 1 else "isolation")
