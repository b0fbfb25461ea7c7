"""The HTTP server's own defences and logs: slow clients, connection caps, JSON lines for uvicorn too.

uvicorn closes an idle keep-alive connection after ``timeout_keep_alive``, but it has no deadline for a request
head or body: a client that opens a socket and sends nothing, or one byte every few seconds, holds a descriptor
for ever (1,010 such sockets locked out 58 of 59 new requests at a 1,024-descriptor limit). :class:`_Watchdog`
adds both, on uvicorn's own HTTP protocol classes:

* **head**: a connection must complete a request head within ``KIN_HEADER_TIMEOUT_S`` of opening or of its
  previous response;
* **body**: a request's body must arrive within ``KIN_BODY_TIMEOUT_S`` of its head.

Each closes the connection and logs one warning line naming the client. ``KIN_MAX_CONNECTIONS`` caps the open
connections per worker: a connection opened past it is answered 503 at once (a problem+json with ``Retry-After``
and ``Connection: close``, logged) instead of letting descriptors run out. :class:`_Watchdog` enforces it itself
rather than through uvicorn's ``limit_concurrency``, whose 503 is text/plain. The settings are read from the
environment in each worker process, since workers are spawned and do not share the parent's objects. With several
workers, :class:`ClosingMultiprocess` closes the shared listening socket on SIGTERM.
"""

from __future__ import annotations

import asyncio
import logging
from typing import Any

from uvicorn.supervisors.multiprocess import Multiprocess

from .api.budget import RETRY_AFTER_SECONDS
from .api.problems import problem_response
from .config import Settings

logger = logging.getLogger("service.server")

_CHECK_EVERY_S = 0.5


class _Watchdog:
    """Mixin for uvicorn's HTTP protocols: head and body deadlines, checked twice a second per connection."""

    _settings: Settings | None = None

    @classmethod
    def _limits(cls) -> Settings:
        if _Watchdog._settings is None:
            _Watchdog._settings = Settings()
        return _Watchdog._settings

    def connection_made(self, transport: asyncio.Transport) -> None:  # type: ignore[override]
        super().connection_made(transport)  # type: ignore[misc]
        loop = asyncio.get_running_loop()
        self._waiting_since = loop.time()
        self._seen_cycle = None
        self._cycle_since = 0.0
        self._watch_timer = loop.call_later(_CHECK_EVERY_S, self._watch)
        open_connections, cap = len(self.connections), self._limits().max_connections  # type: ignore[attr-defined]
        if open_connections > cap:  # (this one included) every request on it gets the 503 problem
            self.app = _over_connection_cap  # type: ignore[attr-defined]
            logger.warning("refused: %d open connections (KIN_MAX_CONNECTIONS)", open_connections,
                           extra={"fields": {"connections": open_connections, "cap": cap}})
        elif open_connections > 0.9 * cap:
            logger.warning("open connections near the cap", extra={"fields": {
                "connections": open_connections, "cap": cap}})

    def on_response_complete(self) -> None:
        self._waiting_since = asyncio.get_running_loop().time()
        super().on_response_complete()  # type: ignore[misc]

    def connection_lost(self, exc: Exception | None) -> None:
        timer = getattr(self, "_watch_timer", None)
        if timer is not None:
            timer.cancel()
        super().connection_lost(exc)  # type: ignore[misc]

    def _watch(self) -> None:
        transport = self.transport  # type: ignore[attr-defined]
        if transport.is_closing():
            return
        loop = asyncio.get_running_loop()
        now = loop.time()
        limits = self._limits()
        cycle = self.cycle  # type: ignore[attr-defined]
        if cycle is None or cycle.response_complete:  # waiting for (the rest of) a request head
            if now - self._waiting_since > limits.header_timeout_s:
                self._close("no complete request head", limits.header_timeout_s, "KIN_HEADER_TIMEOUT_S")
                return
        else:
            if cycle is not self._seen_cycle:
                self._seen_cycle, self._cycle_since = cycle, now
            if cycle.more_body and now - self._cycle_since > limits.body_timeout_s:
                self._close("the request body did not arrive", limits.body_timeout_s, "KIN_BODY_TIMEOUT_S")
                return
        self._watch_timer = loop.call_later(_CHECK_EVERY_S, self._watch)

    def _close(self, what: str, seconds: float, setting: str) -> None:
        client = self.client  # type: ignore[attr-defined]
        logger.warning("slow client: %s within %g s (%s); closing the connection", what, seconds, setting,
                       extra={"fields": {"client": f"{client[0]}:{client[1]}" if client else None,
                                         "timeout_s": seconds, "setting": setting}})
        self.transport.close()  # type: ignore[attr-defined]


