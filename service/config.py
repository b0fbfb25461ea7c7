"""Service settings, read once from the environment.

``HOST`` and ``PORT`` use the names container platforms already set; every
other setting carries the ``KIN_`` prefix (see ``../shared/api.md``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import AliasChoices, Field, SecretStr
from pydantic_settings import BaseSettings, SettingsConfigDict

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
    max_batch: int = Field(10_000, ge=1, description="most rows in one batch request")
    max_body_bytes: int = Field(32 * 1024 * 1024, ge=1024, description="largest request body accepted")
    max_joints: int = Field(32, ge=1, description="most joints a robot may have")
