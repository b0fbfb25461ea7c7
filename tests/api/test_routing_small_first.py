"""Small work where it arrives (service.api.routing.small_first): single FK and IK requests and their batches whose work
is small run on the server's loop; anything that can take longer (a plan to derive, a robot to build, a numeric
search, a large answer, a picture, a large body) starts again on a work loop before any of it is done, and is
answered the same."""

from __future__ import annotations

import threading

import numpy as np
import pytest
from fastapi.testclient import TestClient

from service.api import routing
from service.api.app import create_app
from service.api import ik_requests
from service.config import Settings
from service.kinematics import forward_kinematics

PUMA_Q = [0.3, -0.4, 0.5, 0.2, -0.6, 0.9]


@pytest.fixture()
def fresh():
    """A client on an application of its own: its catalogue robots have derived nothing yet."""
    with TestClient(create_app(Settings(log_level="warning"))) as client:
        yield client


@pytest.fixture()
def where(monkeypatch) -> list[str]:
    """Where each IK answer was computed: 'work' on a work loop's thread, 'here' on the server's loop."""
    places: list[str] = []
    answer_ik = ik_requests.answer_ik

    def recorded(*args, **kwargs):
        places.append("work" if threading.current_thread().name.startswith("kin-work") else "here")
        return answer_ik(*args, **kwargs)

    monkeypatch.setattr(ik_requests, "answer_ik", recorded)
    return places


@pytest.fixture()
def hand_overs(monkeypatch) -> list[str]:
    """The paths of the requests handed to a work loop."""
    paths: list[str] = []
    on_work_loop = routing._on_work_loop

    async def recorded(make):
        paths.append("handed over")
        return await on_work_loop(make)

    monkeypatch.setattr(routing, "_on_work_loop", recorded)
    return paths


def _puma_target(client) -> list[list[float]]:
    response = client.post("/v1/robots/puma560_standard/fk", json={"joints": PUMA_Q})
    assert response.status_code == 200
    return response.json()["pose"]["matrix"]


def test_single_fk_and_a_prepared_single_ik_run_where_they_arrive(fresh, where, hand_overs):
    target = _puma_target(fresh)
    assert hand_overs == []  # FK of a catalogue robot is always small
    first = fresh.post("/v1/robots/puma560_standard/ik", json={"target": {"matrix": target}})
    second = fresh.post("/v1/robots/puma560_standard/ik", json={"target": {"matrix": target}})
    assert first.status_code == second.status_code == 200
    # the first derives the PUMA's plan: handed over before anything was solved; the second finds it built
    assert where == ["work", "here"] and len(hand_overs) == 1
    assert first.json() == second.json()
    assert any(np.allclose(s["joints"], PUMA_Q, atol=1e-9) for s in second.json()["solutions"])


def test_the_same_answers_as_on_a_work_loop(client, monkeypatch):
    """Every kind of small request gets byte-for-byte the answer it gets when forced onto a work loop."""
    target = _puma_target(client)
    requests = [
        ("/v1/robots/puma560_standard/fk", {"joints": PUMA_Q, "frames": True}),
        ("/v1/robots/puma560_standard/ik", {"target": {"matrix": target}}),
        ("/v1/robots/puma560_standard/ik", {"target": {"matrix": target}, "reference": PUMA_Q,
                                            "max_solutions": 3}),
        ("/v1/robots/puma560_standard/ik", {"target": {"position": [5.0, 5.0, 5.0], "quaternion_wxyz": [1, 0, 0, 0]}}),
        ("/v1/robots/puma560_standard/ik", {"target": {"matrix": target}, "reference": [0, 0, 0], "angle_unit": "deg"}),
        ("/v1/robots/ur5/ik", {"target": {"position": [0.3, 0.2, 0.4], "quaternion_wxyz": [0, 1, 0, 0]}}),
        ("/v1/robots/puma560_standard/ik/batch", {"targets": [{"matrix": target}] * 3, "reference": PUMA_Q}),
        ("/v1/robots/puma560_standard/ik/batch", {"targets": {"matrices": [np.ravel(target).tolist()] * 4},
                                                  "format": "arrays"}),
        ("/v1/robots/puma560_standard/ik/batch", {"targets": [{"matrix": target}, {"position": [5.0, 5.0, 5.0]}]}),
        ("/v1/robots/puma560_standard/fk/batch", {"joints": [PUMA_Q, [0.0] * 6], "angle_unit": "deg"}),
        ("/v1/robots/puma560_standard/limits", {"joints": [PUMA_Q, [7.0] * 6]}),
    ]
    here = [client.post(path, json=body) for path, body in requests]
    monkeypatch.setattr(routing, "SMALL_BODY_BYTES", -1)  # every request on a work loop
    on_work_loop = [client.post(path, json=body) for path, body in requests]
    assert [r.status_code for r in here] == [200, 200, 200, 200, 422, 200, 200, 200, 200, 200, 200]
    for small, handed in zip(here, on_work_loop):
        assert small.status_code == handed.status_code
        assert small.content == handed.content


