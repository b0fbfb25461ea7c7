"""Request ids, JSON access logs, Prometheus metrics (one worker and several), readiness."""

from __future__ import annotations

import io
import json
import logging
import re
import time
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from service.api.app import create_app
from service.api.observability import JsonFormatter
from service.config import BUILTIN_ROBOTS_DIR, Settings
from tests.conftest import assert_problem
from tests.live import get, serve


# --------------------------------------------------------------------------- request ids


def test_a_sane_incoming_request_id_is_echoed(client):
    response = client.get("/healthz", headers={"X-Request-ID": "edge-7f3a:42.1_b"})
    assert response.headers["x-request-id"] == "edge-7f3a:42.1_b"


@pytest.mark.parametrize("incoming", [None, "", "has space", "x" * 129, "semi;colon", "ünïcode"])
def test_a_missing_or_insane_request_id_is_replaced(client, incoming):
    headers = {} if incoming is None else {"X-Request-ID": incoming.encode("utf-8")}
    response = client.get("/healthz", headers=headers)
    assert re.fullmatch(r"[0-9a-f]{32}", response.headers["x-request-id"])


def test_errors_carry_the_request_id_too(client):
    response = client.post("/v1/robots/nope/fk", json={"joints": []}, headers={"X-Request-ID": "req-404"})
    assert_problem(response, 404)
    assert response.headers["x-request-id"] == "req-404"


def test_a_server_error_carries_the_request_id_in_header_detail_and_log(monkeypatch):
    """500 is answered by Starlette's outermost middleware; the id still reaches the response and the log."""
    from service.api.routers import fk

    app = create_app(Settings(_env_file=None))

    def explode(*args, **kwargs):
        raise RuntimeError("boom")

    monkeypatch.setattr(fk, "forward_kinematics", explode)
    stream = _capture("service.errors")
    with TestClient(app, raise_server_exceptions=False) as test_client:
        response = test_client.post("/v1/robots/ur5/fk", json={"joints": [0.0] * 6}, headers={"X-Request-ID": "r-500"})
    assert_problem(response, 500, match="r-500")
    assert response.headers["x-request-id"] == "r-500"
    record = json.loads(stream.getvalue().splitlines()[-1])
    assert record["request_id"] == "r-500" and "RuntimeError: boom" in record["exc"]


# --------------------------------------------------------------------------- JSON access log


def _capture(logger_name: str) -> io.StringIO:
    stream = io.StringIO()
    handler = logging.StreamHandler(stream)
    handler.setFormatter(JsonFormatter())
    logging.getLogger(logger_name).addHandler(handler)
    return stream


def test_one_json_access_line_per_request(client):
    stream = _capture("service.access")
    response = client.post("/v1/robots/ur5/fk", json={"joints": [0.0] * 6}, headers={"X-Request-ID": "log-1"})
    lines = [json.loads(line) for line in stream.getvalue().splitlines()]
    assert len(lines) == 1
    line = lines[0]
    assert line["request_id"] == "log-1" == response.headers["x-request-id"]
    assert line["method"] == "POST" and line["path"] == "/v1/robots/ur5/fk"
    assert line["route"] == "/v1/robots/{robot_id}/fk" and line["status"] == 200
    assert line["level"] == "info" and line["logger"] == "service.access"
    assert 0 < line["duration_ms"] < 10_000
    assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}\+00:00", line["ts"])


def test_an_app_started_and_stopped_in_the_process_leaves_the_serving_apps_log_level(client):
    """The log level is the process's: a quieter app holds it while it serves and gives it back when it stops.

    Built and started at ``warning`` (as several tests do), such an app once left the ``service`` loggers at
    WARNING for good, and the session client's access lines (INFO) vanished in whatever test ran after it.
    """
    with TestClient(create_app(Settings(_env_file=None, log_level="warning"))):
        assert logging.getLogger("service").getEffectiveLevel() == logging.WARNING
    stream = _capture("service.access")
    client.post("/v1/robots/ur5/fk", json={"joints": [0.0] * 6}, headers={"X-Request-ID": "after-quiet-app"})
    requests = [json.loads(line)["request_id"] for line in stream.getvalue().splitlines()]
    assert requests == ["after-quiet-app"]


# --------------------------------------------------------------------------- metrics


def _sample(text: str, name: str, **labels: str) -> float:
    """The value of one sample in Prometheus text format (0 when absent)."""
    for line in text.splitlines():
        series, _, value = line.rpartition(" ")
        if series == name or series.startswith(name + "{"):
            found = dict(re.findall(r'(\w+)="([^"]*)"', series[len(name):]))
            if all(found.get(k) == v for k, v in labels.items()):
                return float(value)
    return 0.0


def test_request_counts_and_latency_by_route_template(client):
    before = client.get("/metrics").text
    for robot_id in ("ur5", "puma560_modified", "spong_ex3_5_stanford"):
        joints = [0.0] * len(client.get(f"/v1/robots/{robot_id}").json()["joints"])
        assert client.post(f"/v1/robots/{robot_id}/fk", json={"joints": joints}).status_code == 200
    client.post("/v1/robots/ur5/fk", json={"joints": [0.0]})
    client.get("/no/such/thing")
    response = client.get("/metrics")
    assert response.headers["content-type"].startswith("text/plain")
    after = response.text
    route = "/v1/robots/{robot_id}/fk"
    assert _sample(after, "kin_http_requests_total", method="POST", route=route, status="200") \
        - _sample(before, "kin_http_requests_total", method="POST", route=route, status="200") == 3
    assert _sample(after, "kin_http_requests_total", method="POST", route=route, status="422") \
        - _sample(before, "kin_http_requests_total", method="POST", route=route, status="422") == 1
    assert _sample(after, "kin_http_requests_total", method="GET", route="unmatched", status="404") \
        - _sample(before, "kin_http_requests_total", method="GET", route="unmatched", status="404") == 1
    assert _sample(after, "kin_http_request_duration_seconds_count", method="POST", route=route) \
        - _sample(before, "kin_http_request_duration_seconds_count", method="POST", route=route) == 4
    assert "/v1/robots/ur5/fk" not in after  # raw paths would be unbounded label values


