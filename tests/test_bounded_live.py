"""Bounded work against a real ``python -m service``: peak memory (VmHWM from /proc), health under load, slow
clients, JSON log lines (uvicorn's too), and SIGTERM during a request."""

from __future__ import annotations

import json
import os
import signal
import socket
import threading
import time
from pathlib import Path

import httpx
import pytest

from tests.arms import NUMERIC_ARM, SKEW_7R
from tests.live import LiveServer

pytestmark = pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="needs /proc")

UR5_Q = [0.3, -1.0, 1.2, 0.4, 0.5, 0.6]
NUMERIC_TARGET = {"position": [0.3, 0.2, 0.5], "orientation": {"type": "rpy", "angles": [0.3, 0.2, 0.1]}}
#: A request that keeps a worker busy for seconds (1.8 s here): a skew 7R arm with an inner joint free at 256
#: values (the most an inner joint may take), each of which builds and solves its own general 6R plan (the
#: numeric search of 2,000 starts on NUMERIC_ARM converges in ~0.2 s, too short to probe the server while it runs).
SLOW_REQUEST = {"robot": SKEW_7R, "target": NUMERIC_TARGET, "free_joints": [{"joint": 3, "samples": 256}]}


def peak_rss_mb(pid: int) -> float:
    """The process's peak resident set (VmHWM), in MB, read from /proc (no psutil)."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024.0
    raise RuntimeError("no VmHWM")


def info_server(tmp_path: Path, **settings: str) -> LiveServer:
    """A live server logging at info into a new file of ``tmp_path`` (these tests read its access and uvicorn
    lines)."""
    log = tmp_path / f"server-{len(list(tmp_path.glob('server-*.log')))}.log"
    return LiveServer(log, log_level="info", **settings)


@pytest.fixture
def server(tmp_path):
    started = info_server(tmp_path, KIN_MAX_TURNS_PER_JOINT="1000000", KIN_HEADER_TIMEOUT_S="1",
                     KIN_REQUEST_TIMEOUT_MS="4000")
    yield started
    started.stop()


def test_hostile_requests_keep_one_worker_under_its_memory_bound_and_health_answers(server):
    """The issue's hostile requests, one after another and then side by side with /healthz probes: every one is
    answered within its cap (no 5xx other than a 503 problem), the worker's peak RSS stays far below 1 GB."""
    fk = httpx.post(f"{server.url}/v1/robots/ur5/fk", json={"joints": UR5_Q}).json()
    target = {"matrix": fk["pose"]["matrix"]}
    wide = [{"lower": -1e6, "upper": 1e6}] * 6
    hostile = [
        ("/v1/robots/ur5/ik", {"target": target, "limits": wide}),  # was 7.6 GB
        ("/v1/robots/ur5/ik", {"target": target, "limits": wide, "max_equivalents": 100_000}),  # was 30.6 MB out
        ("/v1/robots/ur5/ik/batch", {"targets": [target] * 10_000}),  # was 8.2 GB, 118 s
        ("/v1/robots/ur5/ik/batch", {"targets": [target] * 50, "limits": [{"lower": -5000, "upper": 5000}] * 6,
                                     "format": "arrays", "max_equivalents": 50}),  # was an int64-overflow 500
        ("/v1/ik", {"robot": NUMERIC_ARM, "target": NUMERIC_TARGET, "limits": [{"lower": -1e6, "upper": 1e6}] * 6,
                    "numeric": {"starts": 2000, "time_budget_ms": 10_000}}),  # was past 12 GB
    ]
    baseline = peak_rss_mb(server.process.pid)
    statuses = []
    with httpx.Client(timeout=60) as client:
        for path, body in hostile:
            started = time.perf_counter()
            response = client.post(f"{server.url}{path}", json=body)
            statuses.append(response.status_code)
            assert response.status_code in (200, 413, 503), response.text[:300]
            if response.status_code != 200:
                assert response.headers["content-type"].startswith("application/problem+json")
            assert time.perf_counter() - started < 30.0
    assert statuses[:3] == [200, 413, 413] and statuses[3] == 200

    # the same hostile requests from 4 threads while /healthz is probed
    health: list[float] = []
    stop = threading.Event()

    def probe() -> None:
        with httpx.Client(timeout=10) as client:
            while not stop.is_set():
                started = time.perf_counter()
                assert client.get(f"{server.url}/healthz").status_code == 200
                health.append(time.perf_counter() - started)
                time.sleep(0.05)

    def hammer() -> None:
        with httpx.Client(timeout=60) as client:
            for path, body in hostile:
                assert client.post(f"{server.url}{path}", json=body).status_code in (200, 413, 503)

    prober = threading.Thread(target=probe)
    prober.start()
    workers = [threading.Thread(target=hammer) for _ in range(4)]
    for worker in workers:
        worker.start()
    for worker in workers:
        worker.join()
    stop.set()
    prober.join()
    peak = peak_rss_mb(server.process.pid)
    print(f"baseline {baseline:.0f} MB, peak {peak:.0f} MB, /healthz max {max(health) * 1000:.0f} ms "
          f"over {len(health)} probes")
    assert peak < 1024 and peak - baseline < 600
    assert max(health) < 2.0  # a liveness probe's timeout; the soak benchmark reports the real figure