def test_work_that_is_not_small_is_handed_over_before_it_starts(client, where):
    target = _puma_target(client)
    client.post("/v1/robots/puma560_standard/ik", json={"target": {"matrix": target}})  # the plan is built
    where.clear()
    wide = [{"lower": -4 * np.pi, "upper": 4 * np.pi}] * 6  # 8 solutions × 4⁶ equivalents: up to 1,024 rows
    not_small = [
        {"target": {"matrix": target}, "limits": wide},
        {"target": {"matrix": target}, "max_equivalents": 600, "limits": wide},
        {"target": {"matrix": target}, "tool": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0.05], [0, 0, 0, 1]]},
    ]
    for body in not_small:
        assert client.post("/v1/robots/puma560_standard/ik", json=body).status_code == 200
    assert where == ["work"] * 3  # each answered once, on a work loop
    # the same tool again: its plan is now kept, so the request is small
    assert client.post("/v1/robots/puma560_standard/ik", json=not_small[2]).status_code == 200
    assert where[-1] == "here"
    where.clear()
    picture = client.post("/v1/robots/puma560_standard/ik?render=iso", json={"target": {"matrix": target}})
    assert picture.status_code == 200 and picture.headers["content-type"].startswith("image/svg+xml")
    padded = b'{"target": {"matrix": ' + repr(target).encode() + b"}" + b" " * routing.SMALL_BODY_BYTES + b"}"
    large_body = client.post("/v1/robots/puma560_standard/ik", content=padded,
                             headers={"content-type": "application/json"})
    assert large_body.status_code == 200
    assert where == ["work", "work"]


def test_a_single_ik_of_two_turns_a_joint_runs_where_it_arrives(fresh, where):
    """A UR5's catalogue limits (±2π on every joint) give up to 8 × 2⁶ = 512 rows: about a millisecond where the
    request arrives, where the hand-over would add about 200 µs. Up to 1,024 (±4π, above) goes to a work loop."""
    pose = fresh.post("/v1/robots/ur5/fk", json={"joints": [0.3, -0.4, 0.5, 0.2, -0.6, 0.7]}).json()["pose"]
    body = {"target": {"matrix": pose["matrix"]}}
    first = fresh.post("/v1/robots/ur5/ik", json=body)
    second = fresh.post("/v1/robots/ur5/ik", json=body)
    assert first.status_code == second.status_code == 200
    assert first.json() == second.json() and len(second.json()["solutions"]) > 64
    assert where == ["work", "here"]  # the first derives the UR5's plan


def test_a_numeric_arm_and_a_new_inline_robot_are_handed_over(client, where, hand_overs):
    rows = [{"a": 0.1 * (i + 1), "alpha": 0.3 * (i + 1), "d": 0.05 * i, "theta": 0.0} for i in range(6)]
    robot = {"id": "skew6", "convention": "standard", "joints": rows}  # no closed form: the numeric search
    q = np.array([0.2, 0.3, -0.4, 0.5, 0.1, -0.2])
    fk = client.post("/v1/fk", json={"robot": robot, "joints": q.tolist()})
    assert fk.status_code == 200
    assert len(hand_overs) == 1  # the robot was built on a work loop
    assert client.post("/v1/fk", json={"robot": robot, "joints": q.tolist()}).status_code == 200
    assert len(hand_overs) == 1  # kept: small
    answer = client.post("/v1/ik", json={"robot": robot, "target": {"matrix": fk.json()["pose"]["matrix"]},
                                         "numeric": {"starts": 8}})
    assert answer.status_code == 200
    assert where == ["work"]


def test_a_few_waypoints_run_where_they_arrive_and_larger_batches_are_handed_over(client, where, hand_overs):
    """A batch is small as a single IK is (its worst-case answer within SMALL_ROWS rows in all): a motion planner's
    few waypoints run where they arrive; a batch that may answer more rows, or a body above SMALL_BODY_BYTES, goes
    to a work loop before anything is solved."""
    target = _puma_target(client)
    client.post("/v1/robots/puma560_standard/ik", json={"target": {"matrix": target}})  # the plan is built
    where.clear()
    hand_overs.clear()
    few = client.post("/v1/robots/puma560_standard/ik/batch", json={"targets": [{"matrix": target}] * 4})
    assert few.status_code == 200 and len(few.json()["results"]) == 4
    assert where == ["here"] and hand_overs == []
    wide = [{"lower": -4 * np.pi, "upper": 4 * np.pi}] * 6  # up to 1,024 rows a target
    assert client.post("/v1/robots/puma560_standard/ik/batch",
                       json={"targets": [{"matrix": target}] * 2, "limits": wide}).status_code == 200
    many = {"targets": {"matrices": [np.ravel(target).tolist()] * 100}, "format": "arrays"}
    assert client.post("/v1/robots/puma560_standard/ik/batch", json=many).status_code == 200
    assert where == ["here", "work", "work"] and len(hand_overs) == 2


