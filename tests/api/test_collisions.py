"""Collision checking over HTTP (issue 25): every solution's clearance and collisions, recomputed independently from
the FK link frames the service returns and the shapes its robot description shows (the pair rules written out
here, the distances by the oracle of tests/oracles/collision.py, which shares no code with the service); the
filter keeps exactly the solutions at least the margin clear; hostile inputs are 4xx problems."""

from __future__ import annotations

import pytest

from tests.collision_check import independent_check

#: A DH arm and a URDF arm of the catalogue, each with a table and a post placed to make some solutions collide.
CASES = {
    # the table under the elbow-down solutions, the post beside two elbow-up ones: 2 of 8 kept. Margin 5 mm: the
    # model's flange sphere sits 7 mm from its forearm capsule in every configuration (both at the wrist centre)
    "puma560_standard": {"q": [0.4, 0.9, -2.4, 0.7, 1.1, -0.5], "margin": 0.005, "obstacles": [
        {"name": "table", "box": {"center": [0.55, 0.0, -0.15], "size": [0.5, 1.0, 0.1]}},
        {"name": "post", "capsule": {"from": [0.27, -0.2, -0.6], "to": [0.27, -0.2, 0.6], "radius": 0.06}}]},
    # the ball and the arm's own wrist against its forearm: 2 of 8 kept
    "unitree_z1": {"q": [0.3, 1.2, -1.1, 0.4, 0.6, -0.2], "margin": 0.01, "obstacles": [
        {"name": "table", "box": {"center": [0.3, 0.0, -0.1], "size": [1.0, 1.0, 0.05],
                                  "orientation": {"type": "rpy", "angles": [0.0, 0.05, 0.0]}}},
        {"name": "ball", "sphere": {"center": [0.25, 0.2, 0.25], "radius": 0.08}}]},
}


@pytest.mark.parametrize("robot_id", sorted(CASES))
def test_every_kept_solution_is_clear_and_every_rejected_one_collides(client, robot_id):
    case = CASES[robot_id]
    assert client.get(f"/v1/robots/{robot_id}").json()["collision"], "the catalogue arm carries its capsule model"
    target = client.post(f"/v1/robots/{robot_id}/fk", json={"joints": case["q"]}).json()["pose"]["matrix"]
    answer = client.post(f"/v1/robots/{robot_id}/ik", json={
        "target": {"matrix": target}, "filter_limits": False,
        "collisions": {"margin": case["margin"], "obstacles": case["obstacles"]}}).json()
    kept, rejected = answer["solutions"], answer["rejected"]
    assert kept and rejected, (answer["status"], len(kept), len(rejected))  # the obstacles split the solutions
    for solution in kept + rejected:
        clearance, close = independent_check(client, robot_id, solution["joints"], case["obstacles"], case["margin"])
        assert solution["clearance"] == pytest.approx(clearance, abs=1e-9)
        reported = {(pair["a"], pair["b"]): pair["distance"] for pair in solution["collisions"]}
        assert reported.keys() == close.keys()
        for key, distance in close.items():
            assert reported[key] == pytest.approx(distance, abs=1e-9)
    assert all(s["clearance"] >= case["margin"] for s in kept)
    assert all(s["clearance"] < case["margin"] for s in rejected)


def test_every_solution_colliding_is_its_own_status(client):
    """A box around the whole arm: solutions exist within the limits, and every one collides."""
    case = CASES["puma560_standard"]
    target = client.post("/v1/robots/puma560_standard/fk", json={"joints": case["q"]}).json()["pose"]["matrix"]
    answer = client.post("/v1/robots/puma560_standard/ik", json={
        "target": {"matrix": target},
        "collisions": {"obstacles": [{"name": "cage", "box": {"center": [0, 0, 0], "size": [3, 3, 3]}}]}}).json()
    assert answer["status"] == "no_collision_free_solution" and not answer["solutions"]
    assert answer["rejected"] and all(pair["b"] == "cage" or pair["b"].startswith("link")
                                      for s in answer["rejected"] for pair in s["collisions"])
    assert "collide" in answer["detail"]


