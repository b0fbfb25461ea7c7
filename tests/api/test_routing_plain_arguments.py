"""The small-first routes find their arguments without FastAPI's general dependency solver
(service.api.routing._PlainArguments) when the request is plain, and leave every other request to FastAPI's handler:
each request below is answered byte for byte (status, headers, body) as FastAPI's handler answers it alone."""

from __future__ import annotations

import asyncio
import json
from types import SimpleNamespace

import fastapi.routing
import numpy as np
import pytest
from fastapi.testclient import TestClient

from service.api import routing
from service.api.app import create_app
from service.api.deps import RobotRef, catalogue_robot
from service.config import Settings
from service.kinematics import forward_kinematics

PUMA_Q = [0.3, -0.4, 0.5, 0.2, -0.6, 0.9]
REQUEST_ID = {"X-Request-ID": "plain-arguments-test"}  # the same id on both sides: the answers can be compared whole


def _client(monkeypatch: pytest.MonkeyPatch | None = None) -> TestClient:
    """A client on an application of its own; with ``monkeypatch``, one whose routes never take the plain arguments
    (FastAPI's handler answers everything, as before they existed)."""
    if monkeypatch is not None:
        monkeypatch.setattr(routing._PlainArguments, "of", classmethod(lambda cls, route: None))
    return TestClient(create_app(Settings(_env_file=None, log_level="warning")))


@pytest.fixture()
def solver_calls(monkeypatch) -> list[str]:
    """The paths of the requests whose arguments FastAPI's dependency solver found."""
    calls: list[str] = []
    solve = fastapi.routing.solve_dependencies

    async def recorded(*, request, **kwargs):
        calls.append(request.url.path)
        return await solve(request=request, **kwargs)

    monkeypatch.setattr(fastapi.routing, "solve_dependencies", recorded)
    return calls


def _answers(client: TestClient, requests: list[tuple]) -> list[tuple]:
    """Each request's status, headers and body bytes (every request twice: the second finds a robot's derived data
    built, as the first may not)."""
    answers = []
    for path, kwargs in requests:
        for _ in range(2):
            response = client.post(path, **{"headers": REQUEST_ID, **kwargs})
            answers.append((path, response.status_code, sorted(response.headers.items()), response.content))
    return answers


def _puma_target() -> list[list[float]]:
    with _client() as client:
        return client.post("/v1/robots/puma560_standard/fk", json={"joints": PUMA_Q}).json()["pose"]["matrix"]


def _puma_description() -> dict:
    with _client() as client:
        return client.get("/v1/robots/puma560_standard").json()


PLAIN = [
    ("/v1/robots/puma560_standard/fk", {"json": {"joints": PUMA_Q}}),
    ("/v1/robots/PUMA560_standard/fk", {"json": {"joints": [17.0, -20.0, 30.0, 5.0, -40.0, 60.0],
                                                  "angle_unit": "deg", "frames": True}}),
    ("/v1/robots/puma560_standard/ik", {"json": {"target": {"matrix": "TARGET"}}}),
    ("/v1/robots/puma560_standard/ik", {"json": {"target": {"matrix": "TARGET"}, "reference": PUMA_Q,
                                                 "max_solutions": 2}}),
    ("/v1/fk", {"json": {"joints": PUMA_Q, "robot": "DESCRIPTION"}}),
    ("/v1/ik", {"json": {"target": {"matrix": "TARGET"}, "robot": "DESCRIPTION"}}),
]


def _filled(requests: list[tuple]) -> list[tuple]:
    target, description = _puma_target(), _puma_description()

    def fill(value):
        if value == "TARGET":
            return target
        if value == "DESCRIPTION":
            return description
        if isinstance(value, dict):
            return {key: fill(item) for key, item in value.items()}
        return value

    return [(path, {key: fill(value) for key, value in kwargs.items()}) for path, kwargs in requests]


def test_plain_requests_skip_the_solver_and_get_the_same_answers(monkeypatch, solver_calls):
    requests = _filled(PLAIN)
    solver_calls.clear()  # the GET that fetched the description
    with _client() as client:
        fast = _answers(client, requests)
    assert solver_calls == [], "a plain request went through FastAPI's dependency solver"
    with _client(monkeypatch) as client:
        reference = _answers(client, requests)
    assert len(solver_calls) == len(reference)  # the reference really is FastAPI's handler
    assert fast == reference
    assert all(status == 200 for _, status, _, _ in fast)
    # and the answers are right, not only equal: the PUMA's FK pose against the core's
    pose = next(content for path, _, _, content in fast if path == "/v1/robots/puma560_standard/fk")
    with _client() as client:
        robot = client.app.state.catalogue.get("puma560_standard").robot
    np.testing.assert_allclose(np.array(json.loads(pose)["pose"]["matrix"]),
                               forward_kinematics(robot, np.array(PUMA_Q)), atol=1e-12)


