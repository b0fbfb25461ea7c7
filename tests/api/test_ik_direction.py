"""The direction orientation of IK targets (api.md "Position and tool direction") and target_kinds."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from tests.conftest import assert_problem
from tests.ik_helpers import fk_inline

ARMS = json.loads((Path(__file__).parents[1] / "data" / "redundant_and_deficient_arms.json").read_text())
SO101 = ARMS["so101_like"]
Q = [20.0, -30.0, 45.0, 10.0, 35.0]  # degrees, as the description


def _target(T: np.ndarray, axis) -> dict:
    return {"position": T[:3, 3].tolist(),
            "orientation": {"type": "direction", "tool_axis": axis, "world_direction": (T[:3, :3] @ axis).tolist()}}


def test_direction_target_in_degrees_returns_the_generating_vector(client):
    T = fk_inline(client, SO101, np.radians(Q).tolist())
    answer = client.post("/v1/ik", json={"robot": SO101, "angle_unit": "deg", "filter_limits": False,
                                         "target": _target(T, [0, 1, 0])}).json()
    assert answer["status"] == "ok" and answer["solver"]["complete"] is True
    joints = np.array([s["joints"] for s in answer["solutions"]])
    assert np.abs(joints - Q).max(axis=1).min() < 1e-6
    for solution in answer["solutions"]:
        assert solution["residual"]["orientation"] < 1e-9


def test_the_roll_axis_leaves_the_roll_joint_free_at_the_reference(client):
    T = fk_inline(client, SO101, np.radians(Q).tolist())
    reference = [0, 0, 0, 0, 77.0]
    answer = client.post("/v1/ik", json={"robot": SO101, "angle_unit": "deg", "filter_limits": False,
                                         "reference": reference, "target": _target(T, [0, 0, 1])}).json()
    assert answer["free_joints"] == [4]
    assert all(s["free_values"] == {"4": 77.0} for s in answer["solutions"])
    assert any(np.abs(np.array(s["joints"][:4]) - Q[:4]).max() < 1e-6 for s in answer["solutions"])
    assert any(s["kind"] == "tool_roll" for s in answer["singularities"])


def test_direction_targets_are_refused_where_they_are_not_solved(client):
    # a 7-joint arm is solved over its free roll (tests/api/test_ik_direction_family.py); 4 joints are too few
    four = {"id": "four", "convention": "standard", "angle_unit": "rad",
            "joints": [{"type": "revolute", "a": 0.3, "alpha": 0, "theta": 0, "d": 0}] * 4}
    T = fk_inline(client, four, [0.1] * 4)
    assert_problem(client.post("/v1/ik", json={"robot": four, "target": _target(T, [0, 0, 1])}), 422,
                   loc=["body", "target", "orientation"], match="at least 5 joints")
    rolls = _target(T, [0, 0, 1])
    rolls["orientation"]["roll_samples"] = 8
    assert_problem(client.post("/v1/ik", json={"robot": SO101, "target": rolls}), 422,
                   loc=["body", "target", "orientation"], match="6 or more joints")
    zero = {"position": [0.1, 0, 0.1], "orientation": {"type": "direction", "world_direction": [0, 0, 0]}}
    assert_problem(client.post("/v1/ik", json={"robot": SO101, "target": zero}), 422,
                   loc=["body", "target", "orientation", "world_direction"])


def test_get_robot_lists_target_kinds(client):
    body = client.get("/v1/robots/ur5").json()
    assert body["target_kinds"] == ["pose", "position", "position_direction"]
