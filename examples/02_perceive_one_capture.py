"""Perception and grasp detection on one recorded capture, without a server or a simulator.

The pipeline is plain functions: `perceive` fuses the five depth frames into a cloud in the
scooter's `base` frame, finds the laser mark in the IR images and segments the object under
it; `find_grasps` detects, scores and clusters grasps on it. Run:

    laserpick record my-capture --scene isolation --aim-at-object mug_1
    python examples/02_perceive_one_capture.py my-capture

A recording is what `laserpick record` writes, or what your own sensor driver writes in the
same format (docs/recording.md). Without the laser's dots in the IR images, give the object's
point directly with `--point X Y Z` (m, `base`: x forward, y left, z up), as a touch screen
would.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from laserpick.description import dims
from laserpick.pipeline.grasp_choice import find_grasps
from laserpick.pipeline.perceive import perceive
from laserpick.robot.recording import RecordingError, read_recording
from laserpick.types import Failure


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("recording", nargs="?", default="my-capture", help="its directory")
    parser.add_argument("--capture", type=int, default=0, help="which capture (0-based)")
    parser.add_argument("--point", type=float, nargs=3, metavar=("X", "Y", "Z"))
    args = parser.parse_args()

    try:
        recording = read_recording(args.recording)
    except RecordingError as exc:
        sys.exit(
            f"{exc}\n(make one with: laserpick record {args.recording} --scene isolation"
            " --aim-at-object mug_1)"
        )
    capture = recording.captures[args.capture]
    print(f"{len(capture.frames)} frames from {', '.join(recording.cameras)}")

    perception = perceive(capture.frames, point=args.point)
    if not perception.ok:
        print(f"no target: {perception.failure}")
        return 1
    mark = perception.mark
    print(
        f"mark at {np.round(mark.point, 3)} m ({mark.source}, seen by {mark.views} cameras);"
        f" target: {len(perception.target_points)} of {len(perception.cloud)} cloud points"
    )

    # q_ref: where the arm starts the grasp motion; q_capture: where it was in the frames.
    found = find_grasps(perception, dims.UR5_READY_Q, q_capture=capture.joints.q)
    if isinstance(found, Failure):
        print(f"no grasp: {found}")
        return 1
    for k, grasp in enumerate(found.ordered()):
        print(
            f"grasp {k}: cluster {grasp.cluster}, TCP at {np.round(grasp.position, 3)} m,"
            f" approach {np.round(grasp.approach, 2)}, width {grasp.width * 1000:.0f} mm,"
            f" score {grasp.score:.3f}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
