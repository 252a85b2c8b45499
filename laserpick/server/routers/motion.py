"""Motion: drive the base (a dead-man command), the e-stop (anyone may press it) and its
reset."""

from __future__ import annotations

from fastapi import APIRouter

from laserpick.server import schemas as S
from laserpick.server.routers.dependencies import API, Commander, Credentials, SessionDep
from laserpick.server.routers.replies import CONFLICT, TOKEN_OPTIONAL, guarded, ok, robot_time
from laserpick.server.session import Actor

__all__ = ["router"]

router = APIRouter(prefix=API, tags=["motion"])


@router.post("/drive", response_model=S.Ok, responses=CONFLICT)
def drive(body: S.DriveRequest, who: Commander, session: SessionDep) -> S.Ok:
    """Drive the base (a dead-man: the command lapses after `duration`, at most 0.5 s)."""
    return guarded(session, lambda: session.drive(who, body.v, body.w, body.duration, body.seq))


@router.post("/stop", response_model=S.Ok, openapi_extra=TOKEN_OPTIONAL)
def stop(session: SessionDep, creds: Credentials) -> S.Ok:
    """E-stop: halt the arm and the base now, latched until `POST /stop/reset`. Needs no
    token: anyone watching may stop the robot."""
    taken_at = robot_time(session)
    token = creds.credentials if creds else None
    source = session.lease.check(token) or "rest"
    session.stop(Actor(source, token))  # type: ignore[arg-type]
    return ok(session, taken_at)


@router.post("/stop/reset", response_model=S.Ok, responses=CONFLICT)
def stop_reset(who: Commander, session: SessionDep) -> S.Ok:
    return guarded(session, lambda: session.reset_stop(who))