def test_ik_solve_time_by_structure_and_solutions_per_target(client):
    before = client.get("/metrics").text
    target = {"matrix": [[0, 1, 0, -0.154], [0, 0, 1, 0.763], [1, 0, 0, 0], [0, 0, 0, 1]]}
    body = client.post("/v1/robots/spong_ex3_5_stanford/ik", json={"target": target, "filter_limits": False}).json()
    structure = body["solver"]["structure"]
    after = client.get("/metrics").text
    assert _sample(after, "kin_ik_solve_seconds_count", method="analytic", structure=structure) \
        - _sample(before, "kin_ik_solve_seconds_count", method="analytic", structure=structure) == 1
    found = len(body["solutions"]) + len(body["rejected"])
    assert found >= 1
    assert _sample(after, "kin_ik_solutions_sum", structure=structure) \
        - _sample(before, "kin_ik_solutions_sum", structure=structure) >= 1


# --------------------------------------------------------------------------- readiness


def test_readiness_is_503_until_the_catalogue_is_loaded():
    app = create_app(Settings(_env_file=None))
    not_started = TestClient(app)  # no `with`: the lifespan (catalogue loading) has not run
    assert not_started.get("/healthz").status_code == 200
    assert_problem(not_started.get("/readyz"), 503, match="not loaded")
    assert_problem(not_started.get("/v1/robots"), 503)
    with TestClient(app) as started:
        ready = started.get("/readyz")
        assert ready.status_code == 200
        files = [p for p in BUILTIN_ROBOTS_DIR.iterdir() if p.suffix in (".yaml", ".yml", ".json")]
        assert ready.json() == {"status": "ready", "robots": len(files), "in_flight": 0}


def test_readiness_is_503_once_shutdown_begins_and_200_again_after_a_new_start_up():
    app = create_app(Settings(_env_file=None))
    with TestClient(app) as client:
        assert client.get("/readyz").status_code == 200
    stopped = TestClient(app)  # the lifespan's shutdown has run
    assert_problem(stopped.get("/readyz"), 503, match="shutting down")
    assert stopped.get("/healthz").status_code == 200
    with TestClient(app) as client:  # started again (tests do): ready again
        assert client.get("/readyz").status_code == 200


def test_a_bad_robot_file_keeps_the_service_from_becoming_ready(tmp_path):
    (tmp_path / "broken.yaml").write_text("id: broken\nconvention: standard\njoints: []\n")
    app = create_app(Settings(_env_file=None, robots_dir=tmp_path))
    with pytest.raises(Exception, match="broken.yaml"):
        with TestClient(app):
            pass
    assert_problem(TestClient(app).get("/readyz"), 503)


# --------------------------------------------------------------------------- several workers, live


def test_several_workers_serve_and_metrics_add_up_across_them(tmp_path):
    """KIN_WORKERS=2: two worker processes, each writing its samples to the multiprocess directory, and
    /metrics (answered by whichever worker) counts every request exactly once."""
    with serve(KIN_WORKERS="2", PROMETHEUS_MULTIPROC_DIR=str(tmp_path)) as base_url:
        time.sleep(1.0)  # let the second worker finish its start-up too
        children = Path(f"/proc/{serve.pid}/task/{serve.pid}/children").read_text().split()
        assert len(children) >= 2  # the workers (uvicorn may add a helper process)
        assert {p.stem.rsplit("_", 1)[1] for p in tmp_path.glob("histogram_*.db")} <= set(children)
        for _ in range(40):
            assert get(f"{base_url}/v1/robots")[0] == 200
        counts = set()
        for _ in range(6):
            status, text, _ = get(f"{base_url}/metrics")
            assert status == 200
            counts.add(_sample(text, "kin_http_requests_total", method="GET", route="/v1/robots", status="200"))
        assert counts == {40.0}
        assert len(list(tmp_path.glob("counter_*.db"))) >= 1


def test_a_log_line_is_json_whatever_its_fields_hold():
    """Every record is one line of valid JSON: a non-finite float as null (the standard encoder wrote NaN, which
    JSON has not), non-ASCII text as it is, an object through str, an integer beyond 64 bits as its digits."""
    record = logging.LogRecord("service.test", logging.WARNING, __file__, 1, "ünïcode %s", ("ok",), None)
    record.fields = {"residual": float("nan"), "limit": float("inf"), "robot": "Roboter-Arm Ω", "path": Path("/x"),
                     "count": 7}
    line = JsonFormatter().format(record)
    assert "\n" not in line
    entry = json.loads(line, parse_constant=lambda name: pytest.fail(f"{name} is not JSON"))
    assert entry["residual"] is None and entry["limit"] is None and entry["count"] == 7
    assert entry["robot"] == "Roboter-Arm Ω" and entry["msg"] == "ünïcode ok" and entry["path"] == "/x"
    assert entry["level"] == "warning" and entry["logger"] == "service.test"
    record.fields = {"huge": 2 ** 70}
    assert json.loads(JsonFormatter().format(record))["huge"] == 2 ** 70
