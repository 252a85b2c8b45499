"""The API's request and response bodies (pydantic), which are also its OpenAPI schema.

Every number is finite (NaN and infinity are refused with 422) and bounded: speeds by the
robot's limits in `laserpick.description.dims`, steps and reaches by `ServerSettings`. Units
are SI (m, rad, s); points are in `base` unless `frame` says `world`.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from laserpick.description import dims
from laserpick.settings import get_settings

_server = get_settings().server

#: Largest laser nudge per command (rad): `ServerSettings.max_nudge`, as this process read it.
MAX_NUDGE = _server.max_nudge
#: Longest a drive command lasts (s): it is a dead-man, sent again to keep going.
MAX_DRIVE_DURATION = 0.5

Finite = Annotated[float, Field(allow_inf_nan=False)]
Coordinate = Annotated[float, Field(allow_inf_nan=False, ge=-50.0, le=50.0)]
Vector3 = Annotated[list[Coordinate], Field(min_length=3, max_length=3)]
Frame = Literal["base", "world"]
Source = Literal["console", "rest", "switch", "joystick", "bench"]


class _Body(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True)  # no "1" or true for 1.0


class ControlRequest(_Body):
    """Who takes control: a name people will see, and the input source for the journal."""

    name: str = Field("rest client", min_length=1, max_length=64)
    source: Source = "rest"
    password: str | None = Field(
        None, max_length=256, description="The operator password, when the server has one."
    )


class ControlGrant(BaseModel):
    token: str = Field(description="Send as `Authorization: Bearer <token>` on every command.")
    holder: str
    lease_timeout_s: float = Field(description="The lease lapses this long after a heartbeat.")
    watchdog_s: float = Field(description="Motion halts when the controller is silent this long.")


class Ray(_Body):
    origin: Vector3
    direction: Vector3

    @model_validator(mode="after")
    def _nonzero(self) -> Ray:
        if math.hypot(*self.direction) < 1e-9:
            raise ValueError("direction must not be the zero vector")
        return self


class AimRequest(_Body):
    """Exactly one of: `yaw` and `pitch` (rad, in `base`); a `point` to aim at (m); or a
    `ray` (a click in the 3D view) whose first hit on the cloud is aimed at."""

    yaw: Annotated[float, Field(allow_inf_nan=False, ge=-math.pi, le=math.pi)] | None = None
    pitch: Annotated[float, Field(allow_inf_nan=False, ge=-math.pi / 2, le=math.pi / 2)] | None = (
        None
    )
    point: Vector3 | None = None
    ray: Ray | None = None
    frame: Frame = "base"

    @model_validator(mode="after")
    def _one_kind(self) -> AimRequest:
        angles = (self.yaw is not None) + (self.pitch is not None)
        if angles == 1:
            raise ValueError("give both yaw and pitch")
        kinds = (angles == 2) + (self.point is not None) + (self.ray is not None)
        if kinds != 1:
            raise ValueError("give exactly one of: yaw and pitch, point, ray")
        return self


class AimResult(BaseModel):
    hit: list[float] | None = Field(None, description="Where a ray met the cloud (m, base).")


class NudgeRequest(_Body):
    """Turn the laser by small steps (rad): + yaw turns left, + pitch up."""

    dyaw: Annotated[float, Field(allow_inf_nan=False, ge=-MAX_NUDGE, le=MAX_NUDGE)]
    dpitch: Annotated[float, Field(allow_inf_nan=False, ge=-MAX_NUDGE, le=MAX_NUDGE)] = 0.0


class StepRequest(_Body):
    level: Literal["cluster", "candidate"] = "cluster"


class SelectRequest(_Body):
    cluster: int = Field(ge=0, le=10_000)
    candidate: int = Field(0, ge=0, le=10_000)


class ModeRequest(_Body):
    mode: Literal["pick_and_drop", "pick_and_place"] | None = None
    selection: Literal["auto", "manual"] | None = None
    strategy: Literal["gpd", "overhead", "jeeves"] | None = None


class DriveRequest(_Body):
    """A dead-man drive command: valid for `duration` s (at most 0.5), then the base stops
    unless the command is sent again."""

    v: Annotated[float, Field(allow_inf_nan=False, ge=-dims.BASE_V_MAX, le=dims.BASE_V_MAX)]
    w: Annotated[float, Field(allow_inf_nan=False, ge=-dims.BASE_W_MAX, le=dims.BASE_W_MAX)] = 0.0
    duration: Annotated[float, Field(allow_inf_nan=False, gt=0.0, le=MAX_DRIVE_DURATION)] = (
        MAX_DRIVE_DURATION
    )
    seq: int | None = Field(
        None,
        ge=0,
        le=2**53 - 1,
        description="Optional: number the drive commands of one token in the order sent. "
        "One older than the last applied is dropped, so a stop sent on another connection "
        "is never overtaken by the drive sent before it.",
    )


class SceneRequest(_Body):
    """A built-in scene by `name`, or an uploaded scene: its YAML text, plus the mesh files
    it names as base64 (flat file names only), and an optional seed for its random rules."""

    name: str | None = Field(None, pattern=r"^[A-Za-z0-9_\-]{1,64}$")
    yaml: str | None = Field(None, min_length=1, max_length=1_000_000)
    files: dict[
        Annotated[str, Field(pattern=r"^[A-Za-z0-9_\-][A-Za-z0-9_.\-]{0,63}$")],
        Annotated[str, Field(max_length=7_000_000)],
    ] = Field(
        default_factory=dict,
        max_length=16,
        # The schema states what the model enforces: a name that does not match is refused.
        json_schema_extra={"additionalProperties": False},
    )
    seed: int | None = Field(None, ge=0, le=2**31 - 1)

    @model_validator(mode="after")
    def _one_kind(self) -> SceneRequest:
        if (self.name is None) == (self.yaml is None):
            raise ValueError("give exactly one of: name, yaml")
        if self.files and self.yaml is None:
            raise ValueError("files go with an uploaded yaml")
        return self


class Refusal(BaseModel):
    """409: the command conflicts with the current state."""

    detail: str
    state: str


class Problem(BaseModel):
    """401 or 413: why the request was refused."""

    detail: str


class Ok(BaseModel):
    ok: bool = True
    state: str
    message: str
    sim_time: float = Field(description="Robot time (s) when the command was taken.")


class LeaseStatus(BaseModel):
    held: bool
    holder: str | None
    source: str | None


class GripperStatus(BaseModel):
    width: float = Field(description="Opening between the pads (m).")
    force: float = Field(description="Summed pad force (N).")
    closed: bool
    holding: bool


class LaserStatus(BaseModel):
    on: bool
    confirmed: bool
    yaw: float
    pitch: float


class JointStatus(BaseModel):
    q: list[float] = Field(description="UR5 joint angles (rad).")
    qd: list[float] = Field(description="Joint velocities (rad/s).")


class TargetStatus(BaseModel):
    points: int
    centroid: list[float]


class GraspsStatus(BaseModel):
    clusters: int
    sizes: list[int]
    cluster: int = Field(description="Current cluster (0-based).")
    candidate: int = Field(description="Current candidate in the cluster (0-based).")
    describe: str


class GraspStatus(BaseModel):
    pose: list[list[float]] = Field(description="4x4 TCP pose in base.")
    position: list[float]
    approach: list[float]
    width: float
    score: float
    factors: dict[str, float] | None = Field(description="Cw, Cj, Ca, Cs, Cp (004 eq. 3-7).")
    cluster: int
    pads_centred: bool = Field(
        description="Whether its pads meet the object along their face about their middle;"
        " such grasps are offered first."
    )


class FailureStatus(BaseModel):
    kind: str
    message: str
    #: How far (m) to back the scooter up, straight, for the arm to do it; null when the
    #: robot has no such advice.
    back_up: float | None = None
    #: How far (m) to park the scooter to its left (negative: right) for the cameras to see
    #: the way the arm needs; null when the robot has no such advice.
    park_left: float | None = None


class Status(BaseModel):
    """The session's state: what a console shows. Points in `base` (m), angles (rad)."""

    state: str
    busy: bool
    job: str | None
    message: str
    mode: str
    selection: str
    strategy: str
    estopped: bool
    drive_stop: str | None = Field(
        description="Why the scooter stopped itself while driving (it pushed the still arm "
        "into something) or was halted (the dead-man: its controller went silent), until it "
        "drives freely again."
    )
    sim_time: float
    rtf: float
    read_at: float = Field(
        description="Wall-clock time (s since the epoch) of the robot reading in this status."
    )
    joints: JointStatus
    base_pose: list[float] = Field(description="Scooter x, y (m) and yaw (rad) in world.")
    gripper: GripperStatus
    laser: LaserStatus
    mark: list[float] | None
    place_mark: list[float] | None
    target: TargetStatus | None
    grasps: GraspsStatus | None
    current: GraspStatus | None
    timings: dict[str, float] = Field(description="Seconds per pipeline stage.")
    failure: FailureStatus | None
    lease: LeaseStatus


