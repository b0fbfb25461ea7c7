"""Arms with two coaxial joints through the API (issue 22 item 1): FK-made targets come back with their
generating configuration, the pair's relation stated and its second joint listed free (api.md: at a
singularity the family is represented by the free joint at the reference value, and the coupling is stated).
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.ik_helpers import find, fk_inline, joints_of

#: Issue 22's request: a planar arm with a = 0, 1, 0, so joints 1 and 2 are one line and the tool point is on
#: axis 3; the target is its pose at q = (0.7, −1.1, 0.4). It was answered "unreachable" with complete: true.
ISSUE_ROBOT = {"id": "edge", "convention": "standard", "angle_unit": "rad", "joints": [
    {"type": "revolute", "a": 0, "alpha": 0, "theta": 0, "d": 0},
    {"type": "revolute", "a": 1, "alpha": 0, "theta": 0, "d": 0},
    {"type": "revolute", "a": 0, "alpha": 0, "theta": 0, "d": 0}]}
ISSUE_REQUEST = {"robot": ISSUE_ROBOT,
                 "target": {"matrix": [[1, 0, 0, 0.9210609940028851], [0, 1, 0, -0.3894183423086507], [0, 0, 1, 0],
                                       [0, 0, 0, 1]]},
                 "filter_limits": False, "reference": [0.7, -1.1, 0.4]}
#: The same arm in Craig's modified DH: row i holds a_{i-1}, α_{i-1}; no offset after the last axis.
ISSUE_ROBOT_MODIFIED = {"id": "edge-modified", "convention": "modified", "angle_unit": "rad", "joints": [
    {"type": "revolute", "a": 0, "alpha": 0, "theta": 0, "d": 0},
    {"type": "revolute", "a": 0, "alpha": 0, "theta": 0, "d": 0},
    {"type": "revolute", "a": 1, "alpha": 0, "theta": 0, "d": 0}]}


def planar_pose(q) -> np.ndarray:
    """world_T_tool of the issue's arm, by hand: unit link at angle q1 + q2, the tool turned by q1 + q2 + q3."""
    pose = np.eye(4)
    c, s = np.cos(q[0] + q[1] + q[2]), np.sin(q[0] + q[1] + q[2])
    pose[:2, :2] = [[c, -s], [s, c]]
    pose[:2, 3] = np.cos(q[0] + q[1]), np.sin(q[0] + q[1])
    return pose


@pytest.mark.parametrize("robot", [ISSUE_ROBOT, ISSUE_ROBOT_MODIFIED], ids=["standard", "modified"])
def test_the_issue_request_returns_its_generating_configuration(client, robot):
    reference = ISSUE_REQUEST["reference"]
    np.testing.assert_allclose(planar_pose(reference), ISSUE_REQUEST["target"]["matrix"], atol=1e-15)
    response = client.post("/v1/ik", json={**ISSUE_REQUEST, "robot": robot})
    assert response.status_code == 200, response.text
    answer = response.json()
    assert answer["status"] == "ok", answer.get("detail")
    assert answer["solver"]["method"] == "analytic" and answer["solver"]["complete"] is True
    assert answer["free_joints"] == [1]
    assert [(s["kind"], s["joints"], s["relation"]) for s in answer["singularities"]] == [("coaxial", [0, 1], "sum")]
    solutions = joints_of(answer)
    np.testing.assert_allclose(solutions, [reference], atol=1e-12)
    assert answer["solutions"][0]["free_values"] == {"1": pytest.approx(-1.1, abs=1e-12)}
    np.testing.assert_allclose(planar_pose(solutions[0]), ISSUE_REQUEST["target"]["matrix"], atol=1e-12)


def test_without_a_reference_the_second_joint_of_the_pair_is_held_at_zero(client):
    body = {key: value for key, value in ISSUE_REQUEST.items() if key != "reference"}
    answer = client.post("/v1/ik", json=body).json()
    assert answer["status"] == "ok" and answer["solver"]["complete"] is True
    np.testing.assert_allclose(joints_of(answer), [[0.7 - 1.1, 0.0, 0.4]], atol=1e-12)


def test_a_position_target_of_the_issue_arm_lists_both_joints_it_leaves_free(client):
    """A position fixes only q1 + q2: q2 (the pair) and q3 (the tool point is on its axis) are free and take
    the reference values."""
    reference = [0.7, -1.1, 0.4]
    answer = client.post("/v1/ik", json={"robot": ISSUE_ROBOT, "target": {"position": [0.9210609940028851,
                                                                                      -0.3894183423086507, 0.0]},
                                         "filter_limits": False, "reference": reference}).json()
    assert answer["status"] == "ok" and answer["solver"]["complete"] is True
    assert answer["free_joints"] == [1, 2]
    np.testing.assert_allclose(joints_of(answer), [reference], atol=1e-12)


