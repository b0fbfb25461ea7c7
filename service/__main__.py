"""``python -m service``: serve the API with uvicorn on HOST:PORT (defaults 127.0.0.1:8000)."""

from __future__ import annotations

import math
import os
import shutil
import sys
import tempfile

import uvicorn

from .config import Settings
from .server import ClosingMultiprocess, WatchedProtocol, log_config

MULTIPROC_ENV = "PROMETHEUS_MULTIPROC_DIR"


def main() -> None:
    settings = Settings()
    own_metrics_dir = None
    if settings.workers > 1 and not os.environ.get(MULTIPROC_ENV):
        # Several worker processes: prometheus-client's multiprocess mode, so that /metrics (answered by any one
        # worker) aggregates every worker's samples. The directory must exist, and be empty, before the workers
        # start; they inherit the variable.
        own_metrics_dir = tempfile.mkdtemp(prefix="kin-metrics-")
        os.environ[MULTIPROC_ENV] = own_metrics_dir
    try:
        config = uvicorn.Config(
            "service.api.app:create_app",
            factory=True,
            host=settings.host,
            port=settings.port,
            workers=settings.workers,
            log_level=settings.log_level,
            log_config=log_config(settings.log_level),  # uvicorn's own lines as JSON too
            access_log=False,  # the service writes its own JSON access log, with the request id
            http=WatchedProtocol,  # head and body deadlines for slow clients (service/server.py)
            timeout_keep_alive=settings.timeout_keep_alive_s,
            # KIN_MAX_CONNECTIONS is enforced by WatchedProtocol (a problem+json 503, not uvicorn's text/plain one)
            h11_max_incomplete_event_size=64 * 1024,  # a request head larger than this is refused
            # Every request ends by its deadline (a 503 problem past it), so waiting that long on SIGTERM lets each
            # in-flight request finish or refuse cleanly instead of being cut off with a text/plain 500.
            timeout_graceful_shutdown=math.ceil(settings.request_timeout_ms / 1000.0) + 2,
        )
        if settings.workers > 1:  # the parent holds the listening socket: it closes it first on SIGTERM
            ClosingMultiprocess(config, sockets=[config.bind_socket()]).run()
        else:
            server = uvicorn.Server(config)
            server.run()
            if not server.started:
                sys.exit(3)  # uvicorn's start-up failure code
    finally:
        if own_metrics_dir is not None:
            shutil.rmtree(own_metrics_dir, ignore_errors=True)


if __name__ == "__main__":
    main()