def test_an_fk_batch_of_a_small_body_runs_where_it_arrives(client, hand_overs):
    """A body within SMALL_BODY_BYTES holds a few hundred rows at most: their FK and encoding are small work."""
    hand_overs.clear()
    rows = np.random.default_rng(2).uniform(-3, 3, (100, 6)).round(6).tolist()
    assert client.post("/v1/robots/puma560_standard/fk/batch", json={"joints": rows[:50]}).status_code == 200
    assert hand_overs == []
    assert client.post("/v1/robots/puma560_standard/fk/batch", json={"joints": rows * 20}).status_code == 200
    assert hand_overs == ["handed over"]


def test_a_small_request_still_meets_its_errors_as_problems(client, hand_overs):
    hand_overs.clear()
    wrong = client.post("/v1/robots/puma560_standard/fk", json={"joints": [0.0] * 5})
    assert wrong.status_code == 422 and wrong.headers["content-type"] == "application/problem+json"
    unknown = client.post("/v1/robots/puma561/fk", json={"joints": PUMA_Q})
    assert unknown.status_code == 404 and unknown.headers["content-type"] == "application/problem+json"
    assert hand_overs == []


def test_fk_pose_matches_the_core(client):
    """The server's-loop path returns the core's FK (an independent check that nothing is lost on the way)."""
    from service.robots.catalogue import load_catalogue
    settings = Settings()
    robot = load_catalogue([settings.builtin_robots_dir], max_joints=settings.max_joints).get("ur5").robot
    q = [0.1, -1.2, 1.1, 0.3, 0.7, -0.4]
    pose = client.post("/v1/robots/ur5/fk", json={"joints": q}).json()["pose"]
    assert np.allclose(pose["matrix"], forward_kinematics(robot, np.array(q)), atol=1e-12)


def test_while_a_request_computes_on_a_work_loop_small_ones_take_their_turn(client, where):
    """Under mixed load the server's loop stays free for I/O: small requests then wait for a turn like the others."""
    target = _puma_target(client)
    body = {"target": {"matrix": target}}
    assert client.post("/v1/robots/puma560_standard/ik", json=body).status_code == 200
    where.clear()
    routing.CORE_TURNS.take()  # as a long request computing on a work loop would
    try:
        assert client.post("/v1/robots/puma560_standard/ik", json=body).status_code == 200
    finally:
        routing.CORE_TURNS.give_back()
    assert client.post("/v1/robots/puma560_standard/ik", json=body).status_code == 200
    assert where == ["work", "here"]


CELL = {"self": True, "margin": 0.005, "obstacles": [
    {"name": "table", "box": {"center": [0.55, 0.0, -0.15], "size": [0.5, 1.0, 0.1]}},
    {"name": "post", "capsule": {"from": [0.27, -0.2, -0.6], "to": [0.27, -0.2, 0.6], "radius": 0.06}}]}


def test_a_single_ik_with_collisions_is_small_once_its_model_is_kept(fresh, where, monkeypatch):
    """The first request compiles its collision model on a work loop; the same cell again finds it kept, and a
    single pose's check is small; a cell of many obstacles (more pair distances than a small check) is not. Each
    is answered byte for byte as on a work loop."""
    target = _puma_target(fresh)
    fresh.post("/v1/robots/puma560_standard/ik", json={"target": {"matrix": target}})  # the plan is built
    where.clear()
    body = {"target": {"matrix": target}, "collisions": CELL}
    first, second = (fresh.post("/v1/robots/puma560_standard/ik", json=body) for _ in range(2))
    assert first.status_code == second.status_code == 200 and first.content == second.content
    assert where == ["work", "here"]
    assert first.json()["rejected"] and all(s["collisions"] for s in first.json()["rejected"])
    crowded = {**CELL, "obstacles": [{"name": f"post {k}", "sphere": {"center": [1.0 + k, 0, 0], "radius": 0.1}}
                                     for k in range(40)]}
    for _ in range(2):
        assert fresh.post("/v1/robots/puma560_standard/ik",
                          json={"target": {"matrix": target}, "collisions": crowded}).status_code == 200
    assert where[2:] == ["work", "work"]  # kept, but 8 solutions × (320 + the self pairs) is not a small check
    small = fresh.post("/v1/robots/puma560_standard/ik", json=body)
    monkeypatch.setattr(routing, "SMALL_BODY_BYTES", -1)  # every request on a work loop
    handed = fresh.post("/v1/robots/puma560_standard/ik", json=body)
    assert where[-2:] == ["here", "work"] and small.content == handed.content
