"""Hostile input: every case is a 4xx problem document that names the field, never a 5xx or a wrong answer."""

from __future__ import annotations

import json
import time

import numpy as np
import pytest
from fastapi.testclient import TestClient

from service.api.app import create_app
from service.api.schemas.common import MAX_MAGNITUDE
from service.config import Settings
from service.openapi import current_spec
from tests.conftest import assert_problem

PLANAR = {"convention": "standard", "joints": [{"a": 1.0}, {"a": 0.5}]}
POSE = {"position": [0.4, 0.1, 0.3], "orientation": {"type": "quaternion", "wxyz": [0, 1, 0, 0]}}


def _raw(client, path: str, text: str):
    return client.post(path, content=text.encode(), headers={"content-type": "application/json"})


# --------------------------------------------------------------------------- NaN and infinity, anywhere

NON_FINITE_CASES = [
    ("/v1/fk", '{"joints": [%s, 0], "robot": %s}', ["body", "joints", 0]),
    ("/v1/fk", '{"joints": [0, 0], "robot": {"convention": "standard", "joints": [{"a": %s}, {"a": 1}]}}%s',
     ["body", "robot", "joints", 0, "a"]),
    ("/v1/fk", '{"joints": [0, 0], "robot": {"convention": "standard", "joints": [{}, {}], '
               '"base": [[1, 0, 0, %s], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}}%s',
     ["body", "robot", "base", 0, 3]),
    ("/v1/fk", '{"joints": [0, 0], "robot": {"convention": "standard", "joints": [{}, {}], '
               '"tool": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, %s], [0, 0, 0, 1]]}}%s',
     ["body", "robot", "tool", 2, 3]),
    ("/v1/fk", '{"joints": [0, 0], "robot": {"convention": "khalil", "joints": [{"r": %s}, {}]}}%s',
     ["body", "robot", "joints", 0, "r"]),
    ("/v1/fk", '{"joints": [0, 0], "robot": {"convention": "standard", '
               '"joints": [{"limits": {"lower": %s, "upper": 1}}, {}]}}%s',
     ["body", "robot", "joints", 0, "limits", "lower"]),
    ("/v1/ik", '{"target": {"position": [1, %s, 0]}, "robot": %s}', ["body", "target", "position", 1]),
    ("/v1/ik", '{"target": {"matrix": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, %s], [0, 0, 0, 1]]}, "robot": %s}',
     ["body", "target", "matrix", 2, 3]),
    ("/v1/ik", '{"target": {"position": [1, 0, 0], "orientation": {"type": "quaternion", "wxyz": [%s, 0, 0, 0]}}, '
               '"robot": %s}', ["body", "target", "orientation", "wxyz", 0]),
    ("/v1/ik", '{"target": {"position": [1, 0, 0], "orientation": {"type": "rpy", "angles": [0, %s, 0]}}, '
               '"robot": %s}', ["body", "target", "orientation", "angles", 1]),
    ("/v1/ik", '{"target": {"position": [1, 0, 0]}, "reference": [0, %s], "robot": %s}', ["body", "reference", 1]),
    ("/v1/ik", '{"target": {"position": [1, 0, 0]}, "ordering": {"weights": [1, %s]}, "robot": %s}',
     ["body", "ordering", "weights", 1]),
    ("/v1/limits", '{"joints": [[0, %s]], "robot": %s}', ["body", "joints", 0, 1]),
    ("/v1/limits", '{"joints": [[0, 0]], "limits": [{"lower": 0, "upper": %s}, null], "robot": %s}',
     ["body", "limits", 0, "upper"]),
]


@pytest.mark.parametrize("token", ["NaN", "Infinity", "-Infinity"])
@pytest.mark.parametrize(("path", "template", "loc"), NON_FINITE_CASES)
def test_nan_and_infinity_anywhere_are_422_naming_the_field(client, token, path, template, loc):
    text = template % (token, json.dumps(PLANAR)) if template.count("%s") == 2 and '"robot": %s' in template \
        else template % (token, "")
    assert_problem(_raw(client, path, text), 422, loc=loc)


