"""Recordings: captures saved from a robot, in a format a real sensor driver can also write.

A recording is a directory (the format is set out in docs/recording.md):

    meta.json                    format and version, units, camera names, the projector, and
                                 per capture: each camera's K and T_base_cam, joint, gripper
                                 and base state, the laser's aim
    capture-000/CAM.depth.npy    (H, W) float32 depth, m along the optical axis, 0 = no reading
    capture-000/CAM.ir.npy       (H, W) uint8 infrared intensity
    capture-001/...              further captures, in sequence

`json` and `numpy.load` alone read it; nothing here imports the simulator. `capture_from`
takes one capture from any `Robot`; `write_recording` writes a `Recording`; `read_recording`
reads one back and checks all of it, naming what is wrong and where (`RecordingError`).
`robot.recorded.RecordedRobot` serves one behind the `Robot` interface.
"""

from laserpick.robot.recording.files import (
    capture_from,
    read_recording,
    recording_meta,
    write_recording,
)
from laserpick.robot.recording.values import (
    FORMAT,
    FRAME,
    META,
    UNITS,
    VERSION,
    Hint,
    RecordedCapture,
    Recording,
    RecordingError,
    capture_dir,
)

__all__ = [
    "FORMAT",
    "FRAME",
    "META",
    "UNITS",
    "VERSION",
    "Hint",
    "RecordedCapture",
    "Recording",
    "RecordingError",
    "capture_dir",
    "capture_from",
    "read_recording",
    "recording_meta",
    "write_recording",
]
