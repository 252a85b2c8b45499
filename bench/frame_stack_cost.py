"""What stacking a pick's depth frames for the seen-space test costs (`frame_stack`), with the
buffers of stacks let go filled again and with a new buffer for every stack.

Each pick stacks its capture's 5 frames for grasp detection and its 45 frames (with the
views from the way in) for planning, as the kitchen's picks do; every pick's frames are new
images of 640 x 480. Prints the median and largest time to stack the 45 frames, over
`--picks` picks, each way.

    .venv/bin/python bench/frame_stack_cost.py [--picks 12]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from laserpick.pipeline import frame_stack as fs
from laserpick.types import DepthFrame

SHAPE = (480, 640)
K = np.array([[525.0, 0.0, 320.0], [0.0, 525.0, 240.0], [0.0, 0.0, 1.0]])


def _frames(n: int, rng: np.random.Generator) -> list[DepthFrame]:
    depth = rng.uniform(0.3, 3.0, SHAPE).astype(np.float32)
    return [
        DepthFrame(
            depth=depth.copy(),
            ir=np.zeros((0, 0), np.uint8),
            K=K,
            T_base_cam=np.eye(4),
            camera=f"cam{k}",
            stamp=0.0,
        )
        for k in range(n)
    ]


def _picks(picks: int, spares: int) -> list[float]:
    """Seconds to stack each pick's 45 frames, with `spares` buffers kept."""
    fs._STACKS.clear()
    fs._SPARES.clear()
    kept, fs.SPARES_KEPT = fs.SPARES_KEPT, spares
    rng = np.random.default_rng(0)
    times = []
    try:
        for _ in range(picks):
            capture = _frames(5, rng)
            fs.frame_stack(capture)
            views = capture + _frames(40, rng)
            t0 = time.perf_counter()
            fs.frame_stack(views)
            times.append(time.perf_counter() - t0)
    finally:
        fs.SPARES_KEPT = kept
        fs._STACKS.clear()
        fs._SPARES.clear()
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--picks", type=int, default=12)
    args = parser.parse_args()
    for label, spares in (("a new buffer each", 0), ("buffers filled again", fs.SPARES_KEPT)):
        times = np.array(_picks(args.picks, spares)[1:]) * 1e3  # the first has no spare
        print(f"{label:>22}: median {np.median(times):6.1f} ms, largest {times.max():6.1f} ms")


if __name__ == "__main__":
    main()
