"""A live ``python -m service`` on a free loopback port, for tests that need a real HTTP server."""

from __future__ import annotations

import contextlib
import os
import random
import signal
import socket
import subprocess
import sys
import tempfile
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


class LiveServer:
    """``python -m service`` on a free loopback port with the given environment (e.g. KIN_WORKERS="2"), its
    stdout and stderr (the JSON log) in the file ``log``, ready once this returns (``url``, ``process``)."""

    def __init__(self, log: Path, *, log_level: str = "warning", **settings: str) -> None:
        self.port = free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        self.log = log
        env = {**os.environ, "HOST": "127.0.0.1", "PORT": str(self.port), "KIN_LOG_LEVEL": log_level, **settings}
        if "PROMETHEUS_MULTIPROC_DIR" not in settings:
            env.pop("PROMETHEUS_MULTIPROC_DIR", None)
        self._out = log.open("wb")
        self.process = subprocess.Popen([sys.executable, "-m", "service"], cwd=ROOT, env=env, stdout=self._out,
                                        stderr=subprocess.STDOUT)
        deadline = time.monotonic() + 60
        while True:
            try:
                if get(f"{self.url}/readyz")[0] == 200:
                    break
            except OSError:
                pass
            if self.process.poll() is not None or time.monotonic() > deadline:
                self.stop()  # never leave a server behind: with several workers it outlives the test run
                raise RuntimeError(f"the service did not start within 60 s: {log.read_text()}")
            time.sleep(0.2)

    def stop(self) -> int:
        """SIGTERM (uvicorn finishes in-flight requests), a kill after 30 s; the exit code."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)
            try:
                self.process.wait(timeout=30)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        self._out.close()
        return self.process.returncode

    def lines(self) -> list[str]:
        """The log's non-empty lines."""
        return [line for line in self.log.read_text().splitlines() if line.strip()]


@contextlib.contextmanager
def serve(**settings: str) -> Iterator[str]:
    """A :class:`LiveServer` for the ``with`` block: yields its URL, then stops it and checks that it exited
    cleanly. ``serve.pid`` is the server's process id."""
    with tempfile.TemporaryDirectory() as directory:
        server = LiveServer(Path(directory) / "server.log", **settings)
        serve.pid = server.process.pid
        try:
            yield server.url
        finally:
            code = server.stop()
        # with one worker, uvicorn re-raises SIGTERM once it has finished
        if code not in (0, -signal.SIGTERM):
            raise RuntimeError(f"the service exited with {code}: {server.log.read_text()}")
