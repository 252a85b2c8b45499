"""What the simulator offers beyond the `Robot` seam, for the server's optional `/sim` routes:
its ground truth (where each object is) and new scenes. The CLI hands a `SimulatorService` to
`server.routers.simulation.include_simulator` only when the robot is simulated, so the server
never imports the simulator; a real robot offers no such service.

Frames: `world` and `base` as named; metres; quaternions (w, x, y, z).
"""

from __future__ import annotations

import base64
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from laserpick.robot.interface import Robot
from laserpick.robot.sim.robot import SimRobot
from laserpick.robot.sim.scenes import Scene, SceneError, load_scene, parse_scene
from laserpick.robot.sim.truth import SimTruth
from laserpick.settings import Settings

__all__ = ["ObjectTruth", "SimulatorService"]


@dataclass(frozen=True)
class ObjectTruth:
    """Where one object is, by the simulator's truth.

    center_base: the middle of its bounds in `base` (m); top_base: its highest point's z in
    `base` (m); upright: its z axis against world z (1 upright, 0 on its side).
    """

    name: str
    model: str
    position_world: np.ndarray
    quat_world: np.ndarray
    center_base: np.ndarray
    top_base: float
    in_basket: bool
    upright: float


class SimulatorService:
    """The simulator's extras for the server: truth about objects, and robots for new scenes.

    Scene errors raise `SceneError`, a `ValueError` naming the file, field and problem.
    """

    def __init__(self, settings: Settings) -> None:
        self.settings = settings

    @staticmethod
    def scene_name(robot: Robot) -> str:
        """The name of the scene `robot` simulates ("" when it is not simulated or empty)."""
        scene = robot.sim.scene if isinstance(robot, SimRobot) else None
        return scene.name if scene is not None else ""

    @staticmethod
    def objects(robot: Robot) -> list[ObjectTruth]:
        """Every object of the scene `robot` simulates, now; none for another robot."""
        if not isinstance(robot, SimRobot) or robot.sim.scene is None:
            return []
        truth = SimTruth(robot)
        out = []
        for p in robot.sim.scene.placements:
            pts = truth.object_points(p.instance)
            lo, hi = pts.min(axis=0), pts.max(axis=0)
            q = truth.world_quat(p.instance)
            out.append(
                ObjectTruth(
                    name=p.instance,
                    model=p.model.name,
                    position_world=truth.world_position(p.instance),
                    quat_world=q,
                    center_base=(lo + hi) / 2,
                    top_base=float(hi[2]),
                    in_basket=truth.in_basket(p.instance),
                    upright=float(1 - 2 * (q[1] ** 2 + q[2] ** 2)),
                )
            )
        return out

    def robot_for(
        self,
        name: str | None,
        yaml: str | None,
        files: dict[str, str],
        seed: int | None,
    ) -> tuple[Callable[[], Robot], str]:
        """A builder of a real-time robot in a built-in scene (`name`) or an uploaded one
        (`yaml` with its meshes as base64 `files`), and the scene's name. The scene is loaded
        here, so a bad one raises `SceneError` before anything is built."""
        scene = load_scene(name, seed=seed) if name is not None else _uploaded(yaml, files, seed)

        def build() -> Robot:
            return SimRobot(scene, realtime=True, settings=self.settings)

        return build, scene.name


def _uploaded(text: str | None, files: dict[str, str], seed: int | None) -> Scene:
    """Parse an uploaded scene whose meshes came along as base64, in a private directory
    (file names were checked to be plain names, so nothing lands outside it)."""
    if text is None:
        raise SceneError("<upload>", [("yaml", "give a scene name or a scene file")])
    with tempfile.TemporaryDirectory(prefix="laserpick-scene-") as tmp:
        base = Path(tmp)
        for name, data in files.items():
            try:
                raw = base64.b64decode(data, validate=True)
            except ValueError:
                raise SceneError("<upload>", [(f"files.{name}", "not valid base64")]) from None
            (base / name).write_bytes(raw)
        return parse_scene(text, source=base / "uploaded.yaml", base_dir=base, seed=seed)