def test_every_request_number_in_the_spec_is_bounded():
    """Every number a request can carry (in any schema a request body reaches) declares the ±1e6 bound, so a
    router that adds a field with a plain float (a twist, say) fails here instead of letting 1e308 through."""
    spec = current_spec()
    schemas = spec["components"]["schemas"]
    seen: set[str] = set()
    unbounded: list[str] = []

    def walk(node, where: str) -> None:
        if isinstance(node, dict):
            ref = node.get("$ref")
            if ref:
                name = ref.rsplit("/", 1)[-1]
                if name not in seen:
                    seen.add(name)
                    walk(schemas[name], name)
                return
            if node.get("type") in ("number", "integer") and "enum" not in node and "const" not in node:
                if "maximum" not in node and "exclusiveMaximum" not in node:
                    unbounded.append(where)
            for key, value in node.items():
                walk(value, f"{where}.{key}")
        elif isinstance(node, list):
            for index, value in enumerate(node):
                walk(value, f"{where}[{index}]")

    for path, operations in spec["paths"].items():
        for method, operation in operations.items():
            body = operation.get("requestBody")
            if body:
                walk(body, f"{method.upper()} {path}")
    assert len(seen) > 10
    assert unbounded == []


# --------------------------------------------------------------------------- magnitudes


@pytest.mark.parametrize(("path", "body", "loc"), [
    ("/v1/fk", {"joints": [1e308, 0], "robot": PLANAR}, ["body", "joints", 0]),
    ("/v1/fk", {"joints": [0, -1e308], "robot": PLANAR}, ["body", "joints", 1]),
    ("/v1/fk", {"joints": [0, 0], "robot": {"convention": "standard", "joints": [{"a": 1e308}, {"d": 1.0}]}},
     ["body", "robot", "joints", 0, "a"]),
    ("/v1/fk", {"joints": [0, 0], "robot": {**PLANAR, "base": [[1, 0, 0, 1e308], [0, 1, 0, 0], [0, 0, 1, 0],
                                                             [0, 0, 0, 1]]}},
     ["body", "robot", "base", 0, 3]),
    ("/v1/ik", {"target": {"position": [1e308, 0, 0]}, "robot": PLANAR}, ["body", "target", "position", 0]),
    ("/v1/limits", {"joints": [[1e300, 0]], "robot": PLANAR}, ["body", "joints", 0, 0]),
    ("/v1/robots/ur5/ik", {"target": POSE, "max_joint_move": 1e308, "reference": [0] * 6}, ["body", "max_joint_move"]),
])
def test_absurd_magnitudes_are_422_naming_the_field(client, path, body, loc):
    problem = assert_problem(client.post(path, json=body), 422, loc=loc)
    assert "1000000" in problem["detail"]


def test_the_magnitude_bound_itself_is_accepted_and_answered_exactly(client):
    """At ±1e6 (a prismatic joint of a 1e6-long arm) FK is still finite and exact: the bound is not an overflow."""
    robot = {"convention": "standard", "joints": [{"type": "prismatic", "a": MAX_MAGNITUDE}, {"a": MAX_MAGNITUDE}]}
    response = client.post("/v1/fk", json={"joints": [MAX_MAGNITUDE, 0.5], "robot": robot})
    assert response.status_code == 200, response.text
    x, y, z = response.json()["pose"]["position"]
    assert (x, y, z) == pytest.approx((MAX_MAGNITUDE + MAX_MAGNITUDE * np.cos(0.5), MAX_MAGNITUDE * np.sin(0.5),
                                       MAX_MAGNITUDE), rel=1e-15)


def test_a_huge_revolute_angle_within_the_bound_keeps_its_limits_answer_exact(client):
    """q = 1e6 rad is within the bound; its 2π-equivalent within [-π, π] is still exact to the tolerance."""
    robot = {"convention": "standard", "joints": [{"a": 1.0, "limits": {"lower": -np.pi, "upper": np.pi}}]}
    response = client.post("/v1/limits", json={"joints": [[1e6]], "robot": robot})
    assert response.status_code == 200, response.text
    equivalent = response.json()["results"][0]["equivalent"][0]
    assert equivalent == pytest.approx(np.remainder(1e6 + np.pi, 2 * np.pi) - np.pi, abs=1e-9)


# --------------------------------------------------------------------------- types, tags, shapes


@pytest.mark.parametrize("value", ["1.0", True, None, [0.1], {"value": 1}])
def test_anything_but_a_number_where_a_number_belongs_is_422(client, value):
    assert_problem(client.post("/v1/fk", json={"joints": [value, 0.0], "robot": PLANAR}), 422,
                   loc=["body", "joints", 0])


