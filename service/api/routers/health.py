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
    in_flight: int | None = Field(None, description="requests being worked on now, up to KIN_MAX_IN_FLIGHT "
                                                    "(readiness; informational: it does not change readiness)")


@router.get("/healthz", operation_id="liveness", response_model=Health, response_model_exclude_none=True)
async def liveness() -> Health:
    """Answer 200 while the process runs."""
    return Health(status="ok")


@router.get("/readyz", operation_id="readiness", response_model=Health, responses=problem_responses(503))
async def readiness(request: Request) -> Health:
    """Answer 200 while the service can serve: its robot catalogue is loaded and it is not shutting down; 503
    before the catalogue is loaded and once shutdown has begun. Load does not change readiness: with
    KIN_MAX_IN_FLIGHT requests in flight it stays 200 (in_flight says how busy it is), and each request past that
    limit is answered 503 with Retry-After by itself. A pod's readiness that followed its load would take every pod
    of a saturated fleet out of its Service at once, and clients would get connection errors instead of that 503."""
    if request.app.state.shutting_down:
        raise ProblemError(503, "not-ready", "Not ready", "The service is shutting down.")
    catalogue = request.app.state.catalogue
    if catalogue is None:
        raise ProblemError(503, "not-ready", "Not ready", "The robot catalogue is not loaded yet.")
    return Health(status="ready", robots=len(catalogue), in_flight=request.app.state.in_flight.count)
