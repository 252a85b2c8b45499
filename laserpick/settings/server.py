"""The operator session and its API: safety timings and input limits."""

from __future__ import annotations

from pydantic import BaseModel, Field

__all__ = ["ServerSettings"]


class ServerSettings(BaseModel):
    """The operator session and its API (safety timings, input limits)."""

    lease_timeout_s: float = Field(
        5.0, gt=0, description="The control lease lapses after this long without a heartbeat (s)."
    )
    watchdog_s: float = Field(
        0.5,
        gt=0,
        le=2.0,
        description="Arm or base motion halts when the controller is silent this long (s).",
    )
    events_hz: float = Field(
        30.0, ge=1.0, le=100.0, description="State frames per second on the events websocket."
    )
    max_body_bytes: int = Field(
        8_000_000, gt=0, description="Largest request body (bytes): a scene with its meshes."
    )
    max_nudge: float = Field(
        0.2, gt=0, description="Largest laser nudge per command (rad), about 11 degrees."
    )
    max_reach: float = Field(
        5.0, gt=0, description="Aim points farther than this from `base`'s origin are refused (m)."
    )
    cloud_voxel: float = Field(
        0.01, gt=0, description="Voxel (m) the cloud is thinned to for GET /cloud."
    )
    seed: int = Field(0, description="Seed of the session's random draws (planner, sampling).")