@pytest.mark.parametrize(("body", "loc"), [
    ({"target": {"position": [1, 0, 0], "orientation": {"type": "axis_angle", "axis": [1, 0, 0]}}, "robot": PLANAR},
     ["body", "target", "orientation"]),
    ({"target": {"position": [1, 0, 0]}, "robot": {"convention": "denavit", "joints": [{}]}}, ["body", "robot"]),
    ({"target": {"position": [1, 0, 0]}, "robot": {"convention": "standard", "joints": [{"type": "spherical"}]}},
     ["body", "robot", "joints", 0, "type"]),
    ({"target": {"position": [1, 0, 0]}, "robot": PLANAR, "angle_unit": "grad"}, ["body", "angle_unit"]),
])
def test_unknown_type_tags_are_422(client, body, loc):
    assert_problem(client.post("/v1/ik", json=body), 422, loc=loc)


@pytest.mark.parametrize(("path", "body", "loc"), [
    ("/v1/robots/ur5/fk", {"joints": [0.0] * 5}, ["body", "joints"]),
    ("/v1/robots/ur5/fk", {"joints": [0.0] * 100_000}, ["body", "joints"]),
    ("/v1/robots/ur5/fk", {"joints": []}, ["body", "joints"]),
    ("/v1/robots/ur5/fk/batch", {"joints": [[0.0] * 6, [0.0] * 7]}, ["body", "joints", 1]),
    ("/v1/robots/ur5/fk/batch", {"joints": []}, ["body", "joints"]),
    ("/v1/robots/ur5/ik/batch", {"targets": []}, ["body", "targets"]),
    ("/v1/robots/ur5/limits", {"joints": []}, ["body", "joints"]),
    ("/v1/robots/ur5/limits", {"joints": [[0.0] * 6], "limits": [None] * 5}, ["body", "limits"]),
    ("/v1/robots/ur5/ik", {"target": POSE, "reference": [0.0] * 5}, ["body", "reference"]),
    ("/v1/robots/ur5/ik", {"target": POSE, "ordering": {"weights": [1.0] * 7}}, ["body", "ordering", "weights"]),
    ("/v1/robots/ur5/ik", {"target": {"position": [0.4, 0.1]}}, ["body", "target", "position"]),
    ("/v1/robots/ur5/ik", {"target": {"matrix": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]}},
     ["body", "target", "matrix"]),
])
def test_wrong_joint_counts_and_empty_or_huge_arrays_are_422(client, path, body, loc):
    assert_problem(client.post(path, json=body), 422, loc=loc)


# --------------------------------------------------------------------------- rotations


@pytest.mark.parametrize(("body", "loc", "match"), [
    ({"target": {"matrix": [[1, 0, 0, 0], [0, -1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}},
     ["body", "target", "matrix"], "determinant -1"),
    ({"target": {"matrix": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1.01, 0], [0, 0, 0, 1]]}},
     ["body", "target", "matrix"], "not orthonormal"),
    ({"target": {"matrix": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]]}},
     ["body", "target", "matrix"], None),
    ({"target": {"position": [0.4, 0, 0.3], "orientation": {"type": "matrix",
                                                            "matrix": [[-1, 0, 0], [0, 1, 0], [0, 0, 1]]}}},
     ["body", "target", "orientation", "matrix"], "determinant -1"),
    ({"target": {"position": [0.4, 0, 0.3], "orientation": {"type": "matrix",
                                                            "matrix": [[1, 1e-5, 0], [0, 1, 0], [0, 0, 1]]}}},
     ["body", "target", "orientation", "matrix"], "not orthonormal"),
    ({"target": {"position": [0.4, 0, 0.3], "orientation": {"type": "quaternion", "wxyz": [1, 1, 0, 0]}}},
     ["body", "target", "orientation", "wxyz"], "norm 1"),
    ({"target": {"position": [0.4, 0, 0.3], "orientation": {"type": "quaternion", "wxyz": [0, 0, 0, 0]}}},
     ["body", "target", "orientation", "wxyz"], None),
])
def test_rotations_that_are_not_rotations_are_422(client, body, loc, match):
    assert_problem(client.post("/v1/robots/ur5/ik", json=body), 422, loc=loc, match=match)