#: A 7-joint arm whose redundancy is a coaxial pair: a base joint on the UR5's first axis (standard DH row 1
#: with a = 0, α = 0), then the UR5's published table.
UR5_WITH_A_COAXIAL_BASE = {"id": "ur5-coaxial-base", "convention": "standard", "angle_unit": "rad", "joints": [
    {"type": "revolute", "a": 0.0, "alpha": 0.0, "d": 0.05, "theta": 0.0},
    {"type": "revolute", "a": 0.0, "alpha": np.pi / 2, "d": 0.039159, "theta": 0.0},
    {"type": "revolute", "a": -0.425, "alpha": 0.0, "d": 0.0, "theta": 0.0},
    {"type": "revolute", "a": -0.39225, "alpha": 0.0, "d": 0.0, "theta": 0.0},
    {"type": "revolute", "a": 0.0, "alpha": np.pi / 2, "d": 0.10915, "theta": 0.0},
    {"type": "revolute", "a": 0.0, "alpha": -np.pi / 2, "d": 0.09465, "theta": 0.0},
    {"type": "revolute", "a": 0.0, "alpha": 0.0, "d": 0.0823, "theta": 0.0}]}


def test_a_seven_joint_arm_whose_redundancy_is_a_coaxial_pair_answers_as_a_six_joint_arm(client):
    """Every value of a free joint would give the UR5's 8 solutions again, split differently between q1 and
    q2: the answer is those 8, complete, with q2 at the reference, the relation stated and q2 listed free."""
    q = np.array([0.4, -0.9, -1.2, 1.0, 0.6, -0.8, 2.1])
    target = fk_inline(client, UR5_WITH_A_COAXIAL_BASE, q)
    response = client.post("/v1/ik", json={"robot": UR5_WITH_A_COAXIAL_BASE, "target": {"matrix": target.tolist()},
                                           "filter_limits": False, "reference": q.tolist()})
    assert response.status_code == 200, response.text
    answer = response.json()
    assert answer["status"] == "ok" and answer["solver"]["complete"] is True
    assert answer["solver"]["method"] == "analytic"
    assert answer["free_joints"] == [1]
    assert any(s["kind"] == "coaxial" and s["joints"] == [0, 1] for s in answer["singularities"])
    solutions = joints_of(answer)
    assert len(solutions) == 8
    np.testing.assert_allclose(solutions[:, 1], q[1], atol=1e-12)
    assert find(_SevenRevolute(), solutions[:1], q) is not None  # nearest first: the generating configuration
    for joints in solutions:
        np.testing.assert_allclose(fk_inline(client, UR5_WITH_A_COAXIAL_BASE, joints), target, atol=1e-9)


class _SevenRevolute:
    is_revolute = np.ones(7, dtype=bool)


def test_a_free_joint_named_on_that_arm_leaves_the_pair_held(client):
    """With q7 named free, the locked arm still holds a coaxial pair: its closed form (the pair's second joint
    at the reference) answers at each value asked, and q2 is listed free beside q7. (The family was refused as
    degenerate, because its probe pose held q2 at 0, and the numeric search answered, complete: false.)"""
    q = np.array([0.4, -0.9, -1.2, 1.0, 0.6, -0.8, 2.1])
    target = fk_inline(client, UR5_WITH_A_COAXIAL_BASE, q)
    answer = client.post("/v1/ik", json={"robot": UR5_WITH_A_COAXIAL_BASE, "target": {"matrix": target.tolist()},
                                         "filter_limits": False, "reference": q.tolist(),
                                         "free_joints": [{"joint": 6, "values": [2.1, 0.0]}]}).json()
    assert answer["status"] == "ok" and answer["solver"]["method"] == "analytic"
    assert answer["solver"]["complete"] is True and answer["free_joints"] == [1, 6]
    solutions = joints_of(answer)
    assert find(_SevenRevolute(), solutions, q) is not None
    for solution in answer["solutions"]:
        assert solution["free_values"]["1"] == pytest.approx(q[1], abs=1e-12)
        assert solution["free_values"]["6"] == solution["joints"][6]
        np.testing.assert_allclose(fk_inline(client, UR5_WITH_A_COAXIAL_BASE, solution["joints"]), target,
                                   atol=1e-9)


@pytest.mark.parametrize("rows", [
    # a planar 3R arm whose joints 1 and 2 are one line, carrying a 3R wrist (no closed form covers the arm
    # without joint 2: it went to the three-parallel family, which listed one member of the family, unflagged)
    [{"type": "revolute"}, {"type": "revolute", "a": 0.3}, {"type": "revolute", "alpha": np.pi / 2},
     {"type": "revolute", "alpha": np.pi / 2}, {"type": "revolute", "a": 0.3}, {"type": "revolute"}],
])
def test_a_coaxial_pair_no_closed_form_covers_is_still_stated(client, rows):
    """Two coaxial joints fix only their sum, whatever covers the rest of the arm: when no closed form covers
    the arm without the pair's second joint, the numeric search answers, and the pair's relation is stated and
    its second joint listed free, held at the reference value."""
    robot = {"convention": "standard", "joints": rows}
    q = [0.5, 0.3, 0.5, 0.5, 0.5, 0.5]
    pose = client.post("/v1/fk", json={"robot": robot, "joints": q}).json()["pose"]
    answer = client.post("/v1/ik", json={"robot": robot, "target": pose, "reference": q}).json()
    assert answer["status"] == "ok", answer["detail"]
    assert answer["free_joints"] == [1]
    assert [(s["kind"], s["joints"], s["relation"]) for s in answer["singularities"]] == [("coaxial", [0, 1], "sum")]
    assert (np.abs((joints_of(answer) - q + np.pi) % (2 * np.pi) - np.pi).max(axis=1) <= 1e-6).any()
