"""Request ids, structured JSON logs and Prometheus metrics.

* Every request gets an id: the client's ``X-Request-ID`` when it is sane
  (1–128 characters of ``[A-Za-z0-9._:-]``), otherwise a fresh one of 32 hex digits. It is
  echoed in the ``X-Request-ID`` response header and carried by every log line
  written while the request is handled.
  The service's ASGI layer (:class:`~.gate.RequestGate`) gives the ids, writes the access log and counts the
  HTTP metrics; this module holds what they are.
* One JSON access-log line per request on the ``service.access`` logger:
  method, path, route template, status, duration, request id.
* Metrics at ``/metrics`` (prometheus-client): request counts and latency by
  route template, IK solve time by solver method and structure, solutions per
  IK target.

Several uvicorn workers: each worker is a process with its own counters. When
``PROMETHEUS_MULTIPROC_DIR`` is set (``python -m service`` sets it to a fresh
temporary directory whenever ``KIN_WORKERS`` > 1), prometheus-client's
multiprocess mode is used: every worker writes its samples to that directory,
and ``/metrics``, whichever worker answers, aggregates all of them. Only
counters and histograms are used, which aggregate correctly across processes.
"""

from __future__ import annotations

import json
import logging
import os
import re
import sys
from contextvars import ContextVar
from datetime import datetime, timezone

import orjson
from fastapi import APIRouter
from fastapi.responses import Response
from prometheus_client import CONTENT_TYPE_LATEST, REGISTRY, CollectorRegistry, Counter, Histogram, generate_latest
from prometheus_client import multiprocess

REQUEST_ID_HEADER = "X-Request-ID"
#: Where the request id is kept in the ASGI scope, for handlers that run outside the middleware (the 500 handler).
REQUEST_ID_SCOPE_KEY = "kin.request_id"
_SANE_REQUEST_ID = re.compile(r"^[A-Za-z0-9._:-]{1,128}$")
UNMATCHED_ROUTE = "unmatched"

request_id_var: ContextVar[str | None] = ContextVar("request_id", default=None)

access_logger = logging.getLogger("service.access")

# --------------------------------------------------------------------------- metrics

_LATENCY_BUCKETS = (0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1.0, 2.5, 5.0, 10.0)

HTTP_REQUESTS = Counter("kin_http_requests", "HTTP requests by method, route template and status code",
                        ["method", "route", "status"])
HTTP_LATENCY = Histogram("kin_http_request_duration_seconds", "HTTP request latency by method and route template",
                         ["method", "route"], buckets=_LATENCY_BUCKETS)
IK_SOLVE_SECONDS = Histogram("kin_ik_solve_seconds",
                             "Time of one IK solver call (all targets of a request) by method and structure",
                             ["method", "structure"], buckets=_LATENCY_BUCKETS)
IK_SOLUTIONS = Histogram("kin_ik_solutions", "Solutions returned per IK target, by solver structure",
                         ["structure"], buckets=(0, 1, 2, 4, 8, 16, 32, 64, 128, 512, 1024))


def observe_ik(method: str, structure: str, seconds: float, solutions_per_target: list[int]) -> None:
    """Record one solver call: its duration, and how many solutions each of its targets got."""
    IK_SOLVE_SECONDS.labels(method, structure).observe(seconds)
    histogram = IK_SOLUTIONS.labels(structure)
    for count in solutions_per_target:
        histogram.observe(count)


def metrics_registry() -> CollectorRegistry:
    """The registry to expose: every worker's samples in multiprocess mode, else this process's."""
    if os.environ.get("PROMETHEUS_MULTIPROC_DIR"):
        registry = CollectorRegistry()
        multiprocess.MultiProcessCollector(registry)
        return registry
    return REGISTRY


metrics_router = APIRouter()


@metrics_router.get("/metrics", include_in_schema=False)
def metrics() -> Response:
    """Prometheus text exposition (never behind the API key)."""
    return Response(generate_latest(metrics_registry()), media_type=CONTENT_TYPE_LATEST)


# --------------------------------------------------------------------------- logs


class JsonFormatter(logging.Formatter):
    """One JSON object per line: ts, level, logger, msg, request_id (when in a request), and ``fields``."""

    def format(self, record: logging.LogRecord) -> str:
        entry: dict[str, object] = {
            "ts": datetime.fromtimestamp(record.created, timezone.utc).isoformat(timespec="milliseconds"),
            "level": record.levelname.lower(),
            "logger": record.name,
            "msg": record.getMessage(),
        }
        request_id = getattr(record, "request_id", None) or request_id_var.get()
        if request_id:
            entry["request_id"] = request_id
        fields = getattr(record, "fields", None)
        if isinstance(fields, dict):
            entry.update(fields)
        if record.exc_info:
            entry["exc"] = self.formatException(record.exc_info)
        try:  # a tenth of json.dumps's time, a line per request; NaN and infinities written as null (valid JSON)
            return orjson.dumps(entry, default=str, option=orjson.OPT_NON_STR_KEYS).decode()
        except TypeError:  # what orjson refuses (an integer beyond 64 bits): the standard encoder, as before
            return json.dumps(entry, default=str, ensure_ascii=False)


class _StdoutHandler(logging.StreamHandler):
    """Writes to the current ``sys.stdout`` (resolved per record, so redirected or captured output still works)."""

    def emit(self, record: logging.LogRecord) -> None:
        self.stream = sys.stdout
        super().emit(record)


def configure_logging(level: str) -> int:
    """Send the ``service`` loggers to stdout as JSON lines (one handler per process) at ``level``.

    The level is the process's: the caller that sets it while it serves (the app's lifespan) gives the returned
    previous level back to ``restore_log_level`` when it stops, so that an app started and stopped in the same
    process (tests) leaves the loggers of another app as it found them.
    """
    logger = logging.getLogger("service")
    if not any(isinstance(handler, _StdoutHandler) for handler in logger.handlers):
        handler = _StdoutHandler()
        handler.setFormatter(JsonFormatter())
        logger.addHandler(handler)
    previous = logger.level
    logger.setLevel(logging.DEBUG if level == "trace" else level.upper())
    logger.propagate = False
    return previous


def restore_log_level(previous: int) -> None:
    logging.getLogger("service").setLevel(previous)


# --------------------------------------------------------------------------- request ids (the gate gives them)


def sane_request_id(value: str | None) -> str | None:
    return value if value is not None and _SANE_REQUEST_ID.match(value) else None
