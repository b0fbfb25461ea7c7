"""Position + tool direction targets of arms of 6 or more joints (issue 22 item 10): a family over the free roll.

api.md offers position + tool direction "for any arm when roll about the tool axis is free". Each target here is
made by the arm's own FK at a configuration within its limits: the tool origin and the direction of its z axis.
The roll ψ of that configuration is computed here from the documented definition (``R = R_t · Rot(a, ψ)``,
``R_t`` the shortest turn of the tool axis onto the direction), independently of the service's code. Checked:

* the generating configuration is among the solutions when the rolls solved include its roll (``roll_values``),
  and it is the first solution when it is the reference (the roll is searched between the default samples);
* every solution's tool origin and tool z axis equal the target's within 1e-9, and its ``free_values["roll"]``
  is its own roll;
* no FK-made target is ever ``unreachable``.
"""

from __future__ import annotations

import numpy as np
import pytest

from service.kinematics import forward_kinematics
from tests.conftest import assert_problem, catalogue_robot
from tests.ik_helpers import angle_gap, find, fk_matrix, joints_of

SIX = ["puma560_standard", "ur5", "kuka_kr6_r900_2", "kinova_jaco2"]
SEVEN = "franka_panda"
Z = np.array([0.0, 0.0, 1.0])


def _configurations(robot, count: int, seed: int) -> np.ndarray:
    """Joint vectors (count, n) inside the limits (±π where a joint has none), away from their ends."""
    lower = np.where(np.isfinite(robot.lower), robot.lower, -np.pi)
    upper = np.where(np.isfinite(robot.upper), robot.upper, np.pi)
    lower, upper = np.maximum(lower, -np.pi), np.minimum(upper, np.pi)
    middle, half = (lower + upper) / 2, (upper - lower) / 2
    return middle + 0.9 * half * np.random.default_rng(seed).uniform(-1.0, 1.0, (count, robot.dof))


def _shortest_turn(a: np.ndarray, d: np.ndarray) -> np.ndarray:
    """The rotation (3, 3) of least angle taking unit a onto unit d (not opposite, as in these tests)."""
    axis, cosine = np.cross(a, d), float(a @ d)
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + K + K @ K / (1.0 + cosine)


def _roll(R: np.ndarray, a: np.ndarray = Z) -> float:
    """ψ with R = R_t · Rot(a, ψ), in (−π, π]."""
    M = _shortest_turn(a, R @ a).T @ R
    sine = 0.5 * a @ np.array([M[2, 1] - M[1, 2], M[0, 2] - M[2, 0], M[1, 0] - M[0, 1]])
    return float(np.arctan2(sine, 0.5 * (np.trace(M) - 1.0)))


def _target(T: np.ndarray, **roll) -> dict:
    return {"position": T[:3, 3].tolist(),
            "orientation": {"type": "direction", "world_direction": T[:3, 2].tolist(), **roll}}


def _check_every_solution(robot, answer: dict, T: np.ndarray) -> None:
    """Each solution reaches the position and points its z axis along the direction within 1e-9, and reports
    its own roll."""
    joints = joints_of(answer)
    reached = forward_kinematics(robot, joints)
    assert np.abs(reached[:, :3, 3] - T[:3, 3]).max() <= 1e-9
    assert np.abs(reached[:, :3, 2] - T[:3, 2]).max() <= 1e-9
    for solution, R in zip(answer["solutions"], reached[:, :3, :3]):
        roll = solution["free_values"]["roll"]
        assert angle_gap(roll, _roll(R)) <= 1e-9


@pytest.mark.parametrize("robot_id", SIX)
def test_the_generating_configuration_is_found_at_its_roll(client, robot_id):
    robot = catalogue_robot(client, robot_id)
    for q in _configurations(robot, 4, seed=22):
        T = fk_matrix(client, robot_id, q)
        rolls = [_roll(T[:3, :3]), -2.5, -1.0, 0.5, 2.0]
        response = client.post(f"/v1/robots/{robot_id}/ik", json={
            "target": _target(T, roll_values=rolls), "limits": [None] * robot.dof, "filter_limits": False})
        assert response.status_code == 200, response.text
        answer = response.json()
        assert answer["status"] == "ok" and answer["solver"]["complete"] is True
        assert answer["solver"]["structure"].startswith("roll_family+")
        assert answer["free_joints"] == []
        assert find(robot, joints_of(answer), q, 1e-6) is not None
        _check_every_solution(robot, answer, T)
        found = {round(s["free_values"]["roll"], 6) for s in answer["solutions"]}
        assert found <= {round(float(np.angle(np.exp(1j * r))), 6) for r in rolls} | {3.141593}


