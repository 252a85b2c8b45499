"""Grasps: find them again for the perceived target, and move the current one through the
clusters and their candidates."""

from __future__ import annotations

from fastapi import APIRouter

from laserpick.server import schemas as S
from laserpick.server.routers.dependencies import API, Commander, SessionDep
from laserpick.server.routers.replies import CONFLICT, guarded

__all__ = ["router"]

router = APIRouter(prefix=API, tags=["grasps"], responses=CONFLICT)


@router.post("/detect", response_model=S.Ok)
def detect(who: Commander, session: SessionDep) -> S.Ok:
    """Find grasps again for the perceived target (with the current strategy)."""
    return guarded(session, lambda: session.detect(who))


@router.post("/grasps/next", response_model=S.Ok)
def grasps_next(who: Commander, session: SessionDep, body: S.StepRequest | None = None) -> S.Ok:
    level = body.level if body is not None else "cluster"
    return guarded(session, lambda: session.step_grasp(who, +1, level))


@router.post("/grasps/prev", response_model=S.Ok)
def grasps_prev(who: Commander, session: SessionDep, body: S.StepRequest | None = None) -> S.Ok:
    level = body.level if body is not None else "cluster"
    return guarded(session, lambda: session.step_grasp(who, -1, level))


@router.post("/grasps/select", response_model=S.Ok)
def grasps_select(body: S.SelectRequest, who: Commander, session: SessionDep) -> S.Ok:
    return guarded(session, lambda: session.select_grasp(who, body.cluster, body.candidate))


@router.post("/grasps/auto", response_model=S.Ok)
def grasps_auto(who: Commander, session: SessionDep) -> S.Ok:
    """Back to the system's choice: the best grasp of the best cluster."""
    return guarded(session, lambda: session.auto_grasp(who))
