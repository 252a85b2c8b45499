"""What only a simulated robot offers: its ground truth (`GET /sim/objects`) and a new scene
(`POST /scene`). The CLI includes these routes with `include_simulator` only when the robot is
simulated, handing in the simulator's service (`robot.sim.service.SimulatorService`); a real
robot serves neither, and the server imports nothing of the simulator.

Frames: `world` and `base` as named; metres.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

import numpy as np
from fastapi import APIRouter, FastAPI, Request

from laserpick.robot.interface import Robot
from laserpick.server import schemas as S
from laserpick.server.errors import unprocessable
from laserpick.server.routers.dependencies import API, Commander, SessionDep
from laserpick.server.routers.replies import CONFLICT, guarded

__all__ = ["Simulator", "include_simulator", "router"]

router = APIRouter(prefix=API)


class ObjectReading(Protocol):
    name: str
    model: str
    position_world: np.ndarray
    quat_world: np.ndarray
    center_base: np.ndarray
    top_base: float
    in_basket: bool
    upright: float


class Simulator(Protocol):
    """The simulator's extras, as the routes use them (`SimulatorService` implements it)."""

    def scene_name(self, robot: Robot) -> str: ...

    def objects(self, robot: Robot) -> list[ObjectReading]: ...

    def robot_for(
        self, name: str | None, yaml: str | None, files: dict[str, str], seed: int | None
    ) -> tuple[Callable[[], Robot], str]:
        """A robot builder for the scene, and its name; raises ValueError for a bad scene."""
        ...


def include_simulator(app: FastAPI, simulator: Simulator) -> None:
    """Serve the simulator's routes on `app` (made by `create_app`), and name the scene in
    `GET /health`."""
    app.state.simulator = simulator
    app.state.settings.scene_name = lambda session: simulator.scene_name(session.robot)
    app.include_router(router)


def _rounded(v: np.ndarray) -> list[float]:
    return [round(float(x), 4) for x in v]


@router.get("/sim/objects", response_model=list[S.SimObject], tags=["simulation"])
def sim_objects(request: Request, session: SessionDep) -> list[S.SimObject]:
    """Simulator ground truth: where each object is. For scoring and scripted operators
    (benchmarks, tests) only; a real robot has no such endpoint, and the session never
    reads it."""
    simulator: Simulator = request.app.state.simulator
    return [
        S.SimObject(
            name=o.name,
            model=o.model,
            position_world=_rounded(o.position_world),
            quat_world=_rounded(o.quat_world),
            center_base=_rounded(o.center_base),
            top_base=float(round(o.top_base, 4)),
            in_basket=o.in_basket,
            upright=float(round(o.upright, 4)),
        )
        for o in simulator.objects(session.robot)
    ]


@router.post("/scene", response_model=S.Ok, tags=["task"], responses=CONFLICT)
def scene(body: S.SceneRequest, who: Commander, session: SessionDep, request: Request) -> S.Ok:
    """Reset to a built-in scene, or to an uploaded scene file with its meshes."""
    simulator: Simulator = request.app.state.simulator
    try:
        build, name = simulator.robot_for(body.name, body.yaml, body.files, body.seed)
    except ValueError as exc:
        raise unprocessable("body", str(exc)) from None
    return guarded(session, lambda: session.replace_robot(who, build, name))