@pytest.mark.parametrize("field", ["base", "tool"])
def test_base_and_tool_must_be_rigid_transforms(client, field):
    reflection = [[1, 0, 0, 0], [0, -1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
    assert_problem(client.post("/v1/fk", json={"joints": [0, 0], "robot": {**PLANAR, field: reflection}}), 422,
                   loc=["body", "robot", field], match="determinant -1")


# --------------------------------------------------------------------------- robots and limits


def test_a_robot_with_no_joints_is_422(client):
    assert_problem(client.post("/v1/fk", json={"joints": [], "robot": {"convention": "standard", "joints": []}}),
                   422, loc=["body", "robot", "joints"])


def test_a_robot_over_the_joint_maximum_is_422_and_at_the_maximum_is_fine():
    with TestClient(create_app(Settings(_env_file=None, max_joints=7))) as small:  # the catalogue has 7 at most
        too_many = {"convention": "standard", "joints": [{"a": 0.1}] * 8}
        assert_problem(small.post("/v1/fk", json={"joints": [0] * 8, "robot": too_many}), 422,
                       loc=["body", "robot", "joints"], match="at most 7 joints")
        enough = {"convention": "standard", "joints": [{"a": 0.1}] * 7}
        response = small.post("/v1/fk", json={"joints": [0] * 7, "robot": enough})
        assert response.status_code == 200
        assert response.json()["pose"]["position"] == pytest.approx([0.7, 0, 0])


@pytest.mark.parametrize(("path", "body", "loc"), [
    ("/v1/fk", {"joints": [0, 0], "robot": {"convention": "standard",
                                            "joints": [{"limits": {"lower": 2, "upper": 1}}, {}]}},
     ["body", "robot", "joints", 0, "limits"]),
    ("/v1/limits", {"joints": [[0, 0]], "limits": [None, {"lower": 1, "upper": -1}], "robot": PLANAR},
     ["body", "limits", 1]),
    ("/v1/robots/ur5/ik", {"target": POSE, "limits": [{"lower": 3, "upper": 2}] + [None] * 5}, ["body", "limits", 0]),
])
def test_limits_with_lower_above_upper_are_422(client, path, body, loc):
    assert_problem(client.post(path, json=body), 422, loc=loc, match="greater than upper")


def test_an_open_limit_side_is_null_in_a_violation_not_a_server_error(client):
    robot = {"convention": "standard", "joints": [{"type": "prismatic", "limits": {"lower": None, "upper": 1.0}}]}
    response = client.post("/v1/limits", json={"joints": [[5.0]], "robot": robot})
    assert response.status_code == 200, response.text
    assert response.json()["results"][0]["violations"] == [{"joint": 0, "value": 5.0, "lower": None, "upper": 1.0}]


# --------------------------------------------------------------------------- sizes


@pytest.fixture(scope="module")
def small_limits_client():
    with TestClient(create_app(Settings(_env_file=None, max_body_bytes=2048, max_batch=3))) as test_client:
        yield test_client


def test_a_body_over_the_maximum_is_413_before_parsing(small_limits_client):
    # Not even JSON: were it parsed, the answer would be 422; the size is refused first.
    response = small_limits_client.post("/v1/fk", content=b"x" * 4096, headers={"content-type": "application/json"})
    problem = assert_problem(response, 413, match="2048 bytes")
    assert problem["type"].endswith("/payload-too-large")


def test_a_chunked_body_over_the_maximum_is_413(small_limits_client):
    def chunks():
        for _ in range(8):
            yield b"[" * 512

    response = small_limits_client.post("/v1/fk", content=chunks(), headers={"content-type": "application/json"})
    assert "content-length" not in response.request.headers
    assert response.request.headers["transfer-encoding"] == "chunked"
    assert_problem(response, 413, match="KIN_MAX_BODY_BYTES")


def test_a_chunked_body_under_the_maximum_is_served(small_limits_client):
    body = json.dumps({"joints": [0.5, -0.7], "robot": PLANAR}).encode()

    def chunks():
        yield body[:10]
        yield body[10:]

    response = small_limits_client.post("/v1/fk", content=chunks(), headers={"content-type": "application/json"})
    assert response.status_code == 200, response.text
    assert response.json()["pose"]["position"][0] == pytest.approx(np.cos(0.5) + 0.5 * np.cos(-0.2))


@pytest.mark.parametrize(("path", "body"), [
    ("/v1/robots/ur5/fk/batch", {"joints": [[0.0] * 6] * 4}),
    ("/v1/robots/ur5/ik/batch", {"targets": [POSE] * 4}),
    ("/v1/robots/ur5/limits", {"joints": [[0.0] * 6] * 4}),
    ("/v1/limits", {"joints": [[0.0, 0.0]] * 4, "robot": PLANAR}),
])
def test_a_batch_over_the_maximum_is_413(small_limits_client, path, body):
    problem = assert_problem(small_limits_client.post(path, json=body), 413, match="at most 3")
    field = "targets" if "targets" in body else "joints"  # the field at fault, located as a 422's are
    assert [error["loc"] for error in problem["errors"]] == [["body", field]]
    body_at_limit = {key: value[:3] if isinstance(value, list) else value for key, value in body.items()}
    assert small_limits_client.post(path, json=body_at_limit).status_code == 200


def test_a_body_that_is_not_utf8_is_422_not_400(client):
    response = client.post("/v1/fk", content=b"\xff\xfe\x00{", headers={"content-type": "application/json"})
    assert_problem(response, 422, loc=["body"])


# --------------------------------------------------------------------------- the numeric search's time budget

# Four skew revolute joints and two slides: no closed-form family or general solver covers it, so the numeric
# search answers (every 6R arm, and every 6-joint arm with one slide, is solved by the general solver, and a 7R
# one by locking a joint).
NUMERIC_ARM = {"convention": "modified", "joints": [
    {"type": kind, "a": a, "alpha": alpha, "d": d}
    for kind, a, alpha, d in zip(["revolute"] * 4 + ["prismatic"] * 2,
                                 [0.05, 0.3, 0.07, 0.25, 0.04, 0.06],
                                 [0.5, -0.9, 1.1, 0.7, -1.3, 0.4], [0.2, 0.1, -0.15, 0.3, 0.05, 0.1])]}


def test_the_server_caps_the_numeric_time_and_refuses_past_it():
    """An arm no family covers: the numeric search runs, the client asks for 10 s,
    the server allows 20 ms per request: the search stops there and the answer is a 503 that names the cap, not a
    partial search."""
    target = {"position": [0.3, 0.2, 0.5], "orientation": {"type": "rpy", "angles": [0.3, 0.2, 0.1]}}
    with TestClient(create_app(Settings(_env_file=None, max_ik_time_ms=20))) as capped:
        started = time.perf_counter()
        response = capped.post("/v1/ik", json={"target": target, "robot": NUMERIC_ARM,
                                               "numeric": {"starts": 2000, "time_budget_ms": 10_000}})
        elapsed = time.perf_counter() - started
    assert_problem(response, 503, match="deadline of 20 ms during the numeric search")
    assert response.headers["retry-after"] == "1"
    assert elapsed < 2.0


def test_a_batch_shares_the_servers_numeric_time(tmp_path):
    """Four targets in one batch, a 40 ms cap per request: the batch as a whole gets 40 ms."""
    (tmp_path / "numeric_arm.json").write_text(json.dumps({"id": "numeric_arm", **NUMERIC_ARM}))
    target = {"position": [0.3, 0.2, 0.5], "orientation": {"type": "rpy", "angles": [0.3, 0.2, 0.1]}}
    with TestClient(create_app(Settings(_env_file=None, robots_dir=tmp_path, max_ik_time_ms=40))) as capped:
        response = capped.post("/v1/robots/numeric_arm/ik/batch",
                               json={"targets": [target] * 4, "numeric": {"starts": 2000, "time_budget_ms": 10_000}})
    assert_problem(response, 503, match="deadline of 40 ms during the numeric search")


def test_axes_rounded_1e_8_off_parallel_are_answered_not_a_500(client):
    """Axes 2 and 3 1.03e-8 rad off parallel (1 − cos² of that rounds to 0): the pose from the arm's own FK is
    answered with the configuration that made it, where the skew-axes fit once divided by zero."""
    robot = {"convention": "standard", "joints": [{"a": 0.1, "alpha": np.pi / 2, "d": 0.4},
                                                  {"a": 0.5, "alpha": 1.03e-8, "d": 0.05}, {"a": 0.4}]}
    q = [0.3, 0.7, -1.1]
    pose = client.post("/v1/fk", json={"joints": q, "robot": robot}).json()["pose"]
    response = client.post("/v1/ik", json={"target": {"position": pose["position"]}, "robot": robot})
    assert response.status_code == 200, response.text
    answer = response.json()
    assert answer["status"] == "ok"
    assert min(np.abs(np.array(s["joints"]) - q).max() for s in answer["solutions"]) < 1e-6