class SimObject(BaseModel):
    """Simulator ground truth about one object: for scoring and scripted operators only."""

    name: str
    model: str
    position_world: list[float] = Field(description="Body origin in world (m).")
    quat_world: list[float] = Field(description="Orientation (w, x, y, z) in world.")
    center_base: list[float] = Field(description="Centre of its bounds in base (m).")
    top_base: float = Field(description="Height of its top in base (m).")
    in_basket: bool
    upright: float = Field(description="cos of its tilt from upright: 1 upright, 0 lying.")


class Health(BaseModel):
    status: Literal["ok"]
    version: str
    scene: str
    viser_port: int | None
    viser_url: str | None = Field(
        description="Where the page finds the 3D view when it is not at viser_port on the"
        " page's host (behind the TLS proxy: /viser/)."
    )
    rtf: float
    max_nudge: float = Field(description="Largest laser nudge per command (rad).")
    max_drive_duration: float = Field(
        description="Longest a drive command lasts (s): send it again sooner to keep going."
    )
    max_speed: float = Field(description="Largest forward or backward drive speed (m/s).")
    max_turn_rate: float = Field(description="Largest drive turn rate (rad/s).")
    watchdog_s: float = Field(
        description="Motion halts when the controller is silent this long (s)."
    )


class LoopLagStats(BaseModel):
    samples: int = Field(description="Wake-ups of the event loop's probe in the window.")
    p50_ms: float
    p99_ms: float
    max_ms: float


class GcStats(BaseModel):
    collections: int = Field(description="Garbage collections in the window.")
    full_collections: int = Field(description="Of them, of the oldest generation.")
    longest_ms: float = Field(description="The longest: every thread waits while one runs.")


class Diagnostics(BaseModel):
    """How the server process itself is doing: what the soak and the lag bench read."""

    uptime_s: float
    rss_mb: float = Field(description="The server process's resident memory (MB).")
    rtf: float = Field(description="The robot's real-time factor (1 for hardware).")
    loop_lag: LoopLagStats = Field(
        description="How late the API's event loop woke (ms) over the asked window: while it"
        " is late no socket is read, so no heartbeat arrives."
    )
    gc: GcStats = Field(description="Python's garbage collections over the same window.")