@pytest.mark.parametrize("robot_id", [*SIX, SEVEN])
def test_with_the_generating_configuration_as_reference_it_is_the_nearest_member(client, robot_id):
    robot = catalogue_robot(client, robot_id)
    for q in _configurations(robot, 3, seed=7):
        T = fk_matrix(client, robot_id, q)
        response = client.post(f"/v1/robots/{robot_id}/ik", json={"target": _target(T), "reference": q.tolist()})
        assert response.status_code == 200, response.text
        answer = response.json()
        assert answer["status"] == "ok" and answer["solver"]["complete"] is True
        first = np.array(answer["solutions"][0]["joints"])
        assert angle_gap(first, q).max() <= 1e-6, (first, q)
        assert angle_gap(answer["solutions"][0]["free_values"]["roll"], _roll(T[:3, :3])) <= 1e-6
        _check_every_solution(robot, answer, T)


@pytest.mark.parametrize("robot_id", [*SIX, SEVEN])
def test_fk_made_targets_are_never_unreachable(client, robot_id):
    robot = catalogue_robot(client, robot_id)
    poses = [fk_matrix(client, robot_id, q) for q in _configurations(robot, 6, seed=3)]
    response = client.post(f"/v1/robots/{robot_id}/ik/batch", json={
        "targets": [_target(T) for T in poses], "filter_limits": False, "max_equivalents": 1})
    assert response.status_code == 200, response.text
    for answer, T in zip(response.json()["results"], poses):
        assert answer["status"] == "ok", answer["detail"]
        assert all("roll" in s["free_values"] for s in answer["solutions"])
        _check_every_solution(robot, answer, T)


def test_a_redundant_arm_samples_its_free_joint_at_each_roll(client):
    robot = catalogue_robot(client, SEVEN)
    q = _configurations(robot, 1, seed=5)[0]
    T = fk_matrix(client, SEVEN, q)
    answer = client.post(f"/v1/robots/{SEVEN}/ik", json={
        "target": _target(T, roll_values=[_roll(T[:3, :3]), 1.0]), "filter_limits": False,
        "free_joints": [{"joint": 6, "values": [float(q[6]), 0.0]}]}).json()
    assert answer["status"] == "ok" and answer["solver"]["complete"] is True and answer["free_joints"] == [6]
    assert find(robot, joints_of(answer), q, 1e-6) is not None
    assert all(set(s["free_values"]) == {"6", "roll"} for s in answer["solutions"])
    _check_every_solution(robot, answer, T)


def test_the_arrays_form_carries_the_roll_in_the_request_unit(client):
    T = fk_matrix(client, "puma560_standard", [0.3, -0.5, 0.4, 0.7, -0.6, 1.1])
    body = client.post("/v1/robots/puma560_standard/ik/batch", json={
        "targets": [_target(T, roll_values=[30.0, 90.0]), _target(T, roll_values=[30.0, 90.0, 390.0])],
        "format": "arrays", "angle_unit": "deg", "filter_limits": False}).json()
    rolls = body["solutions"]["free_values"]["roll"]
    assert len(rolls) == len(body["solutions"]["joints"]) > 0
    assert {round(r, 6) for r in rolls} == {30.0, 90.0}
    first, second = body["targets"]["solution_count"]
    assert first == second  # 390° is 30° again: each solution once


def test_beyond_reach_is_unreachable_and_the_detail_says_so(client):
    answer = client.post("/v1/robots/ur5/ik", json={
        "target": {"position": [5.0, 0.0, 0.0], "orientation": {"type": "direction", "world_direction": [0, 0, 1]}}
    }).json()
    assert answer["status"] == "unreachable" and "outside the workspace" in answer["detail"]


