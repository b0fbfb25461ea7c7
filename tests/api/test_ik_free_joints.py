"""The free-joint fields of the IK API (api.md "Redundant arms"), on an inline iiwa 14 DH table."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import assert_problem
from tests.ik_helpers import find, fk_inline

ARMS = json.loads((Path(__file__).parents[1] / "data" / "redundant_and_deficient_arms.json").read_text())
IIWA = ARMS["iiwa14"]
Q = [0.3, 0.5, -0.7, 1.1, 0.2, -0.4, 0.9]


class _Arm:
    is_revolute = np.ones(7, dtype=bool)


def test_named_values_in_degrees_come_back_with_their_free_values(client):
    T = fk_inline(client, IIWA, Q)
    values = [-60.0, float(np.degrees(Q[2])), 10.0]
    body = client.post("/v1/ik", json={"robot": IIWA, "target": {"matrix": T.tolist()}, "angle_unit": "deg",
                                       "filter_limits": False, "free_joints": [{"joint": 2, "values": values}]})
    assert body.status_code == 200, body.text
    answer = body.json()
    assert answer["free_joints"] == [2] and answer["solver"]["complete"] is True
    assert answer["solver"]["method"] == "analytic"
    joints = np.radians([s["joints"] for s in answer["solutions"]])
    assert find(_Arm(), joints, np.array(Q)) is not None
    for solution in answer["solutions"]:
        assert list(solution["free_values"]) == ["2"]
        assert solution["free_values"]["2"] == solution["joints"][2]
        assert min(abs(solution["free_values"]["2"] - v) for v in values) < 1e-6
        reached = fk_inline(client, IIWA, np.radians(solution["joints"]).tolist())
        assert np.abs(reached - T).max() < 1e-9


def test_default_choice_and_nearest_first_with_max_solutions(client):
    T = fk_inline(client, IIWA, Q)
    reference = [q + 0.05 for q in Q]
    answer = client.post("/v1/ik", json={"robot": IIWA, "target": {"matrix": T.tolist()}, "reference": reference,
                                         "max_solutions": 3}).json()
    assert answer["free_joints"] == [6] and len(answer["solutions"]) == 3
    moves = [max(abs(a - b) for a, b in zip(s["joints"], reference)) for s in answer["solutions"]]
    assert moves == sorted(moves) and moves[0] <= 0.05 + 1e-7  # as near as the generating vector, to the search tolerance


def test_samples_over_the_limits(client):
    T = fk_inline(client, IIWA, Q)
    answer = client.post("/v1/ik", json={"robot": IIWA, "target": {"matrix": T.tolist()}, "filter_limits": False,
                                         "free_joints": [{"joint": 0, "samples": 8}]}).json()
    grid = np.linspace(np.radians(-170), np.radians(170), 8)
    free = np.array([s["free_values"]["0"] for s in answer["solutions"]])
    assert len(free) and np.abs(free[:, None] - grid[None, :]).min(axis=1).max() < 1e-9


def test_bad_free_joints_are_422(client):
    T = fk_inline(client, IIWA, Q).tolist()
    assert_problem(client.post("/v1/ik", json={"robot": IIWA, "target": {"matrix": T},
                                               "free_joints": [{"joint": 2}]}), 422, loc=["body", "free_joints", 0])
    assert_problem(client.post("/v1/ik", json={"robot": IIWA, "target": {"matrix": T},
                                               "free_joints": [{"joint": 7, "values": [0]}]}), 422,
                   loc=["body", "free_joints", 0, "joint"])
    assert_problem(client.post("/v1/ik", json={"robot": IIWA, "target": {"matrix": T},
                                               "free_joints": [{"joint": 1, "values": [0]},
                                                               {"joint": 2, "values": [0]}]}), 422,
                   loc=["body", "free_joints"], match="free joint")


def test_far_target_is_outside_the_workspace(client):
    far = client.post("/v1/ik", json={"robot": IIWA, "target": {"position": [3, 0, 0], "orientation": {
        "type": "rpy", "angles": [0, 0, 0]}}}).json()
    assert far["status"] == "unreachable" and "outside the workspace" in far["detail"]


def test_free_joints_need_a_redundant_arm_and_bounded_values(client):
    pose = client.post("/v1/robots/ur5/fk", json={"joints": [0.1] * 6}).json()["pose"]["matrix"]
    assert_problem(client.post("/v1/robots/ur5/ik", json={"target": {"matrix": pose},
                                                          "free_joints": [{"joint": 2, "values": [0]}]}),
                   422, loc=["body", "free_joints"], match="more than 6 joints")
    T = fk_inline(client, IIWA, Q).tolist()
    assert_problem(client.post("/v1/ik", json={"robot": IIWA, "target": {"matrix": T},
                                               "free_joints": [{"joint": 2, "samples": 1000}]}),
                   422, loc=["body", "free_joints"], match="one plan per value")
    wide = client.post("/v1/ik", json={"robot": IIWA, "target": {"matrix": T}, "max_solutions": 4,
                                       "reference": Q, "free_joints": [{"joint": 0, "samples": 1000}]})
    assert wide.status_code == 200 and len(wide.json()["solutions"]) == 4  # an end joint takes more than 256
    assert_problem(client.post("/v1/ik", json={"robot": IIWA, "target": {"matrix": T},
                                               "free_joints": [{"joint": 0, "samples": 2049}]}),
                   422, loc=["body", "free_joints", 0, "samples"])


def test_a_locking_no_family_covers_falls_back_to_the_numeric_search_and_says_so(client):
    T = fk_inline(client, IIWA, Q).tolist()
    # q4 locked fixes the shoulder–wrist distance of this SRS arm: no family solves that locked arm
    answer = client.post("/v1/ik", json={"robot": IIWA, "target": {"matrix": T}, "filter_limits": False,
                                         "free_joints": [{"joint": 3, "values": [Q[3]]}]}).json()
    assert answer["solver"]["method"] == "numeric" and answer["solver"]["complete"] is False
    assert "q4 locked" in answer["detail"]


def test_free_joint_errors_read_as_before_on_the_wire(client):
    """The core speaks of free joints; the boundary words its errors with the request's field, as always."""
    pose = client.post("/v1/robots/ur5/fk", json={"joints": [0.1] * 6}).json()["pose"]["matrix"]
    body = assert_problem(client.post("/v1/robots/ur5/ik", json={"target": {"matrix": pose},
                                                                 "free_joints": [{"joint": 2, "values": [0]}]}), 422)
    assert body["errors"] == [{"loc": ["body", "free_joints"], "type": "value_error",
                               "msg": "free_joints applies to arms with more than 6 joints; this one has 6"}]


