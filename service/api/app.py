"""The FastAPI application factory."""

from __future__ import annotations

import gc
import logging
from contextlib import asynccontextmanager
from typing import AsyncIterator

from typing import Any

from fastapi import FastAPI
from fastapi.routing import APIRoute

from .. import __version__
from ..robots.catalogue import load_catalogue
from ..config import Settings
from ..kinematics import BudgetExhausted
from .budget import InFlight, budget_exhausted
from .gate import RequestGate
from .robot_cache import RobotCache
from .observability import configure_logging, metrics_router, restore_log_level
from .examples import add_examples
from .pages import install_pages
from .problems import PROBLEM_MEDIA_TYPE, Problem, install_problem_handlers
from .routers import fk, health, ik, limits, render, robots, trajectory
from .security import API_KEY_HEADER, API_KEY_SCHEME, is_protected

logger = logging.getLogger("service")

DESCRIPTION = """\
Forward kinematics and **every** inverse-kinematics solution of serial robots, with joint limits.

* Robots come from the catalogue (`GET /v1/robots`) or inline in the request body (the `/v1/fk`, `/v1/ik`, … twins).
* Standard DH (Spong), modified DH (Craig) and Khalil–Kleinfinger tables are accepted.
* All angles are radians unless the request says `"angle_unit": "deg"`; lengths are in the robot's length unit.
* Every error is `application/problem+json` (RFC 9457) with field-level `errors`.
* Every number in a request must be finite and within ±1e6 (see docs/api-guide.md, "Limits of input").
* When the service runs with `KIN_API_KEY`, every `/v1` operation needs the `X-API-Key` header.
* Bounded work: every `POST /v1/...` request has a deadline (`KIN_REQUEST_TIMEOUT_MS`; the header
  `X-Request-Timeout-Ms` may lower it) and stops when its client disconnects. Past the deadline it is answered
  503 with `Retry-After`; more than `KIN_MAX_IN_FLIGHT` requests at once get the same. An answer that could hold
  more than `KIN_MAX_SOLUTIONS_PER_RESPONSE` solutions (targets × solutions × 2π-equivalents, estimated before
  solving) or `KIN_MAX_RESPONSE_BYTES` is refused with 413, naming the cap and by how much.
"""

_PROBLEM_DESCRIPTIONS = {401: "Missing or wrong API key (only when the service runs with KIN_API_KEY)",
                         404: "Unknown robot", 413: "Body, batch or answer too large", 422: "Invalid request",
                         503: "Not ready, too many requests in flight (KIN_MAX_IN_FLIGHT), or past the request "
                              "deadline (KIN_REQUEST_TIMEOUT_MS); retry after Retry-After seconds"}


#: The collector's thresholds (young, middle, full): a young pass after 5,000 net allocations instead of 700, a middle
#: one after 4 young ones instead of 10 (it walks at most about 25,000 objects; 7,700 before), a full one only after
#: 100 middle ones instead of 10 (see :func:`_tune_collector`).
COLLECTOR_THRESHOLDS = (5000, 4, 100)


def _tune_collector() -> None:
    """Keep the cyclic garbage collector's pauses short: each pass holds the GIL, stalling every thread, the
    server's loop and ``/healthz`` included.

    * What start-up built (modules, the catalogue) lives as long as the process: frozen, it is skipped by every
      pass. Left in, each full pass walked those ~90,000 objects for ~80 ms.
    * A large answer is built as hundreds of thousands of objects that live only until it is encoded, and its
      growth triggered a full pass every few milliseconds of building (each 40–100 ms, in the soak, collecting
      nothing: this service makes almost no reference cycles). Full passes now wait for 100 middle ones.
    * A single answer of hundreds of solutions (a UR5 pose under ±2π limits) is a few thousand dicts and lists that
      go once it is encoded: at the interpreter's young threshold (700) about two young passes a request walked
      them (~100 µs of a 1.4 ms request); young passes now wait for 5,000 net allocations, which such a request
      does not reach. Middle passes come after 4 young ones: in a 10,000-target answer of the objects form the
      longest young or middle pass took 3.9 ms (2.3 ms before), and the passes 40 of its 580 ms (36 before).
    """
    gc.collect()
    gc.freeze()
    gc.set_threshold(*COLLECTOR_THRESHOLDS)


def _operation_id(route: APIRoute) -> str:
    """Stable operationIds: the one written on the route, never a generated one."""
    return route.operation_id or route.name


