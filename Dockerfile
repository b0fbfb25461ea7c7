# syntax=docker/dockerfile:1
#
# Kinematics REST service image.
#
#   docker build -t kinematics-service .
#   docker run --rm -p 8000:8000 kinematics-service
#
# Extra robots (added to the built-in catalogue in /app/robots):
#   docker run --rm -p 8000:8000 \
#     -v ./my-robots:/robots.d:ro -e KIN_ROBOTS_DIR=/robots.d kinematics-service
#
# Other settings are read from the environment: KIN_WORKERS, KIN_LOG_LEVEL,
# KIN_API_KEY, KIN_CORS_ORIGINS, KIN_MAX_BATCH, KIN_MAX_BODY_BYTES, KIN_MAX_JOINTS,
# KIN_MAX_IK_TIME_MS (see the README). With KIN_WORKERS > 1 the service keeps its
# Prometheus samples in a fresh directory under /tmp (multiprocess mode): /tmp must
# be writable (a tmpfs or emptyDir when the root filesystem is read-only).

ARG PYTHON_VERSION=3.11

# ---------------------------------------------------------------------------
# builder: resolve the runtime dependencies into a self-contained venv.
# ---------------------------------------------------------------------------
FROM python:${PYTHON_VERSION}-slim AS builder

ENV PIP_NO_CACHE_DIR=1 \
    PIP_DISABLE_PIP_VERSION_CHECK=1 \
    PYTHONDONTWRITEBYTECODE=1

RUN python -m venv /opt/venv
ENV PATH=/opt/venv/bin:$PATH

# Only requirements.lock is copied first, so the (slow) dependency layer is rebuilt
# when the pinned dependencies change, not on every source edit. The image installs
# exactly the versions CI audits (.ci/audit), with --no-deps: the lock is the whole
# closure, so nothing unpinned can slip in. The package itself is not installed into
# the venv: the service finds its catalogue as the `robots` directory next to the
# `service` package, so both live side by side in /app. pip and setuptools are then
# removed from the venv; the runtime needs neither.
WORKDIR /src
COPY requirements.lock ./
RUN pip install --no-cache-dir --no-deps -r requirements.lock \
 && pip check \
 && pip uninstall --yes pip setuptools \
 && find /opt/venv -depth -type d -name '__pycache__' -exec rm -rf {} +

# ---------------------------------------------------------------------------
# runtime: interpreter + venv + application source, no build tools, not root.
# ---------------------------------------------------------------------------
FROM python:${PYTHON_VERSION}-slim AS runtime

LABEL org.opencontainers.image.title="kinematics-service" \
      org.opencontainers.image.description="REST service for forward and inverse kinematics of serial robots"

ENV PATH=/opt/venv/bin:$PATH \
    PYTHONPATH=/app \
    PYTHONDONTWRITEBYTECODE=1 \
    PYTHONUNBUFFERED=1 \
    HOST=0.0.0.0 \
    PORT=8000

RUN groupadd --gid 10001 app \
 && useradd --uid 10001 --gid app --no-create-home --no-log-init \
        --home-dir /nonexistent --shell /usr/sbin/nologin app

COPY --from=builder /opt/venv /opt/venv

WORKDIR /app
COPY service/ /app/service/
COPY robots/ /app/robots/

# Numeric uid so that Kubernetes' runAsNonRoot can verify it.
USER 10001:10001

EXPOSE 8000

# No curl in the slim image: probe with the standard library. urlopen raises on
# any non-2xx answer or connection error, which makes the exit status non-zero.
HEALTHCHECK --interval=30s --timeout=5s --start-period=20s --retries=3 \
    CMD ["python", "-c", "import os, urllib.request; urllib.request.urlopen('http://127.0.0.1:%s/healthz' % os.environ.get('PORT', '8000'), timeout=4)"]

# Exec form: python is PID 1 and uvicorn receives SIGTERM directly, so it stops
# accepting connections and finishes in-flight requests before exiting.
STOPSIGNAL SIGTERM
CMD ["python", "-m", "service"]
