"""Schema fuzzing: schemathesis over every operation of the committed spec, in-process against the ASGI app.

For each operation, up to MAX_EXAMPLES generated requests, valid and invalid ones ("positive" and "negative"
modes), derandomized so that a CI run is repeatable. Every response must: not be a 5xx; have a status code,
content type, headers and body that the spec declares for that operation; and an invalid request must be
rejected with a 4xx. The app runs with an API key, so 401 is exercised as well (schemathesis also sends
requests without the key and expects them to be refused).

Left out, on purpose: ``positive_data_acceptance``. JSON Schema cannot state the rules that make a schema-valid
body meaningful (as many joint values as the robot has joints; a rotation that is orthonormal; a 4×4 whose last
row is 0 0 0 1), so the service rightly answers 422 to many schema-valid bodies. Those answers are still checked
for a declared status and a conforming problem document.
"""

from __future__ import annotations

import json
import re

import pytest
import schemathesis
from hypothesis import HealthCheck, settings
from hypothesis import strategies as st
from schemathesis.specs.openapi.checks import positive_data_acceptance

from service.api.app import create_app
from service.robots.catalogue import load_catalogue
from service.config import BUILTIN_ROBOTS_DIR, Settings
from service.openapi import SPEC_PATH

MAX_EXAMPLES = 50
API_KEY = "schemathesis-key"

# Small limits, so that a generated batch or numeric search stays fast while the limits themselves get exercised.
app = create_app(Settings(_env_file=None, api_key=API_KEY, max_batch=64, max_ik_time_ms=50))
schema = schemathesis.openapi.from_path(SPEC_PATH)
schema.app = app
# The meaningful pass sends requests a client would: the numeric search (arms no family covers, such as a
# 5-joint arm's full pose) gets the server's default time, not the fuzzing app's 50 ms.
meaningful_schema = schemathesis.openapi.from_path(SPEC_PATH)
meaningful_schema.app = create_app(Settings(_env_file=None, api_key=API_KEY, max_batch=64))
schema.config.generation.update(modes=["positive", "negative"], max_examples=MAX_EXAMPLES, deterministic=True)


CATALOGUE_IDS = sorted(entry.description.id
                       for entry in load_catalogue([BUILTIN_ROBOTS_DIR], max_joints=32).entries())
_ROBOT_ID = re.compile(r"^[a-z0-9][a-z0-9_-]{0,63}$")


@schema.hook
def flatmap_path_parameters(context, path_parameters):
    """Half of the valid robot ids become catalogue ids, so the catalogue operations get past their 404."""
    robot_id = (path_parameters or {}).get("robot_id")
    if not isinstance(robot_id, str) or not _ROBOT_ID.match(robot_id):
        return st.just(path_parameters)
    return st.one_of(st.just(path_parameters),
                     st.sampled_from(CATALOGUE_IDS).map(lambda known: {**path_parameters, "robot_id": known}))


def test_every_operation_of_the_spec_is_fuzzed():
    """The parametrized test below covers each operation of openapi/openapi.json (no path silently dropped)."""
    operations = {(op.method.upper(), op.path) for op in (result.ok() for result in schema.get_all_operations())}
    spec = json.loads(SPEC_PATH.read_text(encoding="utf-8"))
    expected = {(method.upper(), path) for path, ops in spec["paths"].items() for method in ops}
    assert operations == expected
    assert len(expected) >= 12


@schema.parametrize()
@settings(max_examples=MAX_EXAMPLES, derandomize=True, deadline=None, database=None,
          suppress_health_check=list(HealthCheck))
def test_api_conforms_to_its_spec(case):
    case.call_and_validate(headers={"X-API-Key": API_KEY}, excluded_checks=[positive_data_acceptance])


# --------------------------------------------------------------------------- meaningful requests
# Generated bodies rarely have as many joint values as the robot has joints, so most of them (rightly) end in 422.
# To check the success responses of every operation against the spec as well, these requests are meaningful:
# joint vectors of the right length within the limits, and IK targets that FK of such a vector reaches.

import numpy as np  # noqa: E402
from hypothesis import given  # noqa: E402

from service.robots.export import screws_description  # noqa: E402
from service.kinematics import forward_kinematics, quaternions_from_matrices, rpy_from_matrix  # noqa: E402
from service.kinematics._rotations import euler_zyz_from_matrix  # noqa: E402

CATALOGUE = load_catalogue([BUILTIN_ROBOTS_DIR], max_joints=32)


def _joints(robot, rng) -> np.ndarray:
    """Radians / length unit, within the limits (or ±π, ±0.5 where a side is open)."""
    lower = np.where(np.isfinite(robot.lower), robot.lower, np.where(robot.is_revolute, -np.pi, -0.5))
    upper = np.where(np.isfinite(robot.upper), robot.upper, np.where(robot.is_revolute, np.pi, 0.5))
    return rng.uniform(lower, np.maximum(lower, upper))


def _targets(robot, q) -> list[dict]:
    """The pose FK reaches at q, in the five forms a target may take."""
    T = forward_kinematics(robot, q)
    R, p = T[:3, :3], T[:3, 3].tolist()
    return [
        {"matrix": T.tolist()},
        {"position": p, "orientation": {"type": "matrix", "matrix": R.tolist()}},
        {"position": p, "orientation": {"type": "quaternion", "wxyz": quaternions_from_matrices(R[None])[0].tolist()}},
        {"position": p, "orientation": {"type": "euler_zyz", "angles": euler_zyz_from_matrix(R)[0].tolist()}},
        {"position": p, "orientation": {"type": "rpy", "angles": rpy_from_matrix(R)[0].tolist()}},
    ]