def test_slow_clients_are_cut_off_and_logged_and_every_log_line_is_json(server):
    with socket.create_connection(("127.0.0.1", server.port)) as slow:
        slow.sendall(b"GET /healthz HTTP/1.1\r\nHost: x\r\n")  # never finishes its head
        slow.settimeout(10)
        started = time.perf_counter()
        assert slow.recv(1024) == b""  # closed by the server
        assert time.perf_counter() - started < 8.0
    assert httpx.get(f"{server.url}/healthz").status_code == 200
    server.stop()
    lines = server.lines()
    records = [json.loads(line) for line in lines]  # every line is one JSON object, uvicorn's included
    loggers = {record["logger"] for record in records}
    assert {"uvicorn.error", "service", "service.server"} <= loggers
    assert any("KIN_HEADER_TIMEOUT_S" in record["msg"] for record in records)


def test_sigterm_during_a_request_finishes_or_refuses_it_cleanly(tmp_path):
    server = info_server(tmp_path, KIN_REQUEST_TIMEOUT_MS="3000", KIN_MAX_IK_TIME_MS="600000")
    answer: dict = {}

    def slow_request() -> None:
        with httpx.Client(timeout=60) as client:
            response = client.post(f"{server.url}/v1/ik", json={
                "robot": NUMERIC_ARM, "target": NUMERIC_TARGET, "numeric": {"starts": 2000, "time_budget_ms": 10_000}})
            answer["status"], answer["type"] = response.status_code, response.headers["content-type"]

    try:
        request = threading.Thread(target=slow_request)
        request.start()
        time.sleep(1.0)  # the request is being worked on
        server.process.send_signal(signal.SIGTERM)
        request.join(timeout=30)
    finally:
        code = server.stop()
    assert answer["status"] in (200, 503), answer
    assert answer["status"] == 200 or answer["type"].startswith("application/problem+json")
    assert code in (0, -signal.SIGTERM)
    for line in server.lines():
        json.loads(line)


def test_a_saturated_server_stays_ready_sheds_each_request_past_the_limit_and_is_not_ready_in_shutdown(tmp_path):
    """Issue 22.9, load shed per request: with KIN_MAX_IN_FLIGHT = 1 and one slow request in flight, /readyz is
    200 (in_flight 1) and a new request gets a 503 problem with Retry-After; once SIGTERM arrives, the readiness
    probe never answers 200 again (refused: uvicorn closes its listening socket; or 503), while the slow request
    still ends cleanly."""
    server = info_server(tmp_path, KIN_MAX_IN_FLIGHT="1", KIN_REQUEST_TIMEOUT_MS="3000", KIN_MAX_IK_TIME_MS="600000")
    answer: dict = {}

    def slow_request() -> None:
        with httpx.Client(timeout=60) as client:
            response = client.post(f"{server.url}/v1/ik", json=SLOW_REQUEST)
            answer["status"], answer["type"] = response.status_code, response.headers["content-type"]

    request = threading.Thread(target=slow_request)
    try:
        request.start()
        deadline = time.monotonic() + 2.0
        while (ready := httpx.get(f"{server.url}/readyz", timeout=5)).json().get("in_flight") != 1:
            assert time.monotonic() < deadline, ready.text
            time.sleep(0.02)
        assert ready.status_code == 200 and ready.json()["status"] == "ready"  # saturated, and still ready
        refused = httpx.post(f"{server.url}/v1/robots/ur5/fk", json={"joints": UR5_Q}, timeout=5)
        assert refused.status_code == 503 and refused.headers["retry-after"] == "1"
        assert refused.headers["content-type"].startswith("application/problem+json")
        assert refused.json()["type"].endswith("/overloaded") and "KIN_MAX_IN_FLIGHT = 1" in refused.json()["detail"]
        assert answer == {}  # the slow request is still being worked on
        server.process.send_signal(signal.SIGTERM)
        time.sleep(0.3)
        probes = []
        while request.is_alive() and len(probes) < 20:  # during the drain
            try:
                probes.append(httpx.get(f"{server.url}/readyz", timeout=2).status_code)
            except httpx.TransportError:
                probes.append(None)  # refused: the socket is closed, which the probe counts as not ready
            time.sleep(0.1)
        request.join(timeout=30)
    finally:
        code = server.stop()
    assert probes and 200 not in probes, probes
    assert answer["status"] in (200, 503), answer
    assert answer["status"] == 200 or answer["type"].startswith("application/problem+json")
    assert code in (0, -signal.SIGTERM)


