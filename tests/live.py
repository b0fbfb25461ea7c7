"""A live ``python -m service`` on a free loopback port, for tests that need a real HTTP server."""

from __future__ import annotations

import contextlib
import os
import random
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path
from typing import Iterator

ROOT = Path(__file__).resolve().parent.parent


def free_port() -> int:
    """A free loopback port: any, or one in ``KIN_TEST_PORTS`` ("18700-18799") when that is set."""
    span = os.environ.get("KIN_TEST_PORTS")
    candidates = [0]
    if span:
        low, high = (int(part) for part in span.split("-"))
        candidates = random.sample(range(low, high + 1), high - low + 1)
    for port in candidates:
        with socket.socket() as probe:
            try:
                probe.bind(("127.0.0.1", port))
            except OSError:
                continue
            return probe.getsockname()[1]
    raise RuntimeError(f"no free port in KIN_TEST_PORTS={span}")


def get(url: str, headers: dict[str, str] | None = None) -> tuple[int, str, dict]:
    request = urllib.request.Request(url, headers=headers or {})
    try:
        with urllib.request.urlopen(request, timeout=5) as response:
            return response.status, response.read().decode(), dict(response.headers)
    except urllib.error.HTTPError as error:
        return error.code, error.read().decode(), dict(error.headers)


@contextlib.contextmanager
def serve(**settings: str) -> Iterator[str]:
    """Start the service with the given environment (e.g. KIN_WORKERS="2"), wait until ready, yield its URL,
    then stop it with SIGTERM and check that it exited cleanly. ``serve.pid`` is the server's process id."""
    port = free_port()
    env = {**os.environ, "HOST": "127.0.0.1", "PORT": str(port), "KIN_LOG_LEVEL": "warning", **settings}
    if "PROMETHEUS_MULTIPROC_DIR" not in settings:
        env.pop("PROMETHEUS_MULTIPROC_DIR", None)
    server = subprocess.Popen([sys.executable, "-m", "service"], cwd=ROOT, env=env,
                              stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    base_url = f"http://127.0.0.1:{port}"
    serve.pid = server.pid
    try:
        deadline = time.monotonic() + 60
        while True:
            try:
                if get(f"{base_url}/readyz")[0] == 200:
                    break
            except OSError:
                pass
            if server.poll() is not None:
                raise RuntimeError(f"the service exited: {server.stderr.read().decode()}")
            if time.monotonic() > deadline:
                raise RuntimeError("the service did not become ready within 60 s")
            time.sleep(0.2)
        yield base_url
    finally:
        server.terminate()
        try:
            server.wait(timeout=20)
        except subprocess.TimeoutExpired:
            server.kill()
            server.wait()
    # uvicorn finishes in-flight requests on SIGTERM and then, with one worker, re-raises the signal.
    if server.returncode not in (0, -signal.SIGTERM):
        raise RuntimeError(f"the service exited with {server.returncode}: {server.stderr.read().decode()}")
