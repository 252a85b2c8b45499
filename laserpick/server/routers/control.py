"""The control lease: take it (or renew it with your token, a heartbeat), and give it up."""

from __future__ import annotations

import hmac

from fastapi import APIRouter, HTTPException

from laserpick.server import schemas as S
from laserpick.server.lease import LeaseHeld
from laserpick.server.routers.dependencies import API, Commander, Credentials, SessionDep
from laserpick.server.routers.replies import TOKEN_OPTIONAL, UNAUTHORIZED, ok, robot_time

__all__ = ["router"]

router = APIRouter(prefix=API, tags=["control"])


@router.post(
    "/control",
    response_model=S.ControlGrant,
    responses={
        401: {"model": S.Problem, "description": "Wrong or missing operator password."},
        409: {"model": S.Refusal, "description": "Someone else holds control."},
    },
    openapi_extra=TOKEN_OPTIONAL,
)
def take_control(body: S.ControlRequest, session: SessionDep, creds: Credentials) -> S.ControlGrant:
    """Take the control lease, or renew it (a heartbeat) by sending your token."""
    password = session.settings.operator_password
    if password is not None and not hmac.compare_digest(
        (body.password or "").encode(), password.get_secret_value().encode()
    ):
        raise HTTPException(401, "wrong or missing operator password")
    try:
        token = session.lease.acquire(body.name, body.source, creds.credentials if creds else None)
    except LeaseHeld as exc:
        raise HTTPException(409, {"detail": str(exc), "state": session.state.value}) from None
    server = session.settings.server
    return S.ControlGrant(
        token=token,
        holder=body.name,
        lease_timeout_s=server.lease_timeout_s,
        watchdog_s=server.watchdog_s,
    )


@router.delete("/control", response_model=S.Ok, responses=UNAUTHORIZED)
def release_control(who: Commander, session: SessionDep) -> S.Ok:
    assert who.token is not None
    session.lease.release(who.token)
    return ok(session, robot_time(session))