def _samples(robot, q) -> list[dict]:
    """Three poses along a short joint-space move from q, 0.1 s apart (reachable by construction)."""
    step = np.where(robot.is_revolute, 0.01, 0.001 * robot.characteristic_length)
    poses = forward_kinematics(robot, q + np.arange(3)[:, None] * step)
    return [{"time": 0.1 * k, "pose": {"matrix": pose.tolist()}} for k, pose in enumerate(poses)]


def _meaningful_case(path: str, method: str, robot_id: str, seed: int, variant: int):
    """One request per seed; a third of them carry a per-request base and tool, and a third of the inline ones
    describe the robot by its joint screws instead of its own form."""
    entry = CATALOGUE.get(robot_id)
    robot, rng = entry.robot, np.random.default_rng(seed)
    q = _joints(robot, rng)
    inline = entry.description.model_dump(mode="json", by_alias=True)
    if seed % 3 == 1:
        inline = screws_description(entry.description, robot).model_dump(mode="json", by_alias=True)
    frames = {}
    if seed % 3 == 2:
        base, tool = np.eye(4), np.eye(4)
        base[:3, :3] = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
        base[:3, 3] = [0.1, 0.0, 0.2]
        tool[:3, 3] = [0.0, 0.0, 0.05 * robot.characteristic_length]
        frames = {"base": base.tolist(), "tool": tool.tolist()}
        robot = robot.with_frames(base, tool)
    target = _targets(robot, q)[variant]
    bodies = {
        "/v1/robots/{robot_id}/fk": {"joints": q.tolist(), "frames": bool(seed % 2)},
        "/v1/fk": {"joints": q.tolist(), "robot": inline},
        "/v1/robots/{robot_id}/fk/batch": {"joints": [q.tolist(), _joints(robot, rng).tolist()]},
        "/v1/robots/{robot_id}/ik": {"target": target, "reference": q.tolist()},
        "/v1/ik": {"target": target, "robot": inline, "reference": q.tolist()},
        "/v1/robots/{robot_id}/ik/batch": {"targets": _targets(robot, q), "reference": q.tolist()},
        "/v1/robots/{robot_id}/limits": {"joints": [q.tolist(), (q + 7.0).tolist()]},
        "/v1/limits": {"joints": [q.tolist(), (q - 7.0).tolist()], "robot": inline},
        "/v1/robots/{robot_id}/ik/trajectory": {"samples": _samples(robot, q), "reference": q.tolist()},
        "/v1/ik/trajectory": {"samples": _samples(robot, q), "reference": q.tolist(), "robot": inline},
        "/v1/robots/{robot_id}/render": {"joints": [q.tolist(), _joints(robot, rng).tolist()],
                                         "view": ("iso", "front", "side", "top", "iso")[variant]},
        "/v1/render": {"joints": [q.tolist()], "robot": inline, "captions": [f"seed {seed}"]},
    }
    bodies = {key: {**body, **frames} for key, body in bodies.items()}
    operation = meaningful_schema[path][method.upper()]
    parameters = {"robot_id": robot_id} if "{robot_id}" in path else {}
    if method.upper() == "GET":
        query = {"form": ("screws", "urdf")[seed % 2]} if "{robot_id}" in path and seed % 3 == 0 else None
        if query and query["form"] == "urdf" and "urdf" not in _exact_forms(robot_id):
            query = {"form": "screws"}
        return operation.Case(path_parameters=parameters, query=query) if query else \
            operation.Case(path_parameters=parameters)
    if path not in bodies:
        return None
    return operation.Case(path_parameters=parameters, body=bodies[path], media_type="application/json")


def _exact_forms(robot_id: str) -> set[str]:
    from service.robots.export import FormNotExact, description_in_form

    entry, forms = CATALOGUE.get(robot_id), set()
    for form in ("screws", "urdf"):
        try:
            description_in_form(entry.description, entry.robot, form)
            forms.add(form)
        except FormNotExact:
            pass
    return forms


_SPEC = json.loads(SPEC_PATH.read_text(encoding="utf-8"))
_OPERATIONS = [(path, method) for path, methods in _SPEC["paths"].items() for method in methods]


@pytest.mark.parametrize(("path", "method"), _OPERATIONS, ids=[f"{m.upper()} {p}" for p, m in _OPERATIONS])
@given(robot_id=st.sampled_from(CATALOGUE_IDS), seed=st.integers(0, 2**32 - 1), variant=st.integers(0, 4))
@settings(max_examples=20, derandomize=True, deadline=None, database=None, suppress_health_check=list(HealthCheck))
def test_meaningful_requests_succeed_and_conform(path, method, robot_id, seed, variant):
    case = _meaningful_case(path, method, robot_id, seed, variant)
    if case is None:
        pytest.skip(f"no meaningful request written for {method.upper()} {path} yet; the fuzzing above covers it")
    response = case.call_and_validate(headers={"X-API-Key": API_KEY})
    assert response.status_code == 200, response.text
    if path.endswith("/render"):
        assert response.headers["content-type"] in ("image/svg+xml", ["image/svg+xml"])  # schemathesis: a list
        assert response.text.count('class="configuration') == len(case.body["joints"])
        return
    body = response.json()
    if path.endswith("/ik") or path == "/v1/ik":
        # The target is FK of a joint vector within the limits, so it is reachable within the limits.
        assert body["status"] == "ok", body
