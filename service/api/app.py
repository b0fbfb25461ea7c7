"""The FastAPI application factory."""

from __future__ import annotations

import logging
from contextlib import asynccontextmanager
from typing import AsyncIterator

from fastapi import FastAPI
from fastapi.routing import APIRoute

from .. import __version__
from ..catalogue import load_catalogue
from ..config import Settings
from .limits import BodySizeLimit
from .problems import install_problem_handlers
from .routers import fk, health, ik, limits, robots, trajectory

logger = logging.getLogger("service")

DESCRIPTION = """\
Forward kinematics and **every** inverse-kinematics solution of serial robots, with joint limits.

* Robots come from the catalogue (`GET /v1/robots`) or inline in the request body (the `/v1/fk`, `/v1/ik`, … twins).
* Standard DH (Spong), modified DH (Craig) and Khalil–Kleinfinger tables are accepted.
* All angles are radians unless the request says `"angle_unit": "deg"`; lengths are in the robot's length unit.
* Every error is `application/problem+json` (RFC 9457) with field-level `errors`.
"""


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
        app.state.catalogue = load_catalogue(directories, max_joints=settings.max_joints)
        logger.info("catalogue loaded: %d robots from %s", len(app.state.catalogue),
                    ", ".join(str(d) for d in directories))
        yield
        app.state.catalogue = None

    app = FastAPI(
        title="Robot kinematics service",
        version=__version__,
        description=DESCRIPTION,
        lifespan=lifespan,
        generate_unique_id_function=_operation_id,
    )
    app.state.settings = settings
    app.state.catalogue = None
    install_problem_handlers(app)
    app.add_middleware(BodySizeLimit, max_body_bytes=settings.max_body_bytes)
    for module in (health, robots, fk, ik, limits, trajectory):
        app.include_router(module.router)
    return app
