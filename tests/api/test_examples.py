"""The spec's examples run: every request example is answered with a 2xx, every response example is what the
service answers to its operation's first request example, and every schema and property is described."""

from __future__ import annotations

import math

import pytest

from service.api.examples import REQUEST_EXAMPLES, response_examples, trimmed
from service.openapi import current_spec

SPEC = current_spec()


def _operations():
    for path, operations in SPEC["paths"].items():
        for method, operation in operations.items():
            yield path, method, operation


def _request_examples():
    for path, method, operation in _operations():
        media = operation.get("requestBody", {}).get("content", {}).get("application/json", {})
        for name, example in media.get("examples", {}).items():
            yield pytest.param(path, method, example, id=f"{operation['operationId']}:{name}")


def test_every_operation_with_a_body_has_examples_and_so_has_its_schema():
    schemas = SPEC["components"]["schemas"]
    for path, method, operation in _operations():
        if "requestBody" not in operation:
            continue
        media = operation["requestBody"]["content"]["application/json"]
        assert media.get("examples"), f"{method} {path} has no request example"
        name = media["schema"]["$ref"].rsplit("/", 1)[-1]
        assert schemas[name].get("examples"), f"schema {name} has no example"
        if "{robot_id}" in path:
            for example in media["examples"].values():
                assert example["x-robot-id"], f"{method} {path}: example without x-robot-id"


def test_the_examples_cover_the_catalogue_cases_the_docs_promise():
    robots = {e.get("x-robot-id") for examples in REQUEST_EXAMPLES.values() for e in examples.values()}
    assert {"ur5", "puma560_standard", "spong_ex3_1_planar_rr", "assur001_scara_rrp"} <= robots
    values = [e["value"] for examples in REQUEST_EXAMPLES.values() for e in examples.values()]
    assert any("targets" in v for v in values) and any("samples" in v for v in values)  # a batch, a trajectory
    assert any(v.get("target", {}).keys() == {"position"} for v in values)  # a position-only target


@pytest.mark.parametrize("path, method, example", list(_request_examples()))
def test_every_request_example_is_answered_with_a_2xx(client, path, method, example):
    url = path.replace("{robot_id}", example.get("x-robot-id", ""))
    response = client.request(method.upper(), url, json=example["value"])
    assert 200 <= response.status_code < 300, response.text
    if response.headers["content-type"].startswith("application/json"):
        body = response.json()
        if "status" in body and "solutions" in body:
            assert body["status"] == "ok" and body["solutions"], "an IK example should find solutions"


def _close(committed, answered, where="") -> None:
    if isinstance(committed, dict):
        assert isinstance(answered, dict) and committed.keys() == answered.keys(), where
        for key in committed:
            _close(committed[key], answered[key], f"{where}.{key}")
    elif isinstance(committed, list):
        assert isinstance(answered, list) and len(committed) == len(answered), where
        for index, (a, b) in enumerate(zip(committed, answered)):
            _close(a, b, f"{where}[{index}]")
    elif isinstance(committed, float) and isinstance(answered, (int, float)):
        assert math.isclose(committed, answered, abs_tol=1e-6), f"{where}: {committed} != {answered}"
    else:
        assert committed == answered, f"{where}: {committed!r} != {answered!r}"


def test_every_main_response_has_an_example_that_is_the_service_answer(client):
    answers = response_examples()
    for path, method, operation in _operations():
        ok = operation["responses"]["200"]["content"].get("application/json")
        if ok is None or path == "/metrics":
            continue
        operation_id = operation["operationId"]
        assert "example" in ok, f"{operation_id} has no response example"
        examples = REQUEST_EXAMPLES.get(operation_id)
        first = next(iter(examples.values())) if examples else {}
        robot_id = first.get("x-robot-id") or "ur5"
        response = client.request(method.upper(), path.replace("{robot_id}", robot_id), json=first.get("value"))
        assert response.status_code == 200
        _close(answers[operation_id], trimmed(response.json()), operation_id)


def test_every_schema_and_every_property_is_described():
    undescribed = []
    for name, schema in SPEC["components"]["schemas"].items():
        if not schema.get("description", "").strip():
            undescribed.append(name)
        for prop, value in schema.get("properties", {}).items():
            if not value.get("description", "").strip():
                undescribed.append(f"{name}.{prop}")
    assert undescribed == []


def test_every_operation_and_parameter_is_described():
    for path, method, operation in _operations():
        assert operation.get("description") or operation.get("summary"), f"{method} {path}"
        for parameter in operation.get("parameters", []):
            assert parameter.get("description"), f"{method} {path}: {parameter['name']}"
