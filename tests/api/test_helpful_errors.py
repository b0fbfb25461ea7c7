"""Errors that say what to send instead: unknown robot ids, scalar-last quaternions, matrices of the wrong shape,
and FK poses sent back as IK targets as they stand."""

from __future__ import annotations

import numpy as np
import pytest

from service.kinematics import forward_kinematics, matrix_from_quaternion
from tests.conftest import assert_problem, catalogue_robot

UR5_Q = [0.1, -1.2, 1.0, 0.3, 1.5, 0.2]


# --------------------------------------------------------------------------- unknown robot ids


@pytest.mark.parametrize("robot_id, nearest", [
    ("ur-5", ["ur5"]), ("Ur_5", ["ur5"]), ("ur10", ["ur10e"]),
    ("puma", ["puma560_khalil", "puma560_modified", "puma560_standard"]),
    ("pumma560_standard", ["puma560_standard", "puma560_modified"]),
    ("stanford", ["spong_ex3_5_stanford"]),
])
def test_unknown_robot_lists_the_nearest_ids(client, robot_id, nearest):
    body = assert_problem(client.post(f"/v1/robots/{robot_id}/fk", json={"joints": [0] * 6}), 404,
                          match=f"No robot with id {robot_id!r}")
    assert body["nearest_ids"][:len(nearest)] == nearest
    assert f"Did you mean {nearest[0]!r}" in body["detail"]
    assert "GET /v1/robots lists all" in body["detail"]


def test_unknown_robot_without_a_near_id_says_where_the_list_is(client):
    body = assert_problem(client.get("/v1/robots/delta_robot_x"), 404, match="GET /v1/robots lists all")
    assert body["nearest_ids"] == [] and "Did you mean" not in body["detail"]


@pytest.mark.parametrize("robot_id", ["UR5", "Ur5", "PUMA560_Standard"])
def test_robot_ids_are_matched_case_insensitively(client, robot_id):
    described = client.get(f"/v1/robots/{robot_id}")
    assert described.status_code == 200 and described.json()["id"] == robot_id.lower()
    answer = client.post(f"/v1/robots/{robot_id}/fk", json={"joints": [0] * 6}).json()
    assert answer["robot_id"] == robot_id.lower()


# --------------------------------------------------------------------------- quaternion order


@pytest.mark.parametrize("orientation", [
    {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0},
    {"type": "quaternion", "x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0},
    {"type": "quaternion", "xyzw": [0.0, 0.0, 0.0, 1.0]},
    {"xyzw": [0.0, 0.0, 0.0, 1.0]},
])
def test_scalar_last_quaternions_get_the_order_the_service_takes(client, orientation):
    response = client.post("/v1/robots/ur5/ik", json={"target": {"position": [0.3, 0.2, 0.4],
                                                                 "orientation": orientation}})
    body = assert_problem(response, 422, loc=["body", "target", "orientation"], match="scalar first")
    assert '{"type": "quaternion", "wxyz": [1.0, 0.0, 0.0, 0.0]}' in body["detail"]
    assert "(x, y, z, w" in body["detail"] and "discriminator" not in body["detail"]


def test_scalar_last_hint_reorders_the_values_sent(client):
    orientation = {"x": 0.1, "y": 0.2, "z": 0.3, "w": 0.9}
    body = assert_problem(client.post("/v1/robots/ur5/ik", json={"target": {"position": [0.3, 0.2, 0.4],
                                                                            "orientation": orientation}}), 422)
    assert '"wxyz": [0.9, 0.1, 0.2, 0.3]' in body["detail"]


# --------------------------------------------------------------------------- matrix shapes


@pytest.mark.parametrize("matrix, message", [
    ([[1, 0, 0, 0.3], [0, 1, 0, 0.2], [0, 0, 1, 0.4]], "a 4×4 homogeneous transform is expected, got 3 rows"),
    ([[1, 0, 0, 0.3]] * 5, "a 4×4 homogeneous transform is expected, got 5 rows"),
    ([[1, 0, 0], [0, 1, 0], [0, 0, 1], [0, 0, 0]], "a 4×4 homogeneous transform is expected, row 0 has 3 entries"),
])
def test_a_target_matrix_of_the_wrong_shape_is_named(client, matrix, message):
    assert_problem(client.post("/v1/robots/ur5/ik", json={"target": {"matrix": matrix}}), 422,
                   loc=["body", "target", "matrix"], match=message)


def test_a_rotation_of_the_wrong_shape_is_named(client):
    target = {"position": [0.3, 0.2, 0.4], "orientation": {"type": "matrix", "matrix": [[1, 0, 0], [0, 1, 0]]}}
    assert_problem(client.post("/v1/robots/ur5/ik", json={"target": target}), 422,
                   loc=["body", "target", "orientation", "matrix"],
                   match="a 3×3 rotation matrix is expected, got 2 rows")


def test_a_robot_base_of_the_wrong_shape_is_named(client):
    robot = {"convention": "standard", "joints": [{"a": 1.0}], "base": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]}
    assert_problem(client.post("/v1/fk", json={"robot": robot, "joints": [0.0]}), 422,
                   loc=["body", "robot", "base"], match="got 3 rows")


