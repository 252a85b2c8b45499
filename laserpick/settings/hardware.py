"""The simulated hardware: the physics loop and the depth sensors."""

from __future__ import annotations

from pydantic import BaseModel, Field

__all__ = ["SensorSettings", "SimSettings"]


class SimSettings(BaseModel):
    """The MuJoCo loop."""

    rate_hz: float = Field(500.0, gt=0, description="Physics rate (Hz); the timestep is 1/rate.")
    impratio: float = Field(
        10.0, ge=1.0, description="Friction-to-normal impedance ratio; >= 10 holds a jaw grasp."
    )
    noslip_iterations: int = Field(
        2, ge=0, description="Noslip solver passes that stop objects creeping out of a grasp."
    )
    control_rate_hz: float = Field(
        100.0, gt=0, description="Arm controller rate (Hz): IK and trajectory setpoints."
    )


class SensorSettings(BaseModel):
    """The depth sensor noise model, fitted loosely to structured-light sensors."""

    depth_noise_k: float = Field(
        1.5e-3, ge=0, description="Depth noise sigma = k * z^2 (1/m): 1.5 mm at 1 m."
    )
    edge_dropout_jump: float = Field(
        0.04, ge=0, description="Depth jump (m) between neighbours that marks an edge pixel."
    )
    edge_dropout_prob: float = Field(
        0.5, ge=0, le=1, description="Chance that an edge pixel reads no depth."
    )
    specular_dropout: float = Field(
        0.5, ge=0, le=1, description="Fraction of a specular object's pixels that read no depth."
    )
    specular_blob_px: float = Field(
        12.0,
        gt=0,
        description="Size (px) of the blobs a specular object's missing depth comes in.",
    )
    ir_noise: float = Field(
        2.0, ge=0, description="Sigma of the IR image's intensity noise (grey levels)."
    )
    laser_spot_radius_px: float = Field(
        2.5, gt=0, description="Apparent radius of a laser dot in the IR image (px)."
    )
    capture_rate_hz: float = Field(
        2.0, gt=0, description="How often the live console captures all five cameras (Hz)."
    )
    seed: int = Field(0, description="Seed of the sensor noise generator.")
