"""Reads, which need no token: health (with the limits clients keep to), the session's state,
the projector image, the fused cloud, the journal and the server's own diagnostics."""

from __future__ import annotations

import resource
import time
from typing import Annotated, Literal

import numpy as np
from fastapi import APIRouter, HTTPException, Query, Request
from fastapi.responses import PlainTextResponse, Response

from laserpick import __version__
from laserpick.description import dims
from laserpick.pipeline.cloud import voxel_downsample
from laserpick.server import schemas as S
from laserpick.server.routers.dependencies import API, SessionDep, SettingsDep
from laserpick.server.routers.replies import NO_FRAMES, cameras_down
from laserpick.server.session import CamerasUnavailable
from laserpick.server.wire import CLOUD_FORMAT, encode_cloud, encode_png

__all__ = ["router"]

router = APIRouter(prefix=API, tags=["read"])

_STARTED = time.monotonic()


@router.get("/health", response_model=S.Health)
def health(session: SessionDep, settings: SettingsDep) -> S.Health:
    return S.Health(
        status="ok",
        version=__version__,
        scene=settings.scene_name(session),
        viser_port=settings.viser_port,
        viser_url=settings.viser_url,
        rtf=round(session.robot.state().rtf, 3),
        max_nudge=S.MAX_NUDGE,
        max_drive_duration=S.MAX_DRIVE_DURATION,
        max_speed=dims.BASE_V_MAX,
        max_turn_rate=dims.BASE_W_MAX,
        watchdog_s=session.settings.server.watchdog_s,
    )


@router.get("/state", response_model=S.Status)
def state(session: SessionDep) -> S.Status:
    return session.status_model()


@router.get(
    "/projector.png",
    response_class=Response,
    responses={200: {"content": {"image/png": {}}, "description": "The projector image."}},
)
def projector(session: SessionDep) -> Response:
    image = session.projection
    if image is None:  # nothing lit: a black image of the projector's size
        image = np.zeros((session.projector.height, session.projector.width), np.uint8)
    return Response(encode_png(image), media_type="image/png")


@router.get(
    "/cloud",
    response_class=Response,
    responses={
        200: {
            "content": {"application/octet-stream": {}},
            "description": f"The fused cloud, voxel-thinned: {CLOUD_FORMAT}.",
        },
        **NO_FRAMES,
    },
)
def cloud(
    session: SessionDep,
    voxel: Annotated[float | None, Query(gt=0.002, le=0.2, allow_inf_nan=False)] = None,
) -> Response:
    try:
        fused = session.cloud()
    except CamerasUnavailable as exc:
        raise cameras_down(exc) from None
    thinned = voxel_downsample(fused, voxel or session.settings.server.cloud_voxel)
    return Response(encode_cloud(thinned.points), media_type="application/octet-stream")


@router.get("/journal", responses={200: {"content": {"application/json": {}, "text/csv": {}}}})
def journal(
    session: SessionDep,
    format: Literal["json", "csv"] = "json",
    since_id: Annotated[int, Query(ge=0, le=2**62)] = 0,
    limit: Annotated[int, Query(ge=1, le=100_000)] = 10_000,
) -> Response:
    j = session.journal
    if j is None:
        raise HTTPException(404, "this server keeps no journal")
    if format == "csv":
        text = j.export_csv(since_id=since_id, limit=limit)
        return PlainTextResponse(text, media_type="text/csv")
    text = j.export_json(since_id=since_id, limit=limit)
    return Response(text, media_type="application/json")


@router.get("/diagnostics", response_model=S.Diagnostics)
def diagnostics(
    request: Request,
    session: SessionDep,
    window: Annotated[float | None, Query(gt=0, le=600, allow_inf_nan=False)] = None,
) -> S.Diagnostics:
    """The process's memory, the robot's real-time factor and the event loop's lag over the
    last `window` seconds (all that is kept, up to 10 minutes, when absent)."""
    return S.Diagnostics(
        uptime_s=round(time.monotonic() - _STARTED, 1),
        rss_mb=round(_rss_bytes() / 2**20, 1),
        rtf=round(session.robot.state().rtf, 3),
        loop_lag=S.LoopLagStats(**request.app.state.loop_lag.stats(window)),
        gc=S.GcStats(**request.app.state.gc_pauses.stats(window)),
    )


def _rss_bytes() -> int:
    """Resident memory now (Linux's /proc), else the peak that `getrusage` keeps."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * resource.getpagesize()
    except OSError:
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