# --------------------------------------------------------------------------- FK pose as IK target


def test_an_fk_pose_is_an_ik_target_as_it_stands(client):
    pose = client.post("/v1/robots/ur5/fk", json={"joints": UR5_Q}).json()["pose"]
    assert set(pose) == {"matrix", "position", "quaternion_wxyz"}
    answer = client.post("/v1/robots/ur5/ik", json={"target": pose, "reference": UR5_Q}).json()
    assert answer["status"] == "ok"
    np.testing.assert_allclose(answer["solutions"][0]["joints"], UR5_Q, atol=1e-9)
    robot = catalogue_robot(client, "ur5")
    for solution in answer["solutions"][:16]:
        np.testing.assert_allclose(forward_kinematics(robot, solution["joints"]), pose["matrix"], atol=1e-9)


def test_fk_batch_poses_are_ik_batch_targets_as_they_stand(client):
    rows = [UR5_Q, [0.5, -0.8, 1.2, -0.4, 1.1, 0.0]]
    poses = client.post("/v1/robots/ur5/fk/batch", json={"joints": rows}).json()["poses"]
    results = client.post("/v1/robots/ur5/ik/batch", json={"targets": poses, "reference": UR5_Q}).json()["results"]
    assert [r["status"] for r in results] == ["ok", "ok"]
    np.testing.assert_allclose(results[0]["solutions"][0]["joints"], UR5_Q, atol=1e-9)
    robot = catalogue_robot(client, "ur5")
    for result, pose in zip(results, poses):
        for solution in result["solutions"][:8]:
            np.testing.assert_allclose(forward_kinematics(robot, solution["joints"]), pose["matrix"], atol=1e-9)


def test_position_with_quaternion_wxyz_is_a_full_pose_target(client):
    pose = client.post("/v1/robots/ur5/fk", json={"joints": UR5_Q}).json()["pose"]
    target = {"position": pose["position"], "quaternion_wxyz": pose["quaternion_wxyz"]}
    answer = client.post("/v1/robots/ur5/ik", json={"target": target, "reference": UR5_Q}).json()
    np.testing.assert_allclose(answer["solutions"][0]["joints"], UR5_Q, atol=1e-9)
    assert answer["solutions"][0]["residual"]["orientation"] is not None


def test_a_quaternion_of_the_other_sign_is_the_same_rotation(client):
    pose = client.post("/v1/robots/ur5/fk", json={"joints": UR5_Q}).json()["pose"]
    flipped = {**pose, "quaternion_wxyz": [-value for value in pose["quaternion_wxyz"]]}
    assert client.post("/v1/robots/ur5/ik", json={"target": flipped}).status_code == 200


@pytest.mark.parametrize("field, value, message", [
    ("position", [0.0, 0.0, 0.0], "disagrees with the matrix's last column"),
    ("quaternion_wxyz", [1.0, 0.0, 0.0, 0.0], "disagrees with the matrix's rotation"),
])
def test_an_fk_pose_whose_parts_disagree_is_refused(client, field, value, message):
    pose = client.post("/v1/robots/ur5/fk", json={"joints": UR5_Q}).json()["pose"]
    assert_problem(client.post("/v1/robots/ur5/ik", json={"target": {**pose, field: value}}), 422,
                   loc=["body", "target", field], match=message)
    assert_problem(client.post("/v1/robots/ur5/ik/batch", json={"targets": [pose, {**pose, field: value}]}), 422,
                   loc=["body", "targets", 1, field], match=message)


def test_orientation_and_quaternion_wxyz_together_are_refused(client):
    target = {"position": [0.3, 0.2, 0.4], "quaternion_wxyz": [1, 0, 0, 0],
              "orientation": {"type": "quaternion", "wxyz": [1, 0, 0, 0]}}
    assert_problem(client.post("/v1/robots/ur5/ik", json={"target": target}), 422, match="not both")


def test_quaternion_wxyz_is_scalar_first(client):
    """[0, 0, 0, 1] is a half turn about z here (w = 0), the documented trap for scalar-last habits."""
    robot = catalogue_robot(client, "ur5")
    T = forward_kinematics(robot, np.array(UR5_Q))
    half_turn = {"position": T[:3, 3].tolist(), "quaternion_wxyz": [0.0, 0.0, 0.0, 1.0]}
    answer = client.post("/v1/robots/ur5/ik", json={"target": half_turn, "filter_limits": False}).json()
    for solution in answer["solutions"][:8]:
        np.testing.assert_allclose(forward_kinematics(robot, solution["joints"])[:3, :3],
                                   matrix_from_quaternion(np.array([0.0, 0.0, 0.0, 1.0])), atol=1e-9)


@pytest.mark.parametrize("path, body", [
    ("/v1/robots/ur5/fk", {"joints": UR5_Q, "frames": 0}),
    ("/v1/robots/ur5/ik", {"target": {"position": [0.3, 0.2, 0.4]}, "filter_limits": 1}),
])
def test_flags_are_json_booleans(client, path, body):
    """Found by schemathesis once the spec had examples to start from: 0 and 1 were read as false and true."""
    assert_problem(client.post(path, json=body), 422, loc=["body", next(iter(set(body) - {"joints", "target"}))])
