"""RFC 9457 problem documents: the one place where errors become HTTP responses.

Every error the service returns is ``application/problem+json`` with ``type``,
``title``, ``status``, ``detail`` and, for field-level problems, ``errors``: a
list of ``{"loc": [...], "msg": ..., "type": ...}`` whose ``loc`` starts with
``body``, ``path``, ``query`` or ``header``.
"""

from __future__ import annotations

import logging
from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from pydantic import Field
from starlette.exceptions import HTTPException as StarletteHTTPException

from ..kinematics import KinematicsError
from ..robots._fields import field_location
from .observability import REQUEST_ID_HEADER, REQUEST_ID_SCOPE_KEY
from .schemas.common import ApiModel

logger = logging.getLogger("service.errors")

PROBLEM_MEDIA_TYPE = "application/problem+json"
PROBLEM_TYPE_BASE = "https://kinematics-service.dev/problems/"


class FieldError(ApiModel):
    """One field-level problem."""

    loc: list[str | int] = Field(description="path of the offending field, starting with body, path, query or header")
    msg: str = Field(description="what is wrong with the field")
    type: str = Field(description="machine-readable kind, e.g. missing, matrix_shape, quaternion_order")


class Problem(ApiModel):
    """An RFC 9457 problem document."""

    type: str = Field(description="URI naming the kind of problem")
    title: str = Field(description="short summary of the kind of problem")
    status: int = Field(description="the HTTP status code")
    detail: str = Field(description="what went wrong with this request, and what to send instead")
    instance: str | None = Field(None, description="the request path")
    errors: list[FieldError] | None = Field(None, description="field-level problems, each with its location")
    nearest_ids: list[str] | None = Field(
        None, description="with an unknown robot id (404): the catalogue ids nearest the one given, best first")


class ProblemError(Exception):
    """Raise from a router to answer with a problem document."""

    def __init__(self, status: int, slug: str, title: str, detail: str, errors: list[dict] | None = None,
                 headers: dict[str, str] | None = None, **extensions: object) -> None:
        super().__init__(detail)
        self.status, self.slug, self.title, self.detail, self.errors = status, slug, title, detail, errors
        self.headers = headers
        #: RFC 9457 extension members, each declared in :class:`Problem` (e.g. ``nearest_ids``)
        self.extensions = extensions


def problem_response(
    status: int, slug: str, title: str, detail: str, *, instance: str | None = None, errors: list[dict] | None = None,
    headers: dict[str, str] | None = None, extensions: dict[str, Any] | None = None,
) -> JSONResponse:
    body: dict[str, Any] = {"type": PROBLEM_TYPE_BASE + slug, "title": title, "status": status, "detail": detail}
    if instance:
        body["instance"] = instance
    if errors is not None:
        body["errors"] = errors
    body.update(extensions or {})
    return JSONResponse(body, status_code=status, media_type=PROBLEM_MEDIA_TYPE, headers=headers)


def _describe(errors: list[dict]) -> str:
    first = errors[0]
    where = ".".join(str(part) for part in first["loc"])
    more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
    return f"{where}: {first['msg']}{more}"


def _jsonable_errors(raw: list[dict]) -> list[dict]:
    return [
        {"loc": field_location(e.get("loc", ())),
         "msg": str(e.get("msg", "")),
         "type": str(e.get("type", "value_error"))}
        for e in raw
    ]


async def _validation_error(request: Request, exc: RequestValidationError) -> JSONResponse:
    errors = _jsonable_errors(list(exc.errors()))
    return problem_response(422, "validation-error", "Request is not valid", _describe(errors),
                            instance=request.url.path, errors=errors)


async def _kinematics_error(request: Request, exc: KinematicsError) -> JSONResponse:
    errors = [{"loc": list(exc.location), "msg": exc.message, "type": "value_error"}]
    return problem_response(422, "validation-error", "Request is not valid", _describe(errors),
                            instance=request.url.path, errors=errors)


async def _problem_error(request: Request, exc: ProblemError) -> JSONResponse:
    return problem_response(exc.status, exc.slug, exc.title, exc.detail, instance=request.url.path, errors=exc.errors,
                            headers=exc.headers, extensions=exc.extensions)


_HTTP_TITLES = {404: ("not-found", "Not found"), 405: ("method-not-allowed", "Method not allowed"),
                413: ("payload-too-large", "Request body too large"), 401: ("unauthorized", "Unauthorized")}


async def _http_error(request: Request, exc: StarletteHTTPException) -> JSONResponse:
    if exc.status_code == 400:
        # FastAPI answers 400 when it cannot decode the body at all (e.g. bytes that are not UTF-8); the contract
        # says a malformed body is 422, with the body as the offending field.
        errors = [{"loc": ["body"], "msg": "the body is not valid JSON text", "type": "json_invalid"}]
        return problem_response(422, "validation-error", "Request is not valid", _describe(errors),
                                instance=request.url.path, errors=errors)
    slug, title = _HTTP_TITLES.get(exc.status_code, ("http-error", "HTTP error"))
    # Keep the exception's headers: a 405 must carry ``Allow`` (RFC 9110 §15.5.6).
    return problem_response(exc.status_code, slug, title, str(exc.detail), instance=request.url.path,
                            headers=getattr(exc, "headers", None))


async def _unexpected_error(request: Request, exc: Exception) -> JSONResponse:
    # Runs in Starlette's outermost middleware, after the service's ASGI layer (RequestGate) has unwound: take the
    # id from the scope, so that the log line and the response still carry it.
    request_id = request.scope.get(REQUEST_ID_SCOPE_KEY)
    logger.error("unhandled error on %s %s", request.method, request.url.path, exc_info=exc,
                 extra={"request_id": request_id})
    return problem_response(500, "internal-error", "Internal server error",
                            "The service failed to handle this request. This is a bug; please report it"
                            + (f" with the request id {request_id}." if request_id else "."),
                            instance=request.url.path,
                            headers={REQUEST_ID_HEADER: request_id} if request_id else None)


def install_problem_handlers(app: FastAPI) -> None:
    """Route every error through a problem document."""
    app.add_exception_handler(RequestValidationError, _validation_error)
    app.add_exception_handler(KinematicsError, _kinematics_error)
    app.add_exception_handler(ProblemError, _problem_error)
    app.add_exception_handler(StarletteHTTPException, _http_error)
    app.add_exception_handler(Exception, _unexpected_error)


#: OpenAPI ``responses`` entries for routes, so every error is in the spec.
def problem_responses(*statuses: int) -> dict[int | str, dict[str, Any]]:
    descriptions = {404: "Unknown robot", 413: "Body or batch too large", 422: "Invalid request",
                    401: "Missing or wrong API key", 503: "Not ready"}
    return {
        status: {"model": Problem, "description": descriptions.get(status, "Problem"),
                 "content": {PROBLEM_MEDIA_TYPE: {"schema": {"$ref": "#/components/schemas/Problem"}}}}
        for status in statuses
    }
