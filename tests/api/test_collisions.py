"""Collision checking over HTTP (issue 25): every solution's clearance and collisions, recomputed independently from
the FK link frames the service returns and the shapes its robot description shows (the pair rules written out
here, the distances by the oracle of tests/oracles/collision.py, which shares no code with the service); the
filter keeps exactly the solutions at least the margin clear; hostile inputs are 4xx problems."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from tests.oracles.collision import signed_distance

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


def _shape(wire: dict, frame: np.ndarray) -> SimpleNamespace:
    """One wire shape (capsule, sphere or box) in the world, given the frame it is fixed to (4, 4)."""
    R, t = frame[:3, :3], frame[:3, 3]
    if "capsule" in wire:
        c = wire["capsule"]
        return SimpleNamespace(start=R @ np.array(c["from"]) + t, end=R @ np.array(c["to"]) + t,
                               radius=float(c["radius"]))
    if "sphere" in wire:
        return SimpleNamespace(center=R @ np.array(wire["sphere"]["center"]) + t, radius=float(wire["sphere"]["radius"]))
    box = wire["box"]
    rotation = np.eye(3)
    if box.get("orientation"):
        roll, pitch, yaw = box["orientation"]["angles"]
        cr, sr, cp, sp, cy, sy = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch), np.cos(yaw), np.sin(yaw)
        rotation = (np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]]) @ np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
                    @ np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]]))
    return SimpleNamespace(center=R @ np.array(box["center"]) + t, rotation=R @ rotation,
                           half_size=0.5 * np.array(box["size"]))


def _described_shapes(client, robot_id: str) -> tuple[list[dict], list[str]]:
    """The robot's shapes fixed to frame indices (its screws export restates a URDF's onto the frames FK
    returns), and the label the answers give each shape's link (a URDF's link name, else "link i")."""
    own = client.get(f"/v1/robots/{robot_id}").json()
    by_index = client.get(f"/v1/robots/{robot_id}?form=screws").json()
    labels = [entry["link"] if isinstance(entry["link"], str) else f"link {entry['link']}"
              for entry in own["collision"]]
    assert len(by_index["collision"]) == len(labels)
    return by_index["collision"], labels


def _placed(client, robot_id: str, joints) -> list[tuple[int, str, SimpleNamespace]]:
    """(frame index, answer label, shape in the world) of every described shape at ``joints``."""
    described, labels = _described_shapes(client, robot_id)
    frames = client.post(f"/v1/robots/{robot_id}/fk", json={"joints": joints, "frames": True}).json()["frames"]
    link_frames = [np.array(frame["matrix"]) for frame in frames[:-1]]  # base, links 1 … n (not the tool)
    return [(entry["link"], label, _shape(entry, link_frames[entry["link"]]))
            for entry, label in zip(described, labels)]


def _self_pairs(shapes):
    """The shape pairs of different links not joined by a joint."""
    for i, (link_a, label_a, shape_a) in enumerate(shapes):
        for link_b, label_b, shape_b in shapes[i + 1:]:
            low, high = sorted((link_a, link_b))
            if link_a != link_b and high != low + 1:
                yield (low, high), (label_a, shape_a, link_a), (label_b, shape_b, link_b)


def _touching_at_home(client, robot_id: str) -> set[tuple[int, int]]:
    """The link pairs in overlap at q = 0 (both test arms have zero inside their limits): never checked."""
    joints = len(client.get(f"/v1/robots/{robot_id}?form=screws").json()["joints"])
    return {links for links, (_, a, _), (_, b, _) in _self_pairs(_placed(client, robot_id, [0.0] * joints))
            if signed_distance(a, b) < 0}


def _independent_check(client, robot_id: str, joints, obstacles, margin: float) -> tuple[float, dict]:
    """Clearance and the close body pairs of one joint vector, from the FK frames and the described shapes."""
    shapes, ignored = _placed(client, robot_id, joints), _touching_at_home(client, robot_id)
    close, clearance = {}, np.inf
    for links, (label_a, shape_a, link_a), (label_b, shape_b, link_b) in _self_pairs(shapes):
        if links in ignored:
            continue
        distance = signed_distance(shape_a, shape_b)
        clearance = min(clearance, distance)
        if distance < margin:
            key = (label_a, label_b) if link_a < link_b else (label_b, label_a)
            close[key] = min(close.get(key, np.inf), distance)
    for _, label_a, shape_a in shapes:
        for obstacle in obstacles:
            distance = signed_distance(shape_a, _shape(obstacle, np.eye(4)))
            clearance = min(clearance, distance)
            if distance < margin:
                close[(label_a, obstacle["name"])] = min(close.get((label_a, obstacle["name"]), np.inf), distance)
    return clearance, close


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
        clearance, close = _independent_check(client, robot_id, solution["joints"], case["obstacles"], case["margin"])
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
    clearance, close = _independent_check(client, "puma560_standard", case["q"], case["obstacles"],
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
