"""Writing a recording to a directory and reading one back; taking a capture from a robot."""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

import numpy as np

from laserpick.robot.interface import Robot
from laserpick.robot.recording.meta import MetaReader, array_problems
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
from laserpick.types import DepthFrame


def capture_from(robot: Robot, hint: Hint | None = None) -> RecordedCapture:
    """Capture now from `robot` (simulated or real), with its joint, gripper, base and laser
    state. hint: for tests only (`Hint`)."""
    frames = tuple(robot.capture())
    joints = robot.joint_state()
    return RecordedCapture(
        frames=frames,
        joints=joints,
        gripper=robot.gripper_state(),
        base_pose=np.asarray(robot.base_pose(), float).copy(),
        stamp=float(frames[0].stamp) if frames else float(joints.stamp),
        laser=robot.laser.state,
        hint=hint,
    )


# --- writing -------------------------------------------------------------------------------


def _matrix(a: np.ndarray) -> list[list[float]]:
    return [[float(x) for x in row] for row in np.asarray(a, float)]


def _vector(a: np.ndarray) -> list[float]:
    return [float(x) for x in np.asarray(a, float).reshape(-1)]


def _capture_meta(index: int, cap: RecordedCapture) -> dict:
    g = cap.gripper
    out: dict = {
        "dir": capture_dir(index),
        "stamp": float(cap.stamp),
        "frames": {
            f.camera: {
                "K": _matrix(f.K),
                "T_base_cam": _matrix(f.T_base_cam),
                "stamp": float(f.stamp),
            }
            for f in cap.frames
        },
        "joints": {"q": _vector(cap.joints.q), "qd": _vector(cap.joints.qd)},
        "gripper": {
            "width": float(g.width),
            "force": float(g.force),
            "closed": bool(g.closed),
            "holding": bool(g.holding),
        },
        "base_pose": _vector(cap.base_pose),
        "laser": None,
    }
    if cap.laser is not None:
        las = cap.laser
        out["laser"] = {
            "on": bool(las.on),
            "confirmed": bool(las.confirmed),
            "yaw": float(las.yaw),
            "pitch": float(las.pitch),
        }
    if cap.hint is not None:
        out["hint"] = {"object": cap.hint.object, "top_base": _vector(cap.hint.top_base)}
    return out


def recording_meta(recording: Recording) -> dict:
    """meta.json of `recording`, as JSON-ready values."""
    meta: dict = {
        "format": FORMAT,
        "version": VERSION,
        "units": dict(UNITS),
        "frame": FRAME,
        "source": recording.source,
        "cameras": list(recording.cameras),
    }
    if recording.projector is not None:
        p = recording.projector
        meta["projector"] = {
            "K": _matrix(p.K),
            "T_base_proj": _matrix(p.T_base_proj),
            "width": int(p.width),
            "height": int(p.height),
        }
    meta["captures"] = [_capture_meta(i, c) for i, c in enumerate(recording.captures)]
    return meta


#: A JSON list of numbers only (no nested list, object or string).
_NUMBERS = re.compile(r"\[[^\[\]{}\"]*\]")


def meta_text(meta: dict) -> str:
    """meta.json's text: indented, with each list of numbers (a vector, a matrix row) on
    one line."""
    text = json.dumps(meta, indent=1, allow_nan=False)
    return (
        _NUMBERS.sub(
            lambda m: " ".join(m.group(0).split()).replace("[ ", "[").replace(" ]", "]"), text
        )
        + "\n"
    )


def write_recording(directory: str | os.PathLike, recording: Recording) -> Path:
    """Write `recording` into `directory` (new, or empty); the directory.

    Everything is checked first, as `read_recording` checks it (RecordingError), and
    meta.json is written last: a directory without it is no recording. FileExistsError if
    the directory holds files already."""
    root = Path(directory)
    if root.exists() and (not root.is_dir() or any(root.iterdir())):
        raise FileExistsError(f"{root} already exists and is not an empty directory")
    meta = recording_meta(recording)
    reader = MetaReader()
    reader.read(meta)
    problems = list(reader.problems)
    for i, cap in enumerate(recording.captures):
        cameras = tuple(f.camera for f in cap.frames)
        if cameras != recording.cameras:
            problems.append((f"captures[{i}]", f"cameras {cameras} differ from the first's"))
        for f in cap.frames:
            problems += array_problems(f.depth, f.ir, f"{capture_dir(i)}/{f.camera}")
    if problems:
        raise RecordingError(str(root), problems)
    for i, cap in enumerate(recording.captures):
        folder = root / capture_dir(i)
        folder.mkdir(parents=True)
        for f in cap.frames:
            np.save(folder / f"{f.camera}.depth.npy", f.depth, allow_pickle=False)
            np.save(folder / f"{f.camera}.ir.npy", f.ir, allow_pickle=False)
    (root / META).write_text(meta_text(meta))
    return root


# --- reading -------------------------------------------------------------------------------


def _load(path: Path, where: str, problems: list[tuple[str, str]]) -> np.ndarray | None:
    if not path.is_file():
        problems.append((where, "missing"))
        return None
    try:
        return np.load(path, allow_pickle=False)
    except (OSError, ValueError) as exc:
        problems.append((where, f"not an array numpy can read ({exc})"))
        return None


def read_recording(directory: str | os.PathLike) -> Recording:
    """Read and check the recording in `directory`. RecordingError lists every problem found,
    each with where it is (a meta.json field path, or a file) and what is wrong."""
    root = Path(directory)
    if not root.is_dir():
        raise RecordingError(str(root), [("", "no such directory")])
    if not (root / META).is_file():
        raise RecordingError(str(root), [(META, "missing: this is not a laserpick recording")])
    try:
        raw = json.loads((root / META).read_text(encoding="utf-8"))
    except (ValueError, UnicodeDecodeError) as exc:
        raise RecordingError(str(root), [(META, f"not valid JSON: {exc}")]) from None
    reader = MetaReader()
    meta = reader.read(raw)
    problems = reader.problems
    if meta is None or problems:
        raise RecordingError(str(root), problems)
    captures = []
    for cap in meta.captures:
        frames = []
        for cam in meta.cameras:
            where = f"{cap.dir}/{cam}"
            depth = _load(root / cap.dir / f"{cam}.depth.npy", f"{where}.depth.npy", problems)
            ir = _load(root / cap.dir / f"{cam}.ir.npy", f"{where}.ir.npy", problems)
            bad = [] if depth is None or ir is None else array_problems(depth, ir, where)
            problems += bad
            if depth is not None and ir is not None and not bad:
                K, T, stamp = cap.calibration[cam]
                frames.append(DepthFrame(depth, ir, K, T, cam, stamp))
        captures.append(
            RecordedCapture(
                tuple(frames),
                cap.joints,
                cap.gripper,
                cap.base_pose,
                cap.stamp,
                cap.laser,
                cap.hint,
            )
        )
    if problems:
        raise RecordingError(str(root), problems)
    return Recording(tuple(captures), meta.projector, meta.source)