def test_without_the_filter_colliding_solutions_stay_flagged(client):
    case = CASES["puma560_standard"]
    target = client.post("/v1/robots/puma560_standard/fk", json={"joints": case["q"]}).json()["pose"]["matrix"]
    body = {"target": {"matrix": target}, "filter_limits": False}
    plain = client.post("/v1/robots/puma560_standard/ik", json=body).json()
    flagged = client.post("/v1/robots/puma560_standard/ik", json={
        **body, "collisions": {"filter": False, "margin": case["margin"], "obstacles": case["obstacles"]}}).json()
    assert [s["joints"] for s in flagged["solutions"]] == [s["joints"] for s in plain["solutions"]]
    assert any(s["collisions"] for s in flagged["solutions"]) and "clearance" not in plain["solutions"][0]


def test_fk_answers_the_clearance_of_its_joints(client):
    case = CASES["puma560_standard"]
    answer = client.post("/v1/robots/puma560_standard/fk", json={
        "joints": case["q"], "collisions": {"margin": case["margin"], "obstacles": case["obstacles"]}}).json()
    clearance, close = independent_check(client, "puma560_standard", case["q"], case["obstacles"],
                                          case["margin"])
    assert answer["clearance"] == pytest.approx(clearance, abs=1e-9)
    assert {(p["a"], p["b"]) for p in answer["collisions"]} == close.keys()


@pytest.mark.parametrize("collisions, location", [
    ({"obstacles": [{"name": "ball", "sphere": {"center": [0, 0, 1], "radius": -0.1}}]},
     ["body", "collisions", "obstacles", 0, "sphere", "radius"]),
    ({"obstacles": [{"name": "two", "sphere": {"center": [0, 0, 1], "radius": 0.1},
                     "box": {"center": [0, 0, 0], "size": [1, 1, 1]}}]}, ["body", "collisions", "obstacles", 0]),
    ({"ignore": [[0, 7]]}, ["body", "collisions", "ignore", 0, 1]),
    ({"ignore": [[0, "wrist"]]}, ["body", "collisions", "ignore", 0, 1]),
    ({"margin": -1}, ["body", "collisions", "margin"]),
    ({"obstacles": [{"name": "link 2", "sphere": {"center": [0, 0, 1], "radius": 0.1}}]},
     ["body", "collisions", "obstacles", 0, "name"]),
])
def test_hostile_collision_options_are_located_422s(client, collisions, location):
    target = {"position": [0.4, 0.1, 0.3], "quaternion_wxyz": [0, 1, 0, 0]}
    response = client.post("/v1/robots/puma560_standard/ik", json={"target": target, "collisions": collisions})
    assert response.status_code == 422, response.text
    assert response.headers["content-type"] == "application/problem+json"
    assert any(error["loc"][:len(location)] == location for error in response.json()["errors"]), response.json()


def test_a_robot_without_shapes_says_how_to_give_them(client):
    response = client.post("/v1/robots/spong_ex3_1_planar_rr/ik",
                           json={"target": {"position": [1.0, 0.5, 0.0]}, "collisions": {}})
    assert response.status_code == 422 and "collision" in response.json()["detail"]


@pytest.mark.parametrize("settings, words", [
    ({"max_collision_pairs": 20}, "KIN_MAX_COLLISION_PAIRS = 20"),
    ({"max_collision_checks": 1_000}, "KIN_MAX_COLLISION_CHECKS = 1,000"),
])
def test_a_check_past_its_caps_is_refused_before_any_work(settings, words):
    """The cost model counts the pairs (8 PUMA shapes: their self pairs and 8 per obstacle) and the distances
    (targets × solutions × pairs) before solving."""
    from fastapi.testclient import TestClient

    from service.api.app import create_app
    from service.config import Settings

    case = CASES["puma560_standard"]
    with TestClient(create_app(Settings(_env_file=None, **settings))) as capped:
        target = capped.post("/v1/robots/puma560_standard/fk", json={"joints": case["q"]}).json()["pose"]["matrix"]
        body = {"targets": [{"matrix": target}] * 20, "collisions": {"obstacles": case["obstacles"]}}
        response = capped.post("/v1/robots/puma560_standard/ik/batch", json=body)
        assert response.status_code == 413, response.text
        assert response.headers["content-type"] == "application/problem+json"
        assert words in response.json()["detail"]
        fine = capped.post("/v1/robots/puma560_standard/ik", json={
            "target": {"matrix": target}, "collisions": {"self": False, "obstacles": case["obstacles"][:1]}})
        assert fine.status_code == 200, fine.text
