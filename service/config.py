"""Service settings, read once from the environment.

``HOST`` and ``PORT`` use the names container platforms already set; every
other setting carries the ``KIN_`` prefix (see ``../shared/api.md``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Literal

from pydantic import AliasChoices, Field, SecretStr, field_validator
from pydantic_settings import BaseSettings, NoDecode, SettingsConfigDict

#: The built-in catalogue: the ``robots`` directory beside the package.
BUILTIN_ROBOTS_DIR = Path(__file__).resolve().parent.parent / "robots"


class Settings(BaseSettings):
    """Configuration of one service process."""

    model_config = SettingsConfigDict(env_prefix="KIN_", extra="ignore")

    host: str = Field("127.0.0.1", validation_alias=AliasChoices("HOST", "KIN_HOST"))
    port: int = Field(8000, ge=0, le=65535, validation_alias=AliasChoices("PORT", "KIN_PORT"))
    workers: int = Field(1, ge=1, le=64, description="uvicorn worker processes")
    log_level: Literal["critical", "error", "warning", "info", "debug", "trace"] = "info"
    robots_dir: Path | None = Field(None, description="extra directory of robot files added to the built-in catalogue")
    builtin_robots_dir: Path = BUILTIN_ROBOTS_DIR
    api_key: SecretStr | None = Field(None, description="when set, /v1 requires the X-API-Key header")
    cors_origins: Annotated[list[str], NoDecode] = Field(
        default_factory=list,
        description="comma-separated origins allowed by CORS ('*' for any); CORS is off when empty")
    max_batch: int = Field(10_000, ge=1, le=1_000_000, description="most rows in one batch request")
    max_body_bytes: int = Field(32 * 1024 * 1024, ge=1024, description="largest request body accepted")
    max_joints: int = Field(32, ge=1, le=1000, description="most joints a robot may have")
    max_ik_time_ms: int = Field(
        2000, ge=1, le=600_000,
        description="cap on the numeric IK search's time per request (a batch shares it across its targets); past "
                    "it the request is refused with 503, never answered with a partial search")
    request_timeout_ms: int = Field(
        5000, ge=1, le=3_600_000,
        description="deadline for a whole request (solve, select, encode); past it: 503 with Retry-After")
    max_solutions_per_response: int = Field(
        200_000, ge=1, description="most solutions (kept plus rejected) one answer may hold, estimated before "
                                   "solving; more is refused with 413")
    max_response_bytes: int = Field(
        64 * 1024 * 1024, ge=1024, description="largest estimated answer in bytes; more is refused with 413")
    max_turns_per_joint: float = Field(
        100.0, gt=0, description="most whole turns a revolute joint's limits may span (per-request limits included)")
    max_numeric_starts: int = Field(
        20_000, ge=1, description="most numeric-search starts in one request (targets × numeric.starts)")
    max_collision_pairs: int = Field(
        10_000, ge=1, description="most shape pairs one request's collision check may compare (link shapes with "
                                  "each other and with the obstacles)")
    max_collision_checks: int = Field(
        5_000_000, ge=1, description="most pair distances one request's collision check may compute (distinct "
                                     "solutions × shape pairs; about 2 s on one core)")
    max_in_flight: int = Field(32, ge=1, le=10_000, description="most requests worked on at once; more get 503")
    timeout_keep_alive_s: float = Field(5.0, gt=0, description="idle keep-alive connections close after this")
    header_timeout_s: float = Field(10.0, gt=0, description="a connection must send its request head within this")
    body_timeout_s: float = Field(30.0, gt=0, description="a request body must arrive within this")
    max_connections: int = Field(
        900, ge=1, description="most open connections per worker (past it a 503 problem at once); keep it below "
                               "the descriptor limit")
    robot_cache_size: int = Field(
        64, ge=0, le=100_000, description="most inline robot descriptions (and robots with a request's own "
                                          "base/tool) kept built with their IK plans, least recently used "
                                          "dropped first; 0 turns the cache off")
    max_robot_file_bytes: int = Field(1024 * 1024, ge=1024, description="largest robot file the catalogue loads")

    @field_validator("cors_origins", mode="before")
    @classmethod
    def _split_origins(cls, value: object) -> object:
        if isinstance(value, str):
            return [origin.strip() for origin in value.split(",") if origin.strip()]
        return value

    @field_validator("api_key", mode="after")
    @classmethod
    def _empty_key_is_unset(cls, value: SecretStr | None) -> SecretStr | None:
        # KIN_API_KEY= (set but empty) must not turn on a key that every client trivially matches.
        return value if value is not None and value.get_secret_value() else None
