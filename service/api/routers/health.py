"""Liveness and readiness probes (never behind the API key).

Both are ``async``: they run on the event loop, never in the thread pool the solvers use, so they answer while
every solver thread is busy.
"""

from __future__ import annotations

from fastapi import APIRouter, Request
from pydantic import Field

from ..problems import ProblemError, problem_responses
from ..schemas.common import ApiModel

router = APIRouter(tags=["health"])


class Health(ApiModel):
    """Liveness or readiness of the process."""

    status: str = Field(description="ok (liveness) or ready (readiness)")
    robots: int | None = Field(None, description="robots in the loaded catalogue (readiness)")
    in_flight: int | None = Field(None, description="requests being solved now (readiness)")


@router.get("/healthz", operation_id="liveness", response_model=Health, response_model_exclude_none=True)
async def liveness() -> Health:
    """Answer 200 while the process runs."""
    return Health(status="ok")


@router.get("/readyz", operation_id="readiness", response_model=Health, responses=problem_responses(503))
async def readiness(request: Request) -> Health:
    """Answer 200 once the robot catalogue is loaded and the service has room for work; 503 before the catalogue
    is loaded and while KIN_MAX_IN_FLIGHT requests are in flight (saturated: send traffic elsewhere)."""
    catalogue = request.app.state.catalogue
    if catalogue is None:
        raise ProblemError(503, "not-ready", "Not ready", "The robot catalogue is not loaded yet.")
    in_flight = request.app.state.in_flight
    if in_flight.saturated:
        raise ProblemError(503, "saturated", "Saturated",
                           f"{in_flight.count} requests in flight, the limit (KIN_MAX_IN_FLIGHT = "
                           f"{in_flight.capacity}).", headers={"Retry-After": "1"})
    return Health(status="ready", robots=len(catalogue), in_flight=in_flight.count)
