"""The browser page at `/`, the 3D view's page at `/view`, and the page's files under
`/static` (mounted by `create_app`)."""

from __future__ import annotations

from pathlib import Path

from fastapi import APIRouter, HTTPException
from fastapi.responses import HTMLResponse

from laserpick.console.view_page import view_page
from laserpick.server.routers.dependencies import SettingsDep

__all__ = ["STATIC", "router"]

#: The browser page: index.html at `/`, its stylesheet and script under `/static`.
STATIC = Path(__file__).resolve().parents[2] / "static"

_MINIMAL_PAGE = """<!doctype html><html lang="en"><meta charset="utf-8">
<title>laserpick</title><h1>laserpick</h1>
<p>The API is documented at <a href="/docs">/docs</a>.</p></html>"""

router = APIRouter(include_in_schema=False)


@router.get("/", response_class=HTMLResponse)
def index(settings: SettingsDep) -> HTMLResponse:
    html = STATIC / "index.html"
    if settings.page is not None:
        text = settings.page()
    else:
        text = html.read_text(encoding="utf-8") if html.is_file() else _MINIMAL_PAGE
    return HTMLResponse(text)


@router.get("/view", response_class=HTMLResponse)
def view() -> HTMLResponse:
    """The 3D view's page, which the page at `/` embeds (console/view_page.py)."""
    try:
        return HTMLResponse(view_page())
    except RuntimeError as exc:
        raise HTTPException(503, str(exc)) from exc