def create_app(settings: Settings | None = None) -> FastAPI:
    """Build the application. The catalogue is loaded at start-up (lifespan)."""
    settings = settings or Settings()

    @asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        directories = [settings.builtin_robots_dir]
        if settings.robots_dir is not None:
            directories.append(settings.robots_dir)
        app.state.shutting_down = False
        log_level_before = configure_logging(settings.log_level)  # the process's level while this app serves
        app.state.catalogue = load_catalogue(directories, max_joints=settings.max_joints,
                                             max_file_bytes=settings.max_robot_file_bytes)
        logger.info("catalogue loaded: %d robots from %s", len(app.state.catalogue),
                    ", ".join(str(d) for d in directories))
        thresholds = gc.get_threshold()
        _tune_collector()
        yield
        app.state.shutting_down = True  # /readyz: 503 from here on (the catalogue is dropped below)
        gc.unfreeze()  # an application started again in this process (tests) must not pile frozen objects up
        gc.set_threshold(*thresholds)
        restore_log_level(log_level_before)
        app.state.catalogue = None

    app = FastAPI(
        title="Robot kinematics service",
        version=__version__,
        description=DESCRIPTION,
        lifespan=lifespan,
        generate_unique_id_function=_operation_id,
        # /docs and /redoc are served offline by install_pages (below), not from a CDN
        docs_url=None,
        redoc_url=None,
    )
    app.state.settings = settings
    app.state.catalogue = None
    app.state.shutting_down = False
    app.state.in_flight = InFlight(settings.max_in_flight)
    app.state.inline_robots = RobotCache("inline", settings.robot_cache_size)
    install_problem_handlers(app)
    app.add_exception_handler(BudgetExhausted, budget_exhausted)
    # One ASGI layer in front of the routes: request id + access log + metrics → CORS (when configured; answers
    # preflights itself) → API key (when configured) → body size → work limits (deadline, cancellation, in-flight).
    app.add_middleware(RequestGate, settings=settings, in_flight=app.state.in_flight)
    for module in _MATCHING_ORDER:
        app.include_router(module.router)
    app.include_router(metrics_router)

    # --- pages for people (issue 15): pictures, landing page, offline docs, viewer ----------------------------
    app.include_router(render.router)
    install_pages(app)
    # ------------------------------------------------------------------------------------------------------------

    def openapi() -> dict[str, Any]:
        if app.openapi_schema is None:
            _document_problems_and_security(_in_documented_order(FastAPI.openapi(app)))
            add_examples(app.openapi_schema)  # issue 15: examples from the catalogue (service/api/examples.py)
        return app.openapi_schema

    app.openapi = openapi  # type: ignore[method-assign]
    return app


#: The routers as the document lists them: health first, then the catalogue, FK, IK, limits and trajectories.
_DOCUMENTED_ORDER = (health, robots, fk, ik, limits, trajectory)
#: The order FastAPI tries them in (it matches the included routers one after another, each route by its pattern):
#: the routes most requests take first. No two routers' paths overlap, so the order changes no match.
_MATCHING_ORDER = (health, fk, ik, robots, limits, trajectory)


def _in_documented_order(spec: dict[str, Any]) -> dict[str, Any]:
    """The document's paths in :data:`_DOCUMENTED_ORDER` (FastAPI lists them in matching order), the others after."""
    rank = {route.path: index for index, route in enumerate(
        route for module in _DOCUMENTED_ORDER for route in module.router.routes)}
    spec["paths"] = dict(sorted(spec["paths"].items(), key=lambda item: rank.get(item[0], len(rank))))
    return spec


def _problem(status: int) -> dict[str, Any]:
    return {"description": _PROBLEM_DESCRIPTIONS.get(status, "Problem"),
            "content": {PROBLEM_MEDIA_TYPE: {"schema": {"$ref": "#/components/schemas/Problem"}}}}


def _document_problems_and_security(spec: dict[str, Any]) -> None:
    """Declare every error an operation can answer, as problem+json only, and the API-key scheme.

    Done on the finished document so that it covers every router, including ones added later:
    401 on every ``/v1`` operation, 413 and 422 wherever there is a body, 422 wherever there are
    parameters, 404 wherever a robot id is in the path, and 503 on the catalogue's operations.
    """
    components = spec.setdefault("components", {})
    schemas = components.setdefault("schemas", {})
    if "Problem" not in schemas:
        problem_schema = Problem.model_json_schema(ref_template="#/components/schemas/{model}")
        schemas.update(problem_schema.pop("$defs", {}))
        schemas["Problem"] = problem_schema
    components["securitySchemes"] = {API_KEY_SCHEME: {
        "type": "apiKey", "in": "header", "name": API_KEY_HEADER,
        "description": "Required on /v1 only when the service runs with KIN_API_KEY; compared in constant time."}}
    # The key is optional (the empty requirement {}), and declared once for the document rather than on each
    # operation: generated clients (openapi-python-client) then accept a plain Client on every operation, which
    # is all a service without KIN_API_KEY needs, instead of demanding an AuthenticatedClient that sends
    # "Authorization: Bearer". With a key: Client(headers={"X-API-Key": key}). Open routes opt out with [].
    spec["security"] = [{API_KEY_SCHEME: []}, {}]
    for path, operations in spec.get("paths", {}).items():
        for operation in operations.values():
            statuses: set[int] = set()
            if is_protected(path):
                statuses.add(401)
            else:
                operation["security"] = []
            if "requestBody" in operation:
                statuses |= {413, 422}
            if operation.get("parameters"):
                statuses.add(422)
            if "{robot_id}" in path:
                statuses.add(404)
            if path.startswith("/v1/robots") or "requestBody" in operation:
                statuses.add(503)
            responses = operation.setdefault("responses", {})
            for status in statuses:
                responses.setdefault(str(status), _problem(status))
            for status, response in responses.items():
                if status[0] in "45":
                    # Errors are application/problem+json only (FastAPI also lists application/json for a model).
                    response["content"] = _problem(int(status))["content"]
            operation["responses"] = dict(sorted(responses.items()))
