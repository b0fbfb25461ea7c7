"""A batch's targets as flat matrix rows (issue 24): ``{"matrices": [[16 numbers], ...]}`` answers exactly what
the same targets as objects answer, in both response forms; bad rows are 422s located at the row, and the batch
cap counts the rows."""

from __future__ import annotations

import numpy as np
import pytest
from fastapi.testclient import TestClient

from service.api.app import create_app
from service.config import Settings
from tests.conftest import assert_problem


def _poses(client, robot_id: str, count: int, seed: int) -> list[np.ndarray]:
    q = np.random.default_rng(seed).uniform(-np.pi, np.pi, (count, 6))
    poses = client.post(f"/v1/robots/{robot_id}/fk/batch", json={"joints": q.tolist()}).json()["poses"]
    return [np.array(pose["matrix"]) for pose in poses]


@pytest.mark.parametrize("form", ["objects", "arrays"])
@pytest.mark.parametrize("robot_id, options", [
    ("puma560_standard", {}),
    ("ur5", {"reference": [0.1, -1.0, 1.2, 0.0, 0.5, 0.0], "max_solutions": 3, "angle_unit": "rad"}),
    ("kuka_kr6_r900_2", {"filter_limits": False}),
])
def test_matrix_rows_answer_as_target_objects_do(client, robot_id, options, form):
    poses = _poses(client, robot_id, 12, seed=len(robot_id))
    as_objects = client.post(f"/v1/robots/{robot_id}/ik/batch", json={
        "targets": [{"matrix": T.tolist()} for T in poses], "format": form, **options})
    as_rows = client.post(f"/v1/robots/{robot_id}/ik/batch", json={
        "targets": {"matrices": [T.ravel().tolist() for T in poses]}, "format": form, **options})
    assert as_objects.status_code == as_rows.status_code == 200, as_rows.text
    assert as_rows.json() == as_objects.json()


@pytest.mark.parametrize("targets, location, words", [
    ({"matrices": [np.eye(4).ravel().tolist(), [2.0] + np.eye(4).ravel().tolist()[1:]]},
     ["body", "targets", "matrices", 1], "orthonormal"),
    ({"matrices": [[1.0, 0.0, 0.0]]}, ["body", "targets", "matrices", 0], "at least 16"),
    ({"matrices": [np.eye(4).ravel().tolist()[:15] + [float("nan")]]}, ["body", "targets", "matrices", 0, 15], None),
    ({"matrices": []}, ["body", "targets", "matrices"], "at least 1"),
    ({"matrices": [np.eye(4).ravel().tolist()], "extra": 1}, ["body", "targets", "extra"], "not permitted"),
    ([], ["body", "targets"], "at least 1"),
    (5, ["body", "targets"], "matrices"),
])
def test_bad_matrix_rows_are_422s_at_the_row(client, targets, location, words):
    import json

    body = json.dumps({"targets": targets}, allow_nan=True)  # NaN as JSON's NaN token, which strict parsing refuses
    response = client.post("/v1/robots/puma560_standard/ik/batch", content=body,
                           headers={"content-type": "application/json"})
    problem = assert_problem(response, 422)
    assert any(error["loc"] == location for error in problem["errors"]), problem["errors"]
    if words:
        assert words in response.text


def test_the_batch_cap_counts_matrix_rows():
    with TestClient(create_app(Settings(_env_file=None, max_batch=5))) as capped:
        rows = [np.eye(4).ravel().tolist()] * 6
        response = capped.post("/v1/robots/ur5/ik/batch", json={"targets": {"matrices": rows}})
        problem = assert_problem(response, 413)
        assert "targets has 6 rows" in problem["detail"]