def test_a_connection_over_the_cap_gets_a_problem_and_is_logged(tmp_path):
    """KIN_MAX_CONNECTIONS = 3: with three connections open, a fourth is answered 503 application/problem+json
    with Retry-After and closed (uvicorn's own limit answered text/plain); once one closes, requests pass again."""
    server = info_server(tmp_path, KIN_MAX_CONNECTIONS="3", KIN_HEADER_TIMEOUT_S="30")
    held = [socket.create_connection(("127.0.0.1", server.port)) for _ in range(3)]
    try:
        time.sleep(0.3)  # the server has taken all three
        response = httpx.get(f"{server.url}/healthz", timeout=5)
        assert response.status_code == 503
        assert response.headers["content-type"].startswith("application/problem+json")
        assert response.headers["retry-after"] == "1" and response.headers["connection"] == "close"
        problem = response.json()
        assert problem["status"] == 503 and problem["type"].endswith("/overloaded") and problem["title"]
        assert "KIN_MAX_CONNECTIONS" in problem["detail"] and "3" in problem["detail"]
        held.pop().close()
        time.sleep(0.3)
        assert httpx.get(f"{server.url}/healthz", timeout=5).status_code == 200
    finally:
        for connection in held:
            connection.close()
        server.stop()
    records = [json.loads(line) for line in server.lines()]
    assert any("KIN_MAX_CONNECTIONS" in record["msg"] for record in records)


def test_with_two_workers_a_new_connection_during_shutdown_is_refused_at_once(tmp_path):
    """SIGTERM to the parent of two workers while one still holds a connection (a request whose body has not
    arrived): uvicorn's parent kept the shared listening socket open until every worker had finished, so the
    kernel accepted new connections that no one served (they hung for the whole graceful shutdown, then were
    reset). Now the parent closes it at once: a new connection is refused or answered, never left hanging."""
    server = info_server(tmp_path, KIN_WORKERS="2", KIN_BODY_TIMEOUT_S="8", KIN_REQUEST_TIMEOUT_MS="4000")
    held = socket.create_connection(("127.0.0.1", server.port))
    try:
        held.sendall(b"POST /v1/robots/ur5/fk HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
                     b"Content-Length: 100\r\n\r\n{")
        time.sleep(0.5)
        server.process.send_signal(signal.SIGTERM)
        time.sleep(1.5)  # the supervisor polls its signals every 0.5 s; the workers start their shutdown
        assert server.process.poll() is None  # still waiting for the held connection
        started = time.perf_counter()
        try:
            answered = httpx.get(f"{server.url}/healthz", timeout=5).status_code
        except httpx.ConnectError:
            answered = None  # refused: the socket is closed
        assert time.perf_counter() - started < 1.0, answered
    finally:
        held.close()
        code = server.stop()
    assert code in (0, -signal.SIGTERM)
    for line in server.lines():
        json.loads(line)


def test_a_single_ik_is_not_queued_behind_long_requests(server):
    """Long requests (a 2,000-sample unreachable trajectory on the numeric arm, each until its 4 s deadline) fill
    more requests than there are cores; a single IK sent after them is answered while they still run. With one
    work loop per core it waited for one of them to end, and in the soak went past its own deadline."""
    fk = httpx.post(f"{server.url}/v1/robots/ur5/fk", json={"joints": UR5_Q}).json()
    far = {"position": [5.0, 5.0, 5.0], "orientation": {"type": "rpy", "angles": [0, 0, 0]}}
    long_body = {"robot": NUMERIC_ARM, "samples": [{"time": 0.01 * k, "pose": far} for k in range(2000)]}
    ended: list[float] = []

    def long_request() -> None:
        with httpx.Client(timeout=60) as client:
            response = client.post(f"{server.url}/v1/ik/trajectory", json=long_body)
            assert response.status_code in (200, 503)
            ended.append(time.monotonic())

    long_ones = [threading.Thread(target=long_request) for _ in range(2 * (os.cpu_count() or 1) + 1)]
    for thread in long_ones:
        thread.start()
    time.sleep(0.5)  # they have started computing
    with httpx.Client(timeout=60) as client:
        response = client.post(f"{server.url}/v1/robots/ur5/ik", json={"target": {"matrix": fk["pose"]["matrix"]}})
    answered = time.monotonic()
    for thread in long_ones:
        thread.join()
    assert response.status_code == 200 and response.json()["status"] == "ok"
    assert answered < min(ended), (answered, sorted(ended))
