"""``python -m service``: serve the API with uvicorn on HOST:PORT (defaults 127.0.0.1:8000)."""

from __future__ import annotations

import os
import shutil
import tempfile

import uvicorn

from .config import Settings

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
        uvicorn.run(
            "service.api.app:create_app",
            factory=True,
            host=settings.host,
            port=settings.port,
            workers=settings.workers,
            log_level=settings.log_level,
            access_log=False,  # the service writes its own JSON access log, with the request id
            timeout_graceful_shutdown=10,
        )
    finally:
        if own_metrics_dir is not None:
            shutil.rmtree(own_metrics_dir, ignore_errors=True)


if __name__ == "__main__":
    main()
