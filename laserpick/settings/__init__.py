"""The one settings object: every tunable default, named, with where it came from.

Values are read from `LASERPICK_*` environment variables; nested groups use a double
underscore, e.g. `LASERPICK_SIM__RATE_HZ=250` or `LASERPICK_SENSOR__DEPTH_NOISE_K=0.002`.
Hardware limits (joint ranges, speeds, stroke) are not settings: they are facts of the
robot and live in `laserpick.description.dims`.
"""

from __future__ import annotations

from functools import lru_cache

from pydantic import Field, SecretStr
from pydantic_settings import BaseSettings, SettingsConfigDict

from laserpick.settings.behaviours import BehaviourSettings
from laserpick.settings.grasp import GraspSettings
from laserpick.settings.hardware import SensorSettings, SimSettings
from laserpick.settings.motion import ApproachSettings, MotionSettings
from laserpick.settings.perception import PerceptionSettings
from laserpick.settings.server import ServerSettings

__all__ = [
    "ApproachSettings",
    "BehaviourSettings",
    "GraspSettings",
    "MotionSettings",
    "PerceptionSettings",
    "SensorSettings",
    "ServerSettings",
    "Settings",
    "SimSettings",
    "get_settings",
]


class Settings(BaseSettings):
    """All of laserpick's tunable defaults."""

    model_config = SettingsConfigDict(env_prefix="LASERPICK_", env_nested_delimiter="__")

    sim: SimSettings = SimSettings()
    sensor: SensorSettings = SensorSettings()
    perception: PerceptionSettings = PerceptionSettings()
    grasp: GraspSettings = GraspSettings()
    approach: ApproachSettings = ApproachSettings()
    motion: MotionSettings = MotionSettings()
    behaviour: BehaviourSettings = BehaviourSettings()
    server: ServerSettings = ServerSettings()
    operator_password: SecretStr | None = Field(
        None,
        description="Password for taking control (LASERPICK_OPERATOR_PASSWORD). Required to"
        " bind anything but the loopback interface.",
    )


@lru_cache(maxsize=1)
def get_settings() -> Settings:
    """The process-wide settings, read once from the environment."""
    return Settings()
