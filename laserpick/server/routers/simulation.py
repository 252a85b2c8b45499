"""What only a simulated robot offers: its ground truth (`GET /sim/objects`) and a new scene
(`POST /scene`). The CLI includes these routes (`include_simulator`) only when the robot is a
`SimRobot`; a real robot serves neither. The only server module that imports the simulator.

Frames: `world` and `base` as named; metres.
"""

from __future__ import annotations

import base64
import tempfile
from pathlib import Path

import numpy as np
from fastapi import APIRouter, FastAPI

from laserpick.robot.sim.robot import SimRobot
from laserpick.robot.sim.scenes import Scene, SceneError, load_scene, parse_scene
from laserpick.robot.sim.truth import SimTruth
from laserpick.server import schemas as S
from laserpick.server.errors import unprocessable
from laserpick.server.routers.dependencies import API, Commander, SessionDep
from laserpick.server.routers.replies import CONFLICT, guarded
from laserpick.server.session import Session

__all__ = ["include_simulator", "router", "scene_name"]

router = APIRouter(prefix=API)


def include_simulator(app: FastAPI) -> None:
    """Serve the simulator's routes on `app` (made by `create_app`), and name the scene in
    `GET /health`."""
    app.include_router(router)
    app.state.settings.scene_name = scene_name


def scene_name(session: Session) -> str:
    """The name of the scene the session's simulated robot is in ("" when it has none)."""
    robot = session.robot
    scene = robot.sim.scene if isinstance(robot, SimRobot) else None
    return scene.name if scene is not None else ""


def _rounded(v: np.ndarray) -> list[float]:
    return [round(float(x), 4) for x in v]


@router.get("/sim/objects", response_model=list[S.SimObject], tags=["simulation"])
def sim_objects(session: SessionDep) -> list[S.SimObject]:
    """Simulator ground truth: where each object is. For scoring and scripted operators
    (benchmarks, tests) only; a real robot has no such endpoint, and the session never
    reads it."""
    robot = session.robot
    assert isinstance(robot, SimRobot)
    truth = SimTruth(robot)
    out = []
    for p in robot.sim.scene.placements if robot.sim.scene else ():
        pts = truth.object_points(p.instance)
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        q = truth.world_quat(p.instance)
        out.append(
            S.SimObject(
                name=p.instance,
                model=p.model.name,
                position_world=_rounded(truth.world_position(p.instance)),
                quat_world=_rounded(q),
                center_base=_rounded((lo + hi) / 2),
                top_base=float(round(hi[2], 4)),
                in_basket=truth.in_basket(p.instance),
                # the body's z axis against world z: 1 upright, 0 on its side
                upright=float(round(1 - 2 * (q[1] ** 2 + q[2] ** 2), 4)),
            )
        )
    return out


@router.post("/scene", response_model=S.Ok, tags=["task"], responses=CONFLICT)
def scene(body: S.SceneRequest, who: Commander, session: SessionDep) -> S.Ok:
    """Reset to a built-in scene, or to an uploaded scene file with its meshes."""
    try:
        if body.name is not None:
            new = load_scene(body.name, seed=body.seed)
        else:
            assert body.yaml is not None
            new = _uploaded_scene(body.yaml, body.files, body.seed)
    except SceneError as exc:
        raise unprocessable("body", str(exc)) from None

    def build() -> SimRobot:
        return SimRobot(new, realtime=True, settings=session.settings)

    return guarded(session, lambda: session.replace_robot(who, build, new.name))


def _uploaded_scene(text: str, files: dict[str, str], seed: int | None) -> Scene:
    """Parse an uploaded scene whose meshes came along as base64, in a private directory
    (file names were checked to be plain names, so nothing lands outside it)."""
    with tempfile.TemporaryDirectory(prefix="laserpick-scene-") as tmp:
        base = Path(tmp)
        for name, data in files.items():
            try:
                raw = base64.b64decode(data, validate=True)
            except ValueError:
                raise SceneError("<upload>", [(f"files.{name}", "not valid base64")]) from None
            (base / name).write_bytes(raw)
        return parse_scene(text, source=base / "uploaded.yaml", base_dir=base, seed=seed)
