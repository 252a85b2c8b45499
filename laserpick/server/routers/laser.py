"""The laser: aim its single beam (by angles, at a point, or along a click's ray), nudge it,
confirm the mark with both beams, or turn it off."""

from __future__ import annotations

import numpy as np
from fastapi import APIRouter

from laserpick.server import schemas as S
from laserpick.server.routers.dependencies import API, Commander, SessionDep
from laserpick.server.routers.replies import CONFLICT, NO_FRAMES, guarded

__all__ = ["router"]

router = APIRouter(prefix=API, tags=["laser"], responses=CONFLICT)


@router.post("/laser/aim", response_model=S.AimResult, responses=NO_FRAMES)
def aim(body: S.AimRequest, who: Commander, session: SessionDep) -> S.AimResult:
    """Aim the laser's single beam by angles, at a point, or along a click ray."""
    hit: list[float] | None = None

    def run() -> None:
        nonlocal hit
        if body.yaw is not None and body.pitch is not None:
            session.aim(who, body.yaw, body.pitch)
        elif body.point is not None:
            session.aim_at(who, np.array(body.point), body.frame)
        else:
            assert body.ray is not None
            p = session.aim_ray(
                who, np.array(body.ray.origin), np.array(body.ray.direction), body.frame
            )
            hit = [round(float(x), 4) for x in p]

    guarded(session, run)
    return S.AimResult(hit=hit)


@router.post("/laser/nudge", response_model=S.Ok)
def nudge(body: S.NudgeRequest, who: Commander, session: SessionDep) -> S.Ok:
    return guarded(session, lambda: session.nudge(who, body.dyaw, body.dpitch))


@router.post("/laser/confirm", response_model=S.Ok)
def confirm(who: Commander, session: SessionDep) -> S.Ok:
    """Light both beams: mark the object (or, holding one, where to place it)."""
    return guarded(session, lambda: session.confirm(who))


@router.delete("/laser", response_model=S.Ok)
def laser_off(who: Commander, session: SessionDep) -> S.Ok:
    return guarded(session, lambda: session.laser_off(who))
