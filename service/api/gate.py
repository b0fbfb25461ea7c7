"""The service's one ASGI layer in front of the routes: what every request passes before (and after) its handler.

In a request's order:

1. **Request id, access log, metrics** (every HTTP request). The id is the client's ``X-Request-ID`` when it is
   sane (:func:`~.observability.sane_request_id`), else a fresh one of 32 hex digits; it is echoed in the
   response's ``X-Request-ID``, kept in the scope (:data:`~.observability.REQUEST_ID_SCOPE_KEY`) and in a context
   variable that every log line of the request reads. At the end: one access-log line and the HTTP metrics.
2. **CORS** (only when ``KIN_CORS_ORIGINS`` is set): Starlette's middleware, which answers preflights itself, so a
   preflight needs no API key.
3. **API key** (only when ``KIN_API_KEY`` is set): a ``/v1`` request without the right ``X-API-Key`` gets 401 before
   its body is read. The key is compared with :func:`hmac.compare_digest`, on bytes.
4. **Body size**: a declared ``Content-Length`` over ``KIN_MAX_BODY_BYTES`` is refused (413) before any byte is
   read; a chunked body is counted as it streams and refused as soon as it passes the limit.
5. **Work limits** (``POST /v1/...``): a budget with the request's deadline (``KIN_REQUEST_TIMEOUT_MS``, lowered by
   ``X-Request-Timeout-Ms``), cancelled when the client disconnects; past ``KIN_MAX_IN_FLIGHT`` requests at once,
   503 with ``Retry-After``.

One layer instead of five: each of Starlette's middleware is a coroutine call, a ``receive``/``send`` wrapper and a
scan of the headers, per request. The disconnect watcher (5.) starts only when the request first lets the loop run
(it waits for a work loop): a request answered where it arrived, as small FK and IK are, cannot be cancelled
half-way and needs none.
"""

from __future__ import annotations

import asyncio
import itertools
import json
import logging
import math
import os
import time
from typing import Any

from starlette.exceptions import HTTPException
from starlette.middleware.cors import CORSMiddleware
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from ..config import Settings
from ..kinematics import Budget
from .budget import BUDGET_STATE_KEY, RETRY_AFTER_SECONDS, TIMEOUT_HEADER, InFlight
from .observability import (HTTP_LATENCY, HTTP_REQUESTS, REQUEST_ID_HEADER, REQUEST_ID_SCOPE_KEY, UNMATCHED_ROUTE,
                            access_logger, request_id_var, sane_request_id)
from .problems import PROBLEM_MEDIA_TYPE, PROBLEM_TYPE_BASE
from .routing import CORE_TURNS
from .security import API_KEY_HEADER, ApiKeyCheck, is_protected

logger = logging.getLogger("service.budget")

_REQUEST_ID = REQUEST_ID_HEADER.lower().encode()
_API_KEY = API_KEY_HEADER.lower().encode()
_TIMEOUT = TIMEOUT_HEADER.lower().encode()
_WWW_AUTHENTICATE = f'ApiKey header="{API_KEY_HEADER}"'.encode()


class _RequestIds:
    """Fresh request ids: 32 hex digits, a random prefix of this process and a count. Unique across the workers
    (each draws its prefix; a forked child draws again) at the cost of a string format, not a call for random
    bytes per request as :func:`uuid.uuid4` makes."""

    def __init__(self) -> None:
        self._draw()
        os.register_at_fork(after_in_child=self._draw)

    def _draw(self) -> None:
        self._prefix = os.urandom(8).hex()
        self._count = itertools.count(int.from_bytes(os.urandom(4), "big"))

    def next(self) -> str:
        return f"{self._prefix}{next(self._count) & 0xFFFF_FFFF_FFFF_FFFF:016x}"


_request_ids = _RequestIds()


