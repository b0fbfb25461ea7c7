"""API key, CORS, robot ids that never reach the filesystem, and YAML read only with safe_load."""

from __future__ import annotations

import ast
import builtins
import io
import pathlib
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from service.api import security
from service.api.app import create_app
from service.robots.catalogue import CatalogueError, load_robot_file
from service.config import Settings
from tests.conftest import assert_problem

ROOT = Path(__file__).resolve().parents[2]
KEY = "s3cret-key-for-tests"


@pytest.fixture(scope="module")
def keyed():
    with TestClient(create_app(Settings(_env_file=None, api_key=KEY))) as test_client:
        yield test_client


# --------------------------------------------------------------------------- API key


@pytest.mark.parametrize(("method", "path"), [
    ("get", "/v1/robots"), ("get", "/v1/robots/ur5"), ("post", "/v1/robots/ur5/fk"), ("post", "/v1/fk"),
    ("post", "/v1/robots/ur5/ik"), ("post", "/v1/limits"), ("get", "/v1/no-such-route"),
])
def test_every_v1_route_needs_the_key(keyed, method, path):
    missing = assert_problem(getattr(keyed, method)(path), 401, match="X-API-Key")
    assert missing["type"].endswith("/unauthorized")
    wrong = getattr(keyed, method)(path, headers={"X-API-Key": KEY[:-1] + "X"})
    assert_problem(wrong, 401, match="not valid")
    assert wrong.headers["www-authenticate"] == 'ApiKey header="X-API-Key"'


def test_the_right_key_is_served(keyed):
    response = keyed.post("/v1/robots/spong_ex3_1_planar_rr/fk", json={"joints": [0.0, 0.0]},
                          headers={"X-API-Key": KEY})
    assert response.status_code == 200
    assert response.json()["pose"]["position"] == pytest.approx([1.5, 0, 0])


def test_the_key_is_checked_before_the_body_is_read(keyed):
    """An unauthenticated client learns nothing about validation, and a big body is not even read."""
    assert_problem(keyed.post("/v1/fk", content=b"{not json", headers={"content-type": "application/json"}), 401)


@pytest.mark.parametrize("path", ["/healthz", "/readyz", "/metrics"])
def test_health_and_metrics_stay_open(keyed, path):
    assert keyed.get(path).status_code == 200


def test_without_a_key_configured_v1_is_open(client):
    assert client.get("/v1/robots").status_code == 200


def test_an_empty_key_setting_does_not_turn_the_check_on(monkeypatch):
    monkeypatch.setenv("KIN_API_KEY", "")
    assert Settings().api_key is None


def test_the_key_is_compared_in_constant_time():
    """The comparison is hmac.compare_digest, on bytes; no == on the secret anywhere in the module."""
    source = Path(security.__file__).read_text(encoding="utf-8")
    assert "hmac.compare_digest(provided, self._expected)" in source
    tree = ast.parse(source)
    compared = [ast.unparse(node) for node in ast.walk(tree) if isinstance(node, ast.Compare)
                and "_expected" in ast.unparse(node)]
    assert compared == []


def test_the_spec_declares_the_key_scheme_on_v1_only(client):
    spec = client.app.openapi()
    assert spec["components"]["securitySchemes"]["ApiKeyHeader"] == {
        "type": "apiKey", "in": "header", "name": "X-API-Key",
        "description": spec["components"]["securitySchemes"]["ApiKeyHeader"]["description"]}
    for path, operations in spec["paths"].items():
        for operation in operations.values():
            if path.startswith("/v1/"):
                assert operation["security"] == [{"ApiKeyHeader": []}]
                assert "401" in operation["responses"]
            else:
                assert "security" not in operation


# --------------------------------------------------------------------------- CORS


def _preflight(test_client, origin: str):
    return test_client.options("/v1/robots", headers={"Origin": origin, "Access-Control-Request-Method": "GET"})


def test_cors_is_off_by_default(client):
    response = _preflight(client, "https://app.example")
    assert "access-control-allow-origin" not in response.headers
    assert "access-control-allow-origin" not in client.get("/v1/robots", headers={"Origin": "https://app.example"}).headers


