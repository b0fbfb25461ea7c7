"""Position-only targets of arms with more than three joints: no reachable point answered `unreachable`.

Points come from the arm's own FK at random joint vectors, so each is reachable; the held joints (at 0, no
reference) usually cannot reach it. The answer must then give solutions (complete: false, saying why), never
`unreachable`. Points beyond the reach sphere stay `unreachable` with complete: true.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from tests.ik_helpers import fk_inline

ARMS = json.loads((Path(__file__).parents[1] / "data" / "redundant_and_deficient_arms.json").read_text())
UR5 = "ur5"


@pytest.mark.parametrize("name", ["iiwa14", "panda"])
def test_no_reachable_point_of_a_seven_joint_arm_is_unreachable(client, name):
    robot = ARMS[name]
    rng = np.random.default_rng(5)
    for _ in range(3):
        q = rng.uniform(-1.5, 1.5, 7)
        point = fk_inline(client, robot, q.tolist())[:3, 3]
        answer = client.post("/v1/ik", json={"robot": robot, "target": {"position": point.tolist()},
                                             "filter_limits": False}).json()
        assert answer["status"] == "ok", answer["detail"]
        for solution in answer["solutions"]:
            reached = fk_inline(client, robot, solution["joints"])[:3, 3]
            assert np.linalg.norm(reached - point) < 1e-8


def test_no_reachable_point_of_a_six_joint_arm_is_unreachable(client):
    rng = np.random.default_rng(6)
    for _ in range(8):
        q = rng.uniform(-np.pi, np.pi, 6)
        pose = client.post(f"/v1/robots/{UR5}/fk", json={"joints": q.tolist()}).json()["pose"]["matrix"]
        point = np.array(pose)[:3, 3]
        answer = client.post(f"/v1/robots/{UR5}/ik", json={"target": {"position": point.tolist()},
                                                           "filter_limits": False}).json()
        assert answer["status"] == "ok", answer["detail"]
        if not answer["solver"]["complete"]:  # found by the search over every joint, and it says so
            assert "held" in answer["detail"]


def test_a_point_beyond_reach_is_unreachable_and_complete(client):
    answer = client.post("/v1/ik", json={"robot": ARMS["iiwa14"], "target": {"position": [0, 0, 2.0]}}).json()
    assert answer["status"] == "unreachable" and answer["solver"]["complete"] is True
    assert "outside the workspace" in answer["detail"]


def test_the_arrays_batch_form_searches_too(client):
    rng = np.random.default_rng(8)
    points = []
    for _ in range(4):
        pose = client.post(f"/v1/robots/{UR5}/fk", json={"joints": rng.uniform(-np.pi, np.pi, 6).tolist()}).json()
        points.append(np.array(pose["pose"]["matrix"])[:3, 3].tolist())
    body = {"targets": [{"position": p} for p in points] + [{"position": [0, 0, 5.0]}], "filter_limits": False}
    arrays = client.post(f"/v1/robots/{UR5}/ik/batch", json={**body, "format": "arrays"}).json()
    objects = client.post(f"/v1/robots/{UR5}/ik/batch", json=body).json()["results"]
    assert arrays["targets"]["status"] == [r["status"] for r in objects] == ["ok"] * 4 + ["unreachable"]
    assert any(r["solver"]["method"] == "numeric" for r in objects)  # some point needed the search
    assert arrays["targets"]["solution_count"] == [len(r["solutions"]) for r in objects]
    for row, result in enumerate(objects):
        assert arrays["solvers"][arrays["targets"]["solver"][row]]["complete"] == result["solver"]["complete"]
    for target, result in enumerate(objects):
        rows = [i for i, t in enumerate(arrays["solutions"]["target"]) if t == target]
        joints = np.array(arrays["solutions"]["joints"]).reshape(-1, 6)[rows]
        assert np.allclose(joints, np.array([s["joints"] for s in result["solutions"]]).reshape(-1, 6))
        for row, solution in zip(rows, result["solutions"]):  # the free_values column, as the objects form
            columns = {key: column[row] for key, column in arrays["solutions"]["free_values"].items()
                       if column[row] is not None}
            assert columns == solution["free_values"]