class RequestGate:
    """Request id, access log and metrics, CORS, the API key, the body size and the work limits, as one ASGI layer
    (see the module docstring)."""

    def __init__(self, app: ASGIApp, settings: Settings, in_flight: InFlight) -> None:
        self.app = app
        self.in_flight = in_flight
        self.timeout_seconds = settings.request_timeout_ms / 1000.0
        self.max_body_bytes = settings.max_body_bytes
        self.api_key = None if settings.api_key is None else ApiKeyCheck(settings.api_key.get_secret_value())
        self._past_cors: ASGIApp = self._guarded
        if settings.cors_origins:
            self._past_cors = CORSMiddleware(
                self._guarded, allow_origins=settings.cors_origins, allow_methods=["GET", "POST"],
                allow_headers=["Content-Type", API_KEY_HEADER, REQUEST_ID_HEADER, TIMEOUT_HEADER],
                expose_headers=[REQUEST_ID_HEADER], max_age=600)
        #: the metrics' children by their labels: ``labels()`` takes a lock and checks its arguments each call
        self._counters: dict[tuple[str, str, int], Any] = {}
        self._latencies: dict[tuple[str, str], Any] = {}

    # ------------------------------------------------------------------ 1. request id, access log, metrics

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        incoming = None
        for name, value in scope.get("headers", ()):
            if name == _REQUEST_ID:
                incoming = value.decode("latin-1")
                break
        request_id = sane_request_id(incoming) or _request_ids.next()
        scope[REQUEST_ID_SCOPE_KEY] = request_id
        id_header = (_REQUEST_ID, request_id.encode("latin-1"))
        token = request_id_var.set(request_id)
        status = 500  # unless a response starts: an exception escaped and the server error handler answers
        started = time.perf_counter()

        async def send_with_id(message: Message) -> None:
            nonlocal status
            if message["type"] == "http.response.start":
                status = message["status"]
                message["headers"] = [*message.get("headers", ()), id_header]
            await send(message)

        try:
            await self._past_cors(scope, receive, send_with_id)
        finally:
            duration = time.perf_counter() - started
            self._observe(scope, status, duration)
            request_id_var.reset(token)

    def _observe(self, scope: Scope, status: int, duration: float) -> None:
        route = getattr(scope.get("route"), "path", None) or UNMATCHED_ROUTE
        method = scope.get("method", "")
        counter = self._counters.get((method, route, status))
        if counter is None:
            counter = self._counters[method, route, status] = HTTP_REQUESTS.labels(method, route, str(status))
        latency = self._latencies.get((method, route))
        if latency is None:
            latency = self._latencies[method, route] = HTTP_LATENCY.labels(method, route)
        counter.inc()
        latency.observe(duration)
        if access_logger.isEnabledFor(logging.INFO):
            client, path = scope.get("client"), scope.get("path", "")
            access_logger.info("%s %s %d", method, path, status, extra={"fields": {
                "method": method, "path": path, "route": route, "status": status,
                "duration_ms": round(duration * 1000.0, 3), "client": client[0] if client else None}})

    # ------------------------------------------------------------------ 3.–5. API key, body size, work limits

    async def _guarded(self, scope: Scope, receive: Receive, send: Send) -> None:
        path = scope.get("path", "")
        provided = b""
        declared: bytes | None = None
        timeouts: list[bytes] = []
        for name, value in scope.get("headers", ()):
            if name == b"content-length":
                declared = value
            elif name == _API_KEY:
                provided = provided or value
            elif name == _TIMEOUT:
                timeouts.append(value)
        if self.api_key is not None and is_protected(path):
            refusal = self.api_key.refusal(provided)
            if refusal is not None:
                await _send_problem(send, 401, "unauthorized", "Unauthorized", refusal, scope,
                                    headers=[(b"www-authenticate", _WWW_AUTHENTICATE)])
                return
        if declared is not None and _length(declared) > self.max_body_bytes:
            await self._refuse_body(scope, send)
            return
        if scope.get("method") == "POST" and path.startswith("/v1/"):
            await self._within_limits(scope, receive, send, timeouts)
        else:
            await self._counted(scope, receive, send)

    async def _counted(self, scope: Scope, receive: Receive, send: Send) -> None:
        """The app, with the body counted as it arrives (a chunked body declares no length)."""
        received = 0
        response_started = False

        async def counting_receive() -> Message:
            nonlocal received
            message = await receive()
            if message["type"] == "http.request":
                received += len(message.get("body", b""))
                if received > self.max_body_bytes:
                    raise _BodyTooLarge(413, self._body_detail())
            return message

        async def tracking_send(message: Message) -> None:
            nonlocal response_started
            if message["type"] == "http.response.start":
                response_started = True
            await send(message)

        try:
            await self.app(scope, counting_receive, tracking_send)
        except _BodyTooLarge:
            if not response_started:
                await self._refuse_body(scope, send)

    async def _within_limits(self, scope: Scope, receive: Receive, send: Send, timeouts: list[bytes]) -> None:
        timeout = self.timeout_seconds
        for value in timeouts:
            try:
                asked = float(value)
            except ValueError:
                asked = math.nan
            if not (asked > 0 and math.isfinite(asked)):
                await _send_problem(send, 422, "validation-error", "Request is not valid",
                                    f"{TIMEOUT_HEADER} must be a positive number of milliseconds.", scope,
                                    errors=[{"loc": ["header", TIMEOUT_HEADER], "msg": "must be a positive number",
                                             "type": "value_error"}])
                return
            timeout = min(timeout, asked / 1000.0)  # a request may lower its deadline, never raise it
        if self.in_flight.saturated:
            logger.warning("refused: %d requests in flight (KIN_MAX_IN_FLIGHT)", self.in_flight.count,
                           extra={"fields": {"path": scope.get("path"), "in_flight": self.in_flight.count}})
            await _send_problem(send, 503, "overloaded", "Too many requests in flight",
                                f"The service is working on {self.in_flight.count} requests, its limit "
                                f"(KIN_MAX_IN_FLIGHT = {self.in_flight.capacity}); retry after "
                                f"{RETRY_AFTER_SECONDS} s.", scope,
                                headers=[(b"retry-after", str(RETRY_AFTER_SECONDS).encode())])
            return
        budget = Budget(timeout, between_chunks=CORE_TURNS.pass_on)
        scope.setdefault("state", {})[BUDGET_STATE_KEY] = budget
        watch = _DisconnectWatch(receive, budget, scope)
        received = 0
        response_started = False

        async def receive_watched() -> Message:
            nonlocal received
            if watch.body_done:
                return await watch.disconnect()
            message = await receive()
            if message["type"] == "http.disconnect":
                watch.disconnected_now()
            elif message["type"] == "http.request":
                received += len(message.get("body", b""))
                if received > self.max_body_bytes:
                    raise _BodyTooLarge(413, self._body_detail())
                if not message.get("more_body", False):
                    watch.body_arrived()
            return message

        async def send_tracked(message: Message) -> None:
            nonlocal response_started
            if message["type"] == "http.response.start":
                response_started = True
            elif message["type"] == "http.response.body" and not message.get("more_body", False):
                watch.response_done = True
            await send(message)

        self.in_flight.count += 1
        try:
            await self.app(scope, receive_watched, send_tracked)
        except _BodyTooLarge:
            if not response_started:
                await self._refuse_body(scope, send)
        finally:
            self.in_flight.count -= 1
            watch.stop()

    async def _refuse_body(self, scope: Scope, send: Send) -> None:
        await _send_problem(send, 413, "payload-too-large", "Request body too large", self._body_detail(), scope)

    def _body_detail(self) -> str:
        return f"The request body is larger than {self.max_body_bytes} bytes (KIN_MAX_BODY_BYTES)."


