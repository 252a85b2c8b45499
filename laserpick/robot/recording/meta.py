"""Reading and checking a recording's meta.json, and checking its arrays.

`MetaReader.read` turns the parsed JSON into values, collecting every problem it meets as
(where, what): a field path such as `captures[0].frames.left_25.K` and a sentence.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

import numpy as np

from laserpick.robot.interface import GripperState, JointState
from laserpick.robot.pointer import LaserState
from laserpick.robot.recording.values import FORMAT, UNITS, VERSION, Hint
from laserpick.types import Projector

#: Camera names and capture directories are plain file names.
NAME = re.compile(r"^[A-Za-z0-9_\-][A-Za-z0-9_.\-]{0,63}$")
#: How far a pose's rotation may be from orthonormal (JSON keeps floats exactly; a driver
#: writing rounded calibration stays well within this).
ROTATION_TOLERANCE = 1e-5
#: What `MetaReader.get` returns for a missing field it has reported: readers pass it on as
#: None without reporting it again.
ABSENT = object()
_NO_DEFAULT = object()


@dataclass(frozen=True)
class MetaCapture:
    """One capture's entry in meta.json. calibration: per camera (K, T_base_cam, stamp)."""

    dir: str
    stamp: float
    calibration: dict[str, tuple[np.ndarray, np.ndarray, float]]
    joints: JointState
    gripper: GripperState
    base_pose: np.ndarray
    laser: LaserState | None
    hint: Hint | None


@dataclass(frozen=True)
class Meta:
    """meta.json, read and checked."""

    cameras: tuple[str, ...]
    captures: tuple[MetaCapture, ...]
    projector: Projector | None
    source: str


def _missing(*values: Any) -> bool:
    """Whether any value is None (one that could not be read)."""
    return any(v is None for v in values)


def array_problems(depth: np.ndarray, ir: np.ndarray, where: str) -> list[tuple[str, str]]:
    """What is wrong with one camera's depth (float32 m) and IR (uint8) images, if anything;
    `where` names the camera's files without their suffix (`capture-000/left_25`)."""
    out = []
    if depth.ndim != 2 or depth.dtype != np.float32:
        out.append(
            (f"{where}.depth.npy", f"must be (H, W) float32 m, not {depth.dtype} {depth.shape}")
        )
    elif not np.all(np.isfinite(depth)):
        out.append((f"{where}.depth.npy", "contains NaN or infinity (write 0 for no reading)"))
    elif np.any(depth < 0):
        out.append((f"{where}.depth.npy", "contains negative depths"))
    if ir.ndim != 2 or ir.dtype != np.uint8:
        out.append((f"{where}.ir.npy", f"must be (H, W) uint8, not {ir.dtype} {ir.shape}"))
    elif depth.ndim == 2 and ir.shape != depth.shape:
        out.append((f"{where}.ir.npy", f"shape {ir.shape} differs from the depth's {depth.shape}"))
    return out