def test_no_solution_at_the_rolls_solved_is_not_found_not_unreachable(client):
    """A UR5 with its tool x axis as the direction axis: the roll moves the wrist, and this target (made by FK)
    is out of reach at the roll −1.5 rad but not at 1.0 rad."""
    T = fk_matrix(client, "ur5", [0.0, -0.2, 0.02, 0.0, 0.7, 0.0])
    target = {"position": T[:3, 3].tolist(), "orientation": {"type": "direction", "tool_axis": [1, 0, 0],
                                                             "world_direction": T[:3, 0].tolist()}}
    target["orientation"]["roll_values"] = [-1.5]
    answer = client.post("/v1/robots/ur5/ik", json={"target": target}).json()
    assert answer["status"] == "not_found" and answer["solver"]["complete"] is True
    assert "other rolls may reach it" in answer["detail"]
    target["orientation"]["roll_values"] = [-1.5, 1.0]
    assert client.post("/v1/robots/ur5/ik", json={"target": target}).json()["status"] == "ok"


@pytest.mark.parametrize("orientation, loc", [
    ({"type": "direction", "world_direction": [0, 0, 0]}, ["body", "target", "orientation", "world_direction"]),
    ({"type": "direction", "tool_axis": [0, 0, 0], "world_direction": [0, 0, 1]},
     ["body", "target", "orientation", "tool_axis"]),
    ({"type": "direction", "world_direction": [0, 0, 1], "roll_samples": 0},
     ["body", "target", "orientation", "direction", "roll_samples"]),
    ({"type": "direction", "world_direction": [0, 0, 1], "roll_samples": 4, "roll_values": [0.0]},
     ["body", "target", "orientation", "direction"]),
])
def test_hostile_direction_targets_are_refused_at_the_field(client, orientation, loc):
    response = client.post("/v1/robots/puma560_standard/ik",
                           json={"target": {"position": [0.4, 0.1, 0.2], "orientation": orientation}})
    assert_problem(response, 422, loc=loc)


def test_too_many_rolls_times_free_values_are_refused_before_solving(client):
    response = client.post(f"/v1/robots/{SEVEN}/ik", json={
        "target": {"position": [0.4, 0.1, 0.4], "orientation": {"type": "direction", "world_direction": [0, 0, -1],
                                                                "roll_samples": 2048}},
        "free_joints": [{"joint": 6, "samples": 2}]})
    assert_problem(response, 422, loc=["body", "target", "orientation"], match="pose solves per direction target")


def test_an_arm_of_eight_joints_samples_fewer_free_values_per_roll(client):
    """Two free joints at the default rolls: 36 rolls × 32² free values would pass the cap of 2048 pose solves,
    so each free joint is sampled 4 times; with the generating configuration as reference it comes first."""
    import json
    from pathlib import Path

    iiwa = json.loads((Path(__file__).parents[1] / "data" / "redundant_and_deficient_arms.json").read_text())["iiwa14"]
    eight = {key: value for key, value in iiwa.items() if key not in ("name", "source")}
    eight.update(id="eight", angle_unit="rad", joints=[
        {"type": "revolute", "a": 0.3, "alpha": 0, "theta": 0, "d": 0.2},
        *({**joint, "alpha": np.radians(joint["alpha"]), "theta": np.radians(joint["theta"]), "limits": None}
          for joint in iiwa["joints"])])
    q = [0.2, 0.4, -0.5, 0.7, -0.9, 1.1, -1.2, 0.3]
    T = np.array(client.post("/v1/fk", json={"robot": eight, "joints": q}).json()["pose"]["matrix"])
    answer = client.post("/v1/ik", json={"robot": eight, "target": _target(T), "reference": q}).json()
    assert answer["status"] == "ok" and answer["solver"]["complete"] is True and len(answer["free_joints"]) == 2
    assert np.abs(np.array(answer["solutions"][0]["joints"]) - q).max() <= 1e-6
    assert set(answer["solutions"][0]["free_values"]) == {*map(str, answer["free_joints"]), "roll"}


def test_in_a_batch_the_refusal_names_the_target(client):
    fine = {"position": [0.4, 0.1, 0.4], "orientation": {"type": "direction", "world_direction": [0, 0, -1]}}
    many = {"position": [0.4, 0.1, 0.4], "orientation": {"type": "direction", "world_direction": [0, 0, -1],
                                                         "roll_samples": 2048}}
    response = client.post(f"/v1/robots/{SEVEN}/ik/batch", json={
        "targets": [fine, many], "free_joints": [{"joint": 6, "samples": 2}]})
    assert_problem(response, 422, loc=["body", "targets", 1, "orientation"], match="pose solves per direction target")