NOT_PLAIN = [
    # invalid bodies: FastAPI's 422s, its locations and messages
    ("/v1/robots/puma560_standard/fk", {"json": {"joints": "no"}}),
    ("/v1/robots/puma560_standard/fk", {"json": {}}),
    ("/v1/robots/puma560_standard/fk", {"json": [1, 2, 3]}),
    ("/v1/robots/puma560_standard/fk", {"json": {"joints": PUMA_Q, "unknown_field": 1}}),
    ("/v1/robots/puma560_standard/ik", {"json": {"target": {"matrix": [[1, 0], [0, 1]]}}}),
    # bodies orjson refuses: NaN (the standard parser's field-level 422) and malformed JSON
    ("/v1/robots/puma560_standard/fk", {"content": b'{"joints": [NaN, 0, 0, 0, 0, 0]}',
                                        "headers": {**REQUEST_ID, "Content-Type": "application/json"}}),
    ("/v1/robots/puma560_standard/fk", {"content": b'{"joints": [0, 0,',
                                        "headers": {**REQUEST_ID, "Content-Type": "application/json"}}),
    ("/v1/robots/puma560_standard/fk", {"content": b"", "headers": {**REQUEST_ID, "Content-Type": "application/json"}}),
    # other content types: FastAPI parses +json, and nothing else
    ("/v1/robots/puma560_standard/fk", {"content": b'{"joints": [0, 0, 0, 0, 0, 0]}',
                                        "headers": {**REQUEST_ID, "Content-Type": "application/problem+json"}}),
    ("/v1/robots/puma560_standard/fk", {"content": b'{"joints": [0, 0, 0, 0, 0, 0]}',
                                        "headers": {**REQUEST_ID, "Content-Type": "text/plain"}}),
    ("/v1/robots/puma560_standard/fk", {"content": b'{"joints": [0, 0, 0, 0, 0, 0]}', "headers": REQUEST_ID}),
    # the robot: unknown (404, with the nearest ids), an id its pattern refuses (422), both with a bad body
    ("/v1/robots/puma_560/fk", {"json": {"joints": PUMA_Q}}),
    ("/v1/robots/puma_560/fk", {"json": {"joints": "no"}}),
    ("/v1/robots/-bad-id/fk", {"json": {"joints": PUMA_Q}}),
    ("/v1/robots/-bad-id/fk", {"json": {"joints": "no"}}),
    # a query string: the picture, and a view that is not one
    ("/v1/robots/puma560_standard/ik?render=iso", {"json": {"target": {"matrix": "TARGET"}}}),
    ("/v1/robots/puma560_standard/ik?render=sideways", {"json": {"target": {"matrix": "TARGET"}}}),
    # errors the endpoint raises after valid arguments: the same whichever found them
    ("/v1/robots/puma560_standard/fk", {"json": {"joints": [0.0, 0.0]}}),
    ("/v1/ik", {"json": {"target": {"matrix": "TARGET"}, "robot": {"convention": "standard", "joints": []}}}),
]


def test_other_requests_are_answered_as_fastapi_answers_them(monkeypatch):
    requests = _filled(NOT_PLAIN)
    with _client() as client:
        answers = _answers(client, requests)
    with _client(monkeypatch) as client:
        reference = _answers(client, requests)
    assert answers == reference
    statuses = [status for _, status, _, _ in answers[::2]]
    assert statuses == [422, 422, 422, 422, 422, 422, 422, 422, 200, 422, 422, 404, 404, 422, 422, 200, 422, 422,
                        422]


def test_dependency_overrides_are_honoured():
    """With dependencies overridden (as tests of other modules do), FastAPI's handler finds the arguments."""
    with _client() as client:
        puma = client.app.state.catalogue.get("puma560_standard").robot

        async def always_the_puma(robot_id: str) -> RobotRef:
            return RobotRef(f"overridden-{robot_id}", puma)

        client.app.dependency_overrides[catalogue_robot] = always_the_puma
        response = client.post("/v1/robots/anything/fk", json={"joints": PUMA_Q})
    assert response.status_code == 200, response.text
    assert response.json()["robot_id"] == "overridden-anything"


def test_a_fastapi_of_other_internals_leaves_every_request_to_its_handler(monkeypatch, solver_calls):
    """The plain arguments read FastAPI's private route and field API; where it is not what they read (another
    FastAPI), the route takes FastAPI's handler: the answer is FastAPI's, never an error of the shortcut."""
    assert routing._PlainArguments.of(SimpleNamespace(dependant=SimpleNamespace(body_params=[]))) is None

    def other_internals(cls, route):
        raise AttributeError("'APIRoute' object has no attribute '_embed_body_fields'")

    monkeypatch.setattr(routing._PlainArguments, "_of", classmethod(other_internals))
    with _client() as client:
        answer = client.post("/v1/robots/puma560_standard/fk", json={"joints": PUMA_Q})
    assert answer.status_code == 200 and solver_calls == ["/v1/robots/puma560_standard/fk"]


def test_a_field_validate_of_another_signature_leaves_the_request_to_fastapi():
    """Per request too: a body field whose validate takes other arguments gives None (FastAPI's handler answers),
    before anything ran."""
    from service.api.routers import fk

    route = next(route for route in fk.router.routes if route.path.endswith("/robots/{robot_id}/fk"))
    plain = routing._PlainArguments.of(route)
    assert plain is not None
    plain._body = SimpleNamespace(name="body", validate=lambda value: value)
    scope = {"type": "http", "method": "POST", "path": "/v1/robots/puma560_standard/fk", "query_string": b"",
             "headers": [(b"content-type", b"application/json")], "path_params": {"robot_id": "puma560_standard"}}

    async def receive():
        return {"type": "http.request", "body": b"", "more_body": False}

    assert asyncio.run(plain.answer(scope, receive, b'{"joints": [0, 0, 0, 0, 0, 0]}', False)) is None