class _DisconnectWatch:
    """Cancels a request's budget when its client disconnects.

    After the body, the server's ``receive()`` returns only when the client goes or the response is done, so a task
    waits on it. That task starts at the loop's next turn after the body arrived: a request answered before it lets
    the loop run (small work, where it arrives) never starts one.
    """

    def __init__(self, receive: Receive, budget: Budget, scope: Scope) -> None:
        self._receive, self._budget, self._scope = receive, budget, scope
        self.body_done = False
        self.response_done = False
        self._disconnected: asyncio.Event | None = None
        self._start: asyncio.Handle | None = None
        self._task: asyncio.Task | None = None

    def body_arrived(self) -> None:
        self.body_done = True
        self._start = asyncio.get_running_loop().call_soon(self._start_watching)

    def _start_watching(self) -> None:
        self._start = None
        if self._task is None and not self.response_done:
            self._task = asyncio.get_running_loop().create_task(self._watch())

    async def _watch(self) -> None:
        message = await self._receive()
        if message["type"] == "http.disconnect" and not self.response_done:
            self._budget.cancel()
            logger.info("client disconnected: cancelling the request at its next chunk",
                        extra={"fields": {"path": self._scope.get("path")}})
        self._event().set()

    def _event(self) -> asyncio.Event:
        if self._disconnected is None:
            self._disconnected = asyncio.Event()
        return self._disconnected

    def disconnected_now(self) -> None:
        """The client went before its body was whole."""
        self._budget.cancel()
        self._event().set()

    async def disconnect(self) -> Message:
        """What a ``receive()`` after the body returns: the disconnect, once it happens."""
        if self._task is None:
            self._task = asyncio.get_running_loop().create_task(self._watch())
        await self._event().wait()
        return {"type": "http.disconnect"}

    def stop(self) -> None:
        if self._start is not None:
            self._start.cancel()
        if self._task is not None:
            self._task.cancel()


def _length(declared: bytes) -> int:
    try:
        return int(declared)
    except ValueError:
        return 0


async def _send_problem(send: Send, status: int, slug: str, title: str, detail: str, scope: Scope, *,
                        headers: list[tuple[bytes, bytes]] = (), errors: list | None = None) -> None:
    """A problem+json answer written straight to the server (no route ran, so no exception handler can)."""
    body: dict[str, Any] = {"type": PROBLEM_TYPE_BASE + slug, "title": title, "status": status, "detail": detail,
                            "instance": scope.get("path", "")}
    if errors is not None:
        body["errors"] = errors
    encoded = json.dumps(body).encode()
    await send({"type": "http.response.start", "status": status,
                "headers": [(b"content-type", PROBLEM_MEDIA_TYPE.encode()),
                            (b"content-length", str(len(encoded)).encode()), *headers]})
    await send({"type": "http.response.body", "body": encoded})


class _BodyTooLarge(HTTPException):
    """Raised while the body streams in; the problem handlers answer it as a 413 (or the gate, if none ran)."""
