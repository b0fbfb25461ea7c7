"""Liveness and readiness probes (never behind the API key)."""

from __future__ import annotations

from fastapi import APIRouter, Request

from ..problems import ProblemError, problem_responses
from pydantic import Field

from ..schemas.common import ApiModel

router = APIRouter(tags=["health"])


class Health(ApiModel):
    """Liveness or readiness of the process."""

    status: str = Field(description="ok (liveness) or ready (readiness)")
    robots: int | None = Field(None, description="robots in the loaded catalogue (readiness)")


@router.get("/healthz", operation_id="liveness", response_model=Health, response_model_exclude_none=True)
def liveness() -> Health:
    """Answer 200 while the process runs."""
    return Health(status="ok")


@router.get("/readyz", operation_id="readiness", response_model=Health, responses=problem_responses(503))
def readiness(request: Request) -> Health:
    """Answer 200 once the robot catalogue is loaded, 503 before."""
    catalogue = request.app.state.catalogue
    if catalogue is None:
        raise ProblemError(503, "not-ready", "Not ready", "The robot catalogue is not loaded yet.")
    return Health(status="ready", robots=len(catalogue))
