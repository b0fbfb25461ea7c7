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
