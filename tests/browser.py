"""Headless Chromium driven over the DevTools protocol, for tests of the pages people see.

Debian's ``chromium`` (installed by ``.ci/run``) is started with its own profile and no network: every host
name resolves to nothing except 127.0.0.1, and every request the page makes is recorded, so a test can assert
that nothing was fetched from anywhere but the service. The protocol is spoken over the ``websockets`` client
that uvicorn already brings; no browser-automation package (and no browser download) is needed.

When Chromium is missing the browser tests skip, except under CI (``CI=true``), where they must run.
"""

from __future__ import annotations

import base64
import itertools
import json
import os
import shutil
import subprocess
import tempfile
import threading
import time
import urllib.request
from pathlib import Path
from typing import Any

import pytest

from tests.live import free_port

ARTIFACTS_DIR = Path(os.environ.get("KIN_TEST_ARTIFACTS", Path(__file__).resolve().parent.parent / "test-artifacts"))
#: Every screenshot saved in this run; tests/conftest.py lists them at the end of the run, so CI's log has them.


def chromium_path() -> str:
    """The Chromium executable, or skip (fail under CI, where the browser tests must run)."""
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    message = "Chromium is not installed (apt-get install chromium; .ci/run installs it)"
    if os.environ.get("CI"):
        pytest.fail(message)
    pytest.skip(message)


class Browser:
    """One headless Chromium with one page; use as a context manager."""

    def __init__(self, width: int = 1280, height: int = 900) -> None:
        from websockets.sync.client import connect

        self._profile = tempfile.mkdtemp(prefix="kin-chromium-")
        port = free_port()
        self._process = subprocess.Popen(
            [chromium_path(), "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
             "--no-first-run", "--no-default-browser-check", "--disable-extensions", "--disable-sync",
             "--disable-background-networking", "--disable-component-update", "--disable-default-apps",
             "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE 127.0.0.1", f"--window-size={width},{height}",
             f"--remote-debugging-port={port}", "--remote-allow-origins=*", f"--user-data-dir={self._profile}",
             "about:blank"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        deadline = time.monotonic() + 30
        while True:
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=2) as answer:
                    pages = [t for t in json.load(answer) if t["type"] == "page"]
                if pages:
                    break
            except OSError:
                pass
            if self._process.poll() is not None or time.monotonic() > deadline:
                self.close()
                raise RuntimeError("Chromium did not start its DevTools endpoint")
            time.sleep(0.2)
        self._socket = connect(pages[0]["webSocketDebuggerUrl"], max_size=None, open_timeout=10).__enter__()
        self._ids = itertools.count(1)
        self._answers: dict[int, dict] = {}
        self._events: list[dict] = []
        self._lock = threading.Condition()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        self.requests: list[str] = []
        #: requests the browser refused to send (the page's Content-Security-Policy), by URL
        self.blocked: list[str] = []
        self._request_urls: dict[str, str] = {}
        self.console_errors: list[str] = []
        for domain in ("Page", "Runtime", "Network"):
            self.send(f"{domain}.enable")

    def _read(self) -> None:
        try:
            for raw in self._socket:
                message = json.loads(raw)
                with self._lock:
                    if "id" in message:
                        self._answers[message["id"]] = message
                    else:
                        self._on_event(message)
                        self._events.append(message)
                    self._lock.notify_all()
        except Exception:  # the socket closes when the browser stops
            pass

    def _on_event(self, event: dict) -> None:
        params = event.get("params", {})
        if event["method"] == "Network.requestWillBeSent":
            self.requests.append(params["request"]["url"])
            self._request_urls[params["requestId"]] = params["request"]["url"]
        elif event["method"] == "Network.loadingFailed" and params.get("blockedReason"):
            self.blocked.append(self._request_urls.get(params["requestId"], "?"))
        elif event["method"] == "Runtime.exceptionThrown":
            self.console_errors.append(json.dumps(params.get("exceptionDetails", {}))[:500])

    def send(self, method: str, timeout: float = 30, **params: Any) -> dict:
        """Call one protocol method and return its result."""
        call = next(self._ids)
        self._socket.send(json.dumps({"id": call, "method": method, "params": params}))
        with self._lock:
            if not self._lock.wait_for(lambda: call in self._answers, timeout):
                raise TimeoutError(f"{method} did not answer within {timeout} s")
            answer = self._answers.pop(call)
        if "error" in answer:
            raise RuntimeError(f"{method}: {answer['error']}")
        return answer.get("result", {})

    def navigate(self, url: str, timeout: float = 30) -> None:
        """Open ``url`` and wait for its load event."""
        with self._lock:
            self._events.clear()
        self.send("Page.navigate", url=url)
        with self._lock:
            if not self._lock.wait_for(lambda: any(e["method"] == "Page.loadEventFired" for e in self._events),
                                       timeout):
                raise TimeoutError(f"{url} did not load within {timeout} s")

    def evaluate(self, expression: str, timeout: float = 30) -> Any:
        """The value of a JavaScript expression in the page (promises are awaited)."""
        result = self.send("Runtime.evaluate", timeout=timeout, expression=expression, returnByValue=True,
                           awaitPromise=True)
        if "exceptionDetails" in result:
            raise RuntimeError(f"{expression!r} threw: {result['exceptionDetails']}")
        return result["result"].get("value")

    def wait_for(self, expression: str, timeout: float = 30) -> Any:
        """Poll a JavaScript expression until it is truthy, and return its value."""
        deadline = time.monotonic() + timeout
        while True:
            value = self.evaluate(expression)
            if value:
                return value
            if time.monotonic() > deadline:
                raise TimeoutError(f"{expression!r} stayed falsy for {timeout} s")
            time.sleep(0.1)

    def screenshot(self, name: str) -> Path:
        """Save a PNG of the page under the artifacts directory, print its path and return it."""
        ARTIFACTS_DIR.mkdir(parents=True, exist_ok=True)
        path = ARTIFACTS_DIR / name
        path.write_bytes(base64.b64decode(self.send("Page.captureScreenshot", format="png")["data"]))
        print(f"screenshot: {path}")
        return path

    def foreign_requests(self, origin: str) -> list[str]:
        """Requests the page sent to anywhere but ``origin`` (data: and blob: URLs are local; requests that the
        browser blocked before sending them are not counted)."""
        blocked = list(self.blocked)
        sent = []
        for url in self.requests:
            if url in blocked:
                blocked.remove(url)
            elif not url.startswith((origin + "/", "data:", "blob:", "about:")):
                sent.append(url)
        return sent

    def clear(self) -> None:
        """Forget the requests recorded so far."""
        self.requests.clear()
        self.blocked.clear()

    def close(self) -> None:
        socket = getattr(self, "_socket", None)
        if socket is not None:
            socket.close()
        self._process.terminate()
        try:
            self._process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self._process.kill()
            self._process.wait()
        shutil.rmtree(self._profile, ignore_errors=True)

    def __enter__(self) -> "Browser":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