async def _over_connection_cap(scope: dict, receive: Any, send: Any) -> None:
    """The ASGI answer on a connection past ``KIN_MAX_CONNECTIONS``: a 503 problem that closes the connection."""
    cap = _Watchdog._limits().max_connections
    response = problem_response(
        503, "overloaded", "Too many open connections",
        f"The service holds its limit of {cap} open connections per worker (KIN_MAX_CONNECTIONS); retry after "
        f"{RETRY_AFTER_SECONDS} s.", instance=scope.get("path"),
        headers={"Retry-After": str(RETRY_AFTER_SECONDS), "Connection": "close"})
    await response(scope, receive, send)


def _protocol_class() -> type:
    """uvicorn's fastest available HTTP protocol, with the watchdog."""
    try:
        from uvicorn.protocols.http.httptools_impl import HttpToolsProtocol
    except ImportError:  # httptools missing: the pure-Python h11 protocol
        from uvicorn.protocols.http.h11_impl import H11Protocol

        return type("WatchedH11Protocol", (_Watchdog, H11Protocol), {"__module__": __name__})
    return type("WatchedHttpToolsProtocol", (_Watchdog, HttpToolsProtocol), {"__module__": __name__})


#: The HTTP protocol ``python -m service`` runs (module-level so that spawned workers import it by name).
WatchedProtocol = _protocol_class()
globals()[WatchedProtocol.__name__] = WatchedProtocol


class ClosingMultiprocess(Multiprocess):
    """uvicorn's supervisor of several workers, closing its listening socket as soon as SIGTERM or SIGINT arrives.

    The workers share the parent's socket. uvicorn's parent keeps it open until every worker has finished its
    graceful shutdown, so the kernel went on accepting connections that no one served: they hung for up to
    ``KIN_REQUEST_TIMEOUT_MS`` + 2 s and were then reset. Closed at once (and by each worker as it stops), a new
    connection is refused, as with one worker.
    """

    def _close_sockets(self) -> None:
        for sock in self.sockets:
            sock.close()

    def handle_term(self) -> None:
        self._close_sockets()
        super().handle_term()

    def handle_int(self) -> None:
        self._close_sockets()
        super().handle_int()


def log_config(level: str) -> dict[str, Any]:
    """``logging.config`` for uvicorn's own loggers and the root logger: one JSON object per line on stdout,
    tracebacks in the ``exc`` field (the service's own loggers are configured by the app the same way)."""
    level_name = "DEBUG" if level == "trace" else level.upper()
    handler = {"class": "service.api.observability._StdoutHandler", "formatter": "json"}
    return {
        "version": 1,
        "disable_existing_loggers": False,
        "formatters": {"json": {"()": "service.api.observability.JsonFormatter"}},
        "handlers": {"json": handler},
        "loggers": {
            "uvicorn": {"handlers": ["json"], "level": level_name, "propagate": False},
            "uvicorn.error": {"handlers": ["json"], "level": level_name, "propagate": False},
            "uvicorn.access": {"handlers": ["json"], "level": level_name, "propagate": False},
            "service.server": {"handlers": ["json"], "level": level_name, "propagate": False},
        },
        "root": {"handlers": ["json"], "level": "WARNING"},
    }
