"""How the app refuses a request: 413 for a body over the size limit, 422 for invalid input
(naming the field, and recorded in the journal), and HTTP errors as JSON bodies."""

from __future__ import annotations

from fastapi import FastAPI, HTTPException, Request
from fastapi.encoders import jsonable_encoder
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.types import ASGIApp, Message, Receive, Scope, Send

__all__ = ["BodyLimit", "add_error_handlers", "unprocessable"]


class BodyLimit:
    """Refuse request bodies over `limit` bytes with 413, whether or not they declare a
    Content-Length (a chunked upload is counted as it arrives)."""

    def __init__(self, app: ASGIApp, limit: int) -> None:
        self.app, self.limit = app, limit

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        length = dict(scope.get("headers", [])).get(b"content-length")
        if length is not None and (not length.isdigit() or int(length) > self.limit):
            await _too_large(self.limit)(scope, receive, send)
            return
        seen = 0

        async def counted() -> Message:
            nonlocal seen
            message = await receive()
            seen += len(message.get("body", b""))
            if seen > self.limit:
                raise _BodyTooLarge(self.limit)
            return message

        try:
            await self.app(scope, counted, send)
        except _BodyTooLarge:
            await _too_large(self.limit)(scope, receive, send)


class _BodyTooLarge(HTTPException):
    """An HTTPException, so that FastAPI's body reader passes it on (rather than answering
    400) to the app's handler, which answers 413."""

    def __init__(self, limit: int) -> None:
        super().__init__(413, f"request body larger than {limit} bytes")


def _too_large(limit: int) -> JSONResponse:
    return JSONResponse({"detail": f"request body larger than {limit} bytes"}, status_code=413)


def unprocessable(where: str, message: str) -> HTTPException:
    """A 422 naming `where` (e.g. "body") with `message`, shaped as FastAPI's own."""
    return HTTPException(422, {"detail": [{"loc": [where], "msg": message, "type": "value_error"}]})


async def _http_error(request: Request, exc: StarletteHTTPException) -> JSONResponse:
    if exc.status_code == 400:  # FastAPI could not decode the body (not UTF-8): bad input
        error = {"loc": ("body",), "msg": str(exc.detail), "type": "json_invalid"}
        return await _invalid(request, RequestValidationError([error]))
    body = exc.detail if isinstance(exc.detail, dict) else {"detail": exc.detail}
    return JSONResponse(body, status_code=exc.status_code, headers=exc.headers)


async def _invalid(request: Request, exc: RequestValidationError) -> JSONResponse:
    errors = [
        {"loc": list(e.get("loc", ())), "msg": e.get("msg", ""), "type": e.get("type", "")}
        for e in exc.errors()
    ]
    journal = request.app.state.session.journal
    if journal is not None:
        fields = ", ".join(".".join(str(p) for p in e["loc"]) for e in errors)
        journal.record(source="rest", action="invalid", outcome="refused", message=fields[:500])
    return JSONResponse({"detail": jsonable_encoder(errors)}, status_code=422)


def add_error_handlers(app: FastAPI) -> None:
    """Answer HTTP errors with JSON bodies (FastAPI's 400 for an undecodable body becomes a
    422), and invalid input with 422 listing each field, recorded in the journal."""
    app.add_exception_handler(StarletteHTTPException, _http_error)  # FastAPI's 400 is Starlette's
    app.add_exception_handler(RequestValidationError, _invalid)  # type: ignore[arg-type]