@pytest.mark.parametrize("robot_id", ["kuka_iiwa14", "franka_panda"])
def test_a_target_out_of_reach_of_a_urdf_arm_is_unreachable_not_a_500(client, robot_id):
    """The reach-sphere proof read DH lengths, which a URDF robot does not have: an empty answer of the free-joint
    family was a 500, in a single request and in a batch."""
    far = {"matrix": [[1, 0, 0, 5.0], [0, 1, 0, 5.0], [0, 0, 1, 5.0], [0, 0, 0, 1]]}
    single = client.post(f"/v1/robots/{robot_id}/ik", json={"target": far})
    assert single.status_code == 200, single.text
    assert single.json()["status"] == "unreachable" and "outside the workspace" in single.json()["detail"]
    batch = client.post(f"/v1/robots/{robot_id}/ik/batch", json={"targets": [far, far]})
    assert batch.status_code == 200, batch.text
    assert [r["status"] for r in batch.json()["results"]] == ["unreachable", "unreachable"]


#: A mobile manipulator's torso lift (0…0.6 m) under a 6R arm of general geometry (issue 22, 5.1): locking an arm
#: joint leaves a slide and five revolute joints, which no closed-form family covers and the general solver does.
TORSO_ARM = {"convention": "standard", "angle_unit": "rad", "length_unit": "m", "joints": [
    {"type": "prismatic", "a": 0.0, "alpha": 0.0, "d": 0.35, "theta": 0.0, "limits": {"lower": 0.0, "upper": 0.6}},
    {"type": "revolute", "a": 0.12, "alpha": -1.4, "d": 0.05, "theta": 0.3},
    {"type": "revolute", "a": 0.31, "alpha": 0.6, "d": -0.08, "theta": -0.2},
    {"type": "revolute", "a": 0.05, "alpha": 1.9, "d": 0.27, "theta": 0.9},
    {"type": "revolute", "a": 0.22, "alpha": -0.7, "d": 0.02, "theta": 0.1},
    {"type": "revolute", "a": 0.08, "alpha": 1.2, "d": 0.11, "theta": -0.6},
    {"type": "revolute", "a": 0.03, "alpha": -0.5, "d": 0.09, "theta": 0.4}]}
TORSO_Q = [0.27, 0.4, -0.9, 1.3, -0.5, 0.8, -1.1]


class _TorsoArm:
    is_revolute = np.array([False] + [True] * 6)


def test_a_torso_lift_and_6r_arm_with_an_arm_joint_free_is_solved_in_closed_form_at_the_values_asked(client):
    T = fk_inline(client, TORSO_ARM, TORSO_Q)
    values = [TORSO_Q[2], -0.3, 2.0]
    answer = client.post("/v1/ik", json={"robot": TORSO_ARM, "target": {"matrix": T.tolist()}, "filter_limits": False,
                                         "free_joints": [{"joint": 2, "values": values}]})
    assert answer.status_code == 200, answer.text
    answer = answer.json()
    assert answer["solver"]["method"] == "analytic" and answer["solver"]["complete"] is True
    assert answer["solver"]["structure"] == "general_5r1p with q3 free" and answer["free_joints"] == [2]
    joints = np.array([s["joints"] for s in answer["solutions"]])
    assert find(_TorsoArm(), joints, np.array(TORSO_Q)) is not None
    for solution in answer["solutions"]:  # every solution holds one of the values asked, and reaches the target
        assert solution["free_values"]["2"] == solution["joints"][2]
        assert min(abs(solution["joints"][2] - v) for v in values) == 0.0
        assert np.abs(fk_inline(client, TORSO_ARM, solution["joints"]) - T).max() < 1e-9