def test_cors_allows_only_the_configured_origins():
    settings = Settings(_env_file=None, cors_origins="https://app.example", api_key=KEY)
    with TestClient(create_app(settings)) as test_client:
        allowed = _preflight(test_client, "https://app.example")
        assert allowed.status_code == 200  # a preflight carries no key, and needs none
        assert allowed.headers["access-control-allow-origin"] == "https://app.example"
        assert "x-api-key" in allowed.headers["access-control-allow-headers"].lower()
        denied = _preflight(test_client, "https://evil.example")
        assert "access-control-allow-origin" not in denied.headers
        simple = test_client.get("/v1/robots", headers={"Origin": "https://app.example", "X-API-Key": KEY})
        assert simple.headers["access-control-allow-origin"] == "https://app.example"
        assert "x-request-id" in simple.headers["access-control-expose-headers"].lower()


def test_cors_origins_come_from_a_comma_separated_variable(monkeypatch):
    monkeypatch.setenv("KIN_CORS_ORIGINS", "https://a.example, https://b.example")
    assert Settings().cors_origins == ["https://a.example", "https://b.example"]


# --------------------------------------------------------------------------- robot ids


@pytest.mark.parametrize("robot_id", ["ur5.yaml", "UR5", "-ur5", "ur5%00", "ur5 ", "a" * 65])
def test_robot_ids_outside_the_pattern_are_422(client, robot_id):
    assert_problem(client.get(f"/v1/robots/{robot_id}"), 422, loc=["path", "robot_id"])


@pytest.mark.parametrize("path", ["/v1/robots/../../etc/passwd", "/v1/robots/..%2F..%2Fetc%2Fpasswd",
                                  "/v1/robots/%2Fetc%2Fpasswd"])
def test_path_traversal_never_reaches_a_file(client, path):
    response = client.get(path)
    assert response.status_code == 404  # a decoded "/" leaves no route that matches: no lookup, no file
    assert "root:" not in response.text


def test_requests_never_read_a_file(client, monkeypatch):
    """After start-up the catalogue is in memory: a request for any id, known or not, opens no file."""
    def refuse(*args, **kwargs):
        raise AssertionError(f"a request opened a file: {args[:1]}")

    monkeypatch.setattr(builtins, "open", refuse)
    monkeypatch.setattr(io, "open", refuse)
    monkeypatch.setattr(pathlib.Path, "open", refuse)
    monkeypatch.setattr(pathlib.Path, "read_text", refuse)
    monkeypatch.setattr(pathlib.Path, "read_bytes", refuse)
    assert client.get("/v1/robots/ur5").status_code == 200
    assert client.get("/v1/robots/etc-passwd").status_code == 404
    assert client.post("/v1/robots/ur5/fk", json={"joints": [0.0] * 6}).status_code == 200


# --------------------------------------------------------------------------- YAML


def test_yaml_is_only_read_with_safe_load():
    """No yaml.load / unsafe_load / full_load / Loader= anywhere in the service's source."""
    offenders = []
    for path in (ROOT / "service").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "yaml":
                if node.attr not in ("safe_load", "YAMLError"):
                    offenders.append(f"{path.relative_to(ROOT)}:{node.lineno}: yaml.{node.attr}")
            if isinstance(node, ast.keyword) and node.arg == "Loader":
                offenders.append(f"{path.relative_to(ROOT)}:{node.lineno}: Loader=")
    assert offenders == []
    assert "yaml.safe_load(" in (ROOT / "service" / "robots" / "catalogue.py").read_text(encoding="utf-8")


def test_a_robot_file_with_a_python_tag_is_refused(tmp_path):
    marker = tmp_path / "pwned"
    evil = tmp_path / "evil.yaml"
    evil.write_text(f"!!python/object/apply:os.system ['touch {marker}']\n")
    with pytest.raises(CatalogueError, match="evil.yaml"):
        load_robot_file(evil, max_joints=32)
    assert not marker.exists()
