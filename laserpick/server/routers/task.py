"""The task: execute (pick, or drop what the hand holds), cancel, and the modes."""

from __future__ import annotations

from fastapi import APIRouter

from laserpick.server import schemas as S
from laserpick.server.routers.dependencies import API, Commander, SessionDep
from laserpick.server.routers.replies import CONFLICT, UNAUTHORIZED, guarded

__all__ = ["router"]

router = APIRouter(prefix=API, tags=["task"])


@router.post("/execute", response_model=S.Ok, responses=CONFLICT)
def execute(who: Commander, session: SessionDep) -> S.Ok:
    """Pick with the current grasp (manual) or the best that plans (auto); when holding,
    drop the object in the basket."""
    return guarded(session, lambda: session.execute(who))


@router.post("/cancel", response_model=S.Ok, responses=UNAUTHORIZED)
def cancel(who: Commander, session: SessionDep) -> S.Ok:
    return guarded(session, lambda: session.cancel(who))


@router.post("/mode", response_model=S.Ok, responses=CONFLICT)
def mode(body: S.ModeRequest, who: Commander, session: SessionDep) -> S.Ok:
    return guarded(session, lambda: session.set_mode(who, body.mode, body.selection, body.strategy))
