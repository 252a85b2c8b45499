"""How a command is answered: `Ok` with the state after it and the robot time it was taken,
409 when it conflicts with the task state, 422 when the session finds the input invalid; and
503 when it needed a new capture and the cameras gave none; and the documented refusals every
command route lists in the OpenAPI."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from fastapi import HTTPException

from laserpick.server import schemas as S
from laserpick.server.errors import unprocessable
from laserpick.server.session import CamerasUnavailable, Conflict, Session

__all__ = [
    "CONFLICT",
    "NO_FRAMES",
    "TOKEN_OPTIONAL",
    "UNAUTHORIZED",
    "cameras_down",
    "guarded",
    "ok",
    "robot_time",
]

UNAUTHORIZED: dict[int | str, dict[str, Any]] = {
    401: {"model": S.Problem, "description": "No token, or not the lease's."}
}
CONFLICT: dict[int | str, dict[str, Any]] = {
    **UNAUTHORIZED,
    409: {"model": S.Refusal, "description": "Conflicts with the task state."},
}
NO_FRAMES: dict[int | str, dict[str, Any]] = {
    503: {"model": S.Problem, "description": "A new capture was needed; the cameras gave none."}
}
#: The token is optional here. FastAPI lists the bearer scheme as required and appends
#: these requirements to it; the empty one makes the scheme optional in the OpenAPI.
TOKEN_OPTIONAL: dict[str, Any] = {"security": [{}]}


def robot_time(session: Session) -> float:
    """The robot's clock now (s)."""
    return session.robot.state().stamp


def ok(session: Session, taken_at: float) -> S.Ok:
    """The answer to a command taken at robot time `taken_at` (s)."""
    return S.Ok(state=session.state.value, message=session.message, sim_time=taken_at)


def guarded(session: Session, fn: Callable[[], object]) -> S.Ok:
    """Run a session command: `Ok`, or 409 on a `Conflict`, 422 on a ValueError or
    IndexError (input the session found invalid), 503 on `CamerasUnavailable`."""
    taken_at = robot_time(session)
    try:
        fn()
    except Conflict as exc:
        raise HTTPException(409, {"detail": str(exc), "state": exc.state.value}) from None
    except (ValueError, IndexError) as exc:
        raise unprocessable("body", str(exc)) from None
    except CamerasUnavailable as exc:
        raise cameras_down(exc) from None
    return ok(session, taken_at)


def cameras_down(exc: CamerasUnavailable) -> HTTPException:
    """The 503 for a read or command that needed frames the cameras could not give."""
    return HTTPException(503, str(exc))