class MetaReader:
    """Reads meta.json's values; `problems` collects what is wrong, with where."""

    def __init__(self) -> None:
        self.problems: list[tuple[str, str]] = []

    def bad(self, where: str, what: str) -> None:
        self.problems.append((where, what))

    # --- values -------------------------------------------------------------------------

    def get(self, obj: dict, key: str, where: str, default: Any = _NO_DEFAULT) -> Any:
        """obj[key]; `default` when it is missing, or, without one, a problem and ABSENT."""
        if key in obj:
            return obj[key]
        if default is _NO_DEFAULT:
            self.bad(f"{where}.{key}" if where else key, "missing")
            return ABSENT
        return default

    def mapping(self, v: Any, where: str) -> dict | None:
        if isinstance(v, dict):
            return v
        if v is not ABSENT:
            self.bad(where, f"must be a JSON object, not {v!r}")
        return None

    def number(self, v: Any, where: str) -> float | None:
        if v is ABSENT:
            return None
        if isinstance(v, bool) or not isinstance(v, int | float):
            self.bad(where, f"must be a number, not {v!r}")
            return None
        if not math.isfinite(v):
            self.bad(where, f"must be finite, not {v!r}")
            return None
        return float(v)

    def flag(self, v: Any, where: str) -> bool | None:
        if v is ABSENT:
            return None
        if not isinstance(v, bool):
            self.bad(where, f"must be true or false, not {v!r}")
            return None
        return v

    def text(self, v: Any, where: str) -> str | None:
        if v is ABSENT:
            return None
        if not isinstance(v, str):
            self.bad(where, f"must be a string, not {v!r}")
            return None
        return v

    def name(self, v: Any, where: str) -> str | None:
        if self.text(v, where) is None:
            return None
        if not NAME.match(v) or v in (".", ".."):
            self.bad(where, f"{v!r} is not a plain file name (letters, digits, '_', '-', '.')")
            return None
        return v

    def array(self, v: Any, shape: tuple[int, ...], where: str) -> np.ndarray | None:
        if v is ABSENT:
            return None
        try:
            a = np.asarray(v, dtype=float)
        except (TypeError, ValueError):
            self.bad(where, f"must be numbers of shape {shape}")
            return None
        if a.shape != shape:
            self.bad(where, f"must have shape {shape}, not {a.shape}")
            return None
        if not np.all(np.isfinite(a)):
            self.bad(where, "contains NaN or infinity")
            return None
        return a

    def intrinsics(self, v: Any, where: str) -> np.ndarray | None:
        K = self.array(v, (3, 3), where)
        if K is None:
            return None
        if not np.array_equal(K[2], [0.0, 0.0, 1.0]) or K[1, 0] != 0.0:
            self.bad(where, "is not a pinhole K: its last row must be [0, 0, 1] and K[1][0] 0")
            return None
        if K[0, 0] <= 0 or K[1, 1] <= 0:
            self.bad(where, "focal lengths K[0][0] and K[1][1] must be positive (px)")
            return None
        return K

    def pose(self, v: Any, where: str) -> np.ndarray | None:
        T = self.array(v, (4, 4), where)
        if T is None:
            return None
        if not np.array_equal(T[3], [0.0, 0.0, 0.0, 1.0]):
            self.bad(where, "is not a rigid transform: its last row must be [0, 0, 0, 1]")
            return None
        R = T[:3, :3]
        off = np.max(np.abs(R.T @ R - np.eye(3)))
        if off > ROTATION_TOLERANCE or np.linalg.det(R) < 0:
            self.bad(where, f"its rotation is not a proper rotation (off by {off:.2g})")
            return None
        return T

    # --- meta.json ----------------------------------------------------------------------

    def read(self, meta: Any) -> Meta | None:
        """The checked values of meta.json, or None with `problems` saying why."""
        if self.mapping(meta, "meta.json") is None:
            return None
        if meta.get("format") != FORMAT:
            self.bad("format", f"must be {FORMAT!r}, not {meta.get('format')!r}")
            return None
        if meta.get("version") != VERSION:
            self.bad(
                "version", f"this laserpick reads version {VERSION}, not {meta.get('version')!r}"
            )
            return None
        units = self.mapping(self.get(meta, "units", "", UNITS), "units") or {}
        for key, unit in units.items():
            if key in UNITS and unit != UNITS[key]:
                self.bad(f"units.{key}", f"must be {UNITS[key]!r}, not {unit!r}")
        source = self.text(self.get(meta, "source", "", ""), "source") or ""
        cameras = self.cameras(self.get(meta, "cameras", ""))
        raw_projector = self.get(meta, "projector", "", None)
        projector = None if raw_projector is None else self.projector(raw_projector)
        raw = self.get(meta, "captures", "")
        if not isinstance(raw, list) or not raw:
            if raw is not ABSENT:
                self.bad("captures", "must be a non-empty list")
            return None
        captures = [self.capture(c, f"captures[{i}]", cameras) for i, c in enumerate(raw)]
        dirs = [c.dir for c in captures if c is not None]
        if len(set(dirs)) != len(dirs):
            self.bad("captures", "two captures share a dir")
        if self.problems:
            return None
        return Meta(cameras, tuple(captures), projector, source)

    def cameras(self, v: Any) -> tuple[str, ...]:
        if not isinstance(v, list) or not v:
            if v is not ABSENT:
                self.bad("cameras", "must be a non-empty list of camera names")
            return ()
        names = [self.name(c, f"cameras[{i}]") for i, c in enumerate(v)]
        if len(set(names)) != len(names):
            self.bad("cameras", "names a camera twice")
        return tuple(n for n in names if n is not None)

    def projector(self, v: Any) -> Projector | None:
        if self.mapping(v, "projector") is None:
            return None
        K = self.intrinsics(self.get(v, "K", "projector"), "projector.K")
        T = self.pose(self.get(v, "T_base_proj", "projector"), "projector.T_base_proj")
        size = [self.get(v, key, "projector") for key in ("width", "height")]
        if ABSENT in size:
            return None
        if not all(isinstance(s, int) and not isinstance(s, bool) and s > 0 for s in size):
            self.bad("projector", f"width and height must be positive pixel counts, not {size}")
            return None
        return None if K is None or T is None else Projector(K, T, size[0], size[1])

    def capture(self, c: Any, where: str, cameras: tuple[str, ...]) -> MetaCapture | None:
        if self.mapping(c, where) is None:
            return None
        folder = self.name(self.get(c, "dir", where), f"{where}.dir")
        stamp = self.number(self.get(c, "stamp", where), f"{where}.stamp")
        frames = self.calibration(self.get(c, "frames", where), f"{where}.frames", cameras)
        joints = self.joints(self.get(c, "joints", where), f"{where}.joints", stamp or 0.0)
        gripper = self.gripper(self.get(c, "gripper", where), f"{where}.gripper")
        pose = self.get(c, "base_pose", where, [0.0, 0.0, 0.0])
        base_pose = self.array(pose, (3,), f"{where}.base_pose")
        laser = self.get(c, "laser", where, None)
        laser = None if laser is None else self.laser(laser, f"{where}.laser")
        hint = self.get(c, "hint", where, None)
        hint = None if hint is None else self.hint(hint, f"{where}.hint")
        if _missing(folder, stamp, joints, gripper, base_pose) or len(frames) != len(cameras):
            return None
        calibration = {cam: (K, T, stamp if s is None else s) for cam, (K, T, s) in frames.items()}
        return MetaCapture(folder, stamp, calibration, joints, gripper, base_pose, laser, hint)

    def calibration(
        self, v: Any, where: str, cameras: tuple[str, ...]
    ) -> dict[str, tuple[np.ndarray, np.ndarray, float | None]]:
        """Per camera (K, T_base_cam, stamp or None for the capture's)."""
        if self.mapping(v, where) is None:
            return {}
        for extra in sorted(set(v) - set(cameras)):
            self.bad(f"{where}.{extra}", "is not among `cameras`")
        out = {}
        for cam in cameras:
            f = self.mapping(self.get(v, cam, where), f"{where}.{cam}")
            if f is None:
                continue
            K = self.intrinsics(self.get(f, "K", f"{where}.{cam}"), f"{where}.{cam}.K")
            T = self.pose(self.get(f, "T_base_cam", f"{where}.{cam}"), f"{where}.{cam}.T_base_cam")
            stamp = self.get(f, "stamp", f"{where}.{cam}", None)
            stamp = None if stamp is None else self.number(stamp, f"{where}.{cam}.stamp")
            if K is not None and T is not None:
                out[cam] = (K, T, stamp)
        return out

    def joints(self, v: Any, where: str, stamp: float) -> JointState | None:
        if self.mapping(v, where) is None:
            return None
        q = self.array(self.get(v, "q", where), (6,), f"{where}.q")
        qd = self.array(self.get(v, "qd", where, [0.0] * 6), (6,), f"{where}.qd")
        return None if q is None or qd is None else JointState(q, qd, stamp)

    def gripper(self, v: Any, where: str) -> GripperState | None:
        if self.mapping(v, where) is None:
            return None
        width = self.number(self.get(v, "width", where), f"{where}.width")
        force = self.number(self.get(v, "force", where), f"{where}.force")
        closed = self.flag(self.get(v, "closed", where), f"{where}.closed")
        holding = self.flag(self.get(v, "holding", where), f"{where}.holding")
        if width is not None and width < 0:
            self.bad(f"{where}.width", f"must not be negative, not {width}")
            return None
        if _missing(width, force, closed, holding):
            return None
        return GripperState(width, force, closed, holding)

    def laser(self, v: Any, where: str) -> LaserState | None:
        if self.mapping(v, where) is None:
            return None
        on = self.flag(self.get(v, "on", where), f"{where}.on")
        confirmed = self.flag(self.get(v, "confirmed", where), f"{where}.confirmed")
        yaw = self.number(self.get(v, "yaw", where), f"{where}.yaw")
        pitch = self.number(self.get(v, "pitch", where), f"{where}.pitch")
        if _missing(on, confirmed, yaw, pitch):
            return None
        return LaserState(on, confirmed, yaw, pitch)

    def hint(self, v: Any, where: str) -> Hint | None:
        if self.mapping(v, where) is None:
            return None
        name = self.text(self.get(v, "object", where), f"{where}.object")
        top = self.array(self.get(v, "top_base", where), (3,), f"{where}.top_base")
        return None if name is None or top is None else Hint(name, top)
