"""Forward kinematics through HTTP: textbook vectors, closed forms, conventions, batch and units."""

from __future__ import annotations

import json

import numpy as np
import pytest

from service.api.schemas.fk import FKBatchResponse, FKResponse
from tests.conftest import DATA, assert_problem
from tests.oracles.closed_forms import CLOSED_FORMS
from tests.oracles.rotations import matrix_of_quaternion


def _fk(client, robot_id, joints, **extra):
    response = client.post(f"/v1/robots/{robot_id}/fk", json={"joints": list(map(float, joints)), **extra})
    assert response.status_code == 200, response.text
    body = response.json()
    # encoded without the response model: it must be exactly what the model would write
    assert FKResponse.model_validate(body).model_dump(mode="json", exclude_none=True) == body
    return body


def test_every_textbook_fk_vector(client, textbook_fk_vectors):
    """textbook.md §8: every printed matrix (6 significant digits)."""
    checked = 0
    for robot_id, vectors in textbook_fk_vectors.items():
        for vector in vectors:
            pose = _fk(client, robot_id, vector["joints"])["pose"]
            expected = np.array(vector["matrix"])
            np.testing.assert_allclose(pose["matrix"], expected, atol=5e-6 * max(1.0, np.abs(expected).max()),
                                       err_msg=f"{robot_id} at {vector['joints']}")
            checked += 1
    assert checked >= 3 * 17


@pytest.mark.parametrize("robot_id", sorted(CLOSED_FORMS))
def test_closed_form_matrices_at_random_joint_vectors(client, robot_id):
    """textbook.md §2–6 (the corrected matrices) at 50 seeded random joint vectors, in one batch call."""
    dof = len(client.get(f"/v1/robots/{robot_id}").json()["joints"])
    rng = np.random.default_rng(0)
    q = rng.uniform(-np.pi, np.pi, (50, dof))
    response = client.post(f"/v1/robots/{robot_id}/fk/batch", json={"joints": q.tolist()})
    assert response.status_code == 200, response.text
    for row, pose in zip(q, response.json()["poses"]):
        expected = CLOSED_FORMS[robot_id](row)
        np.testing.assert_allclose(pose["matrix"], expected, rtol=0, atol=1e-9 * max(1.0, np.abs(expected).max()))


def test_puma_craig_khalil_and_standard_forms_agree(client):
    """The three PUMA tables give one physical pose, by the relations recorded in puma_frame_alignment.json."""
    relations = json.loads((DATA / "puma_frame_alignment.json").read_text())["relations"]
    rng = np.random.default_rng(5)
    for relation in relations:
        offset = np.radians(relation["joint_offset_deg"])
        to_base_T_from_base = np.array(relation["to_base_T_from_base"])
        from_flange_T_to_flange = np.array(relation["from_flange_T_to_flange"])
        for q in rng.uniform(-np.pi, np.pi, (20, 6)):
            source = np.array(_fk(client, relation["from"], q)["pose"]["matrix"])
            target = np.array(_fk(client, relation["to"], q + offset)["pose"]["matrix"])
            np.testing.assert_allclose(target, to_base_T_from_base @ source @ from_flange_T_to_flange, atol=1e-12)


def test_batch_equals_single_calls(client):
    rng = np.random.default_rng(6)
    q = rng.uniform(-2, 2, (7, 6))
    batch = client.post("/v1/robots/spong_ex3_5_stanford/fk/batch", json={"joints": q.tolist()}).json()["poses"]
    for row, pose in zip(q, batch):
        assert pose == _fk(client, "spong_ex3_5_stanford", row)["pose"]


@pytest.mark.parametrize("rows", [1, 300, 3000])
def test_the_batch_answer_is_its_response_model(client, rows):
    """The batch's answer is built field by field, not through FKBatchResponse: it must be what the model says, in
    degrees and with a tool too, for a small body (answered where it arrives) and a large one (on a work loop)."""
    q = np.random.default_rng(rows).uniform(-180, 180, (rows, 6))
    tool = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.1], [0.0, 0.0, 0.0, 1.0]]
    body = {"joints": q.tolist(), "angle_unit": "deg", "tool": tool}
    response = client.post("/v1/robots/ur5/fk/batch", json=body)
    assert response.status_code == 200, response.text
    answer = response.json()
    assert FKBatchResponse.model_validate(answer).model_dump(mode="json") == answer
    assert answer["robot_id"] == "ur5" and len(answer["poses"]) == rows
    assert answer["poses"][-1] == _fk(client, "ur5", q[-1], angle_unit="deg", tool=body["tool"])["pose"]


def test_degrees_equal_radians_and_prismatic_joints_are_not_converted(client):
    q = np.array([0.5, 0.4, 0.6, -0.7, 1.1, -0.4])  # cylindrical with wrist: R P P R R R
    in_degrees = q.copy()
    in_degrees[[0, 3, 4, 5]] = np.degrees(q[[0, 3, 4, 5]])
    radians = _fk(client, "spong_ex3_4_cylindrical_with_wrist", q)["pose"]
    degrees = _fk(client, "spong_ex3_4_cylindrical_with_wrist", in_degrees, angle_unit="deg")["pose"]
    np.testing.assert_allclose(degrees["matrix"], radians["matrix"], atol=1e-14)


def test_pose_forms_agree(client):
    pose = _fk(client, "puma560_modified", [0.5, -0.7, 1.1, -0.4, 0.9, -1.3])["pose"]
    T = np.array(pose["matrix"])
    w, x, y, z = pose["quaternion_wxyz"]
    R = matrix_of_quaternion(w, x, y, z)
    assert w >= 0
    np.testing.assert_allclose(R, T[:3, :3], atol=1e-12)
    np.testing.assert_allclose(pose["position"], T[:3, 3])


def test_frames_list_every_link_frame(client):
    body = _fk(client, "spong_ex4_3_elbow_with_wrist", [0.5, -0.7, 1.1, -0.4, 0.9, -1.3], frames=True)
    joint_names = [joint["name"] for joint in client.get("/v1/robots/spong_ex4_3_elbow_with_wrist").json()["joints"]]
    assert [frame["name"] for frame in body["frames"]] == ["base", *joint_names, "tool"]
    assert body["frames"][-1]["matrix"] == body["pose"]["matrix"]
    np.testing.assert_allclose(body["frames"][1]["position"], [0, 0, 0.5], atol=1e-15)  # o1 = (0, 0, d1)


def test_inline_robot_equals_catalogue_robot(client):
    description = client.get("/v1/robots/puma560_khalil").json()
    q = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]
    inline = client.post("/v1/fk", json={"joints": q, "robot": description})
    assert inline.status_code == 200, inline.text
    assert inline.json()["pose"] == _fk(client, "puma560_khalil", q)["pose"]


def test_inline_robot_with_base_and_tool(client):
    robot = {"convention": "standard", "joints": [{"a": 1.0}, {"a": 0.5}],
             "base": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 2.0], [0, 0, 0, 1]],
             "tool": [[1, 0, 0, 0.25], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}
    pose = client.post("/v1/fk", json={"joints": [0, 0], "robot": robot}).json()["pose"]
    np.testing.assert_allclose(pose["position"], [1.75, 0, 2.0])


# --- errors -----------------------------------------------------------------------------------

def test_unknown_robot_is_404(client):
    assert_problem(client.post("/v1/robots/no_such_robot/fk", json={"joints": [0]}), 404, match="no_such_robot")


def test_wrong_number_of_joints_is_422(client):
    assert_problem(client.post("/v1/robots/spong_ex3_1_planar_rr/fk", json={"joints": [0, 0, 0]}), 422,
                   loc=["body", "joints"], match="2 joints")


@pytest.mark.parametrize("literal", ["NaN", "Infinity", "-Infinity", "1e999"])
def test_non_finite_joint_values_are_422(client, literal):
    response = client.post("/v1/robots/spong_ex3_1_planar_rr/fk", content=f'{{"joints": [0.1, {literal}]}}',
                           headers={"content-type": "application/json"})
    assert_problem(response, 422, loc=["body", "joints", 1], match="finite")


def test_strings_and_unknown_fields_are_422(client):
    assert_problem(client.post("/v1/robots/spong_ex3_1_planar_rr/fk", json={"joints": [0, "1"]}), 422,
                   loc=["body", "joints", 1])
    assert_problem(client.post("/v1/robots/spong_ex3_1_planar_rr/fk", json={"joints": [0, 1], "jionts": 1}), 422,
                   loc=["body", "jionts"])


def test_malformed_inline_robots_are_422(client):
    bad_limits = {"convention": "standard", "joints": [{"a": 1, "limits": {"lower": 2, "upper": 1}}]}
    assert_problem(client.post("/v1/fk", json={"joints": [0], "robot": bad_limits}), 422, match="greater than upper")
    unknown_convention = {"convention": "paul", "joints": [{"a": 1}]}
    assert_problem(client.post("/v1/fk", json={"joints": [0], "robot": unknown_convention}), 422,
                   loc=["body", "robot"])
    no_joints = {"convention": "standard", "joints": []}
    assert_problem(client.post("/v1/fk", json={"joints": [], "robot": no_joints}), 422, loc=["body", "robot"])
    bad_base = {"convention": "standard", "joints": [{"a": 1}],
                "base": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, -1, 0], [0, 0, 0, 1]]}  # determinant -1
    assert_problem(client.post("/v1/fk", json={"joints": [0], "robot": bad_base}), 422,
                   loc=["body", "robot", "base"])


def test_batch_rows_are_checked(client):
    response = client.post("/v1/robots/spong_ex3_1_planar_rr/fk/batch", json={"joints": [[0, 0], [0, 0, 0]]})
    assert_problem(response, 422, loc=["body", "joints", 1])


def test_the_wire_pose_of_one_matrix_is_the_stacks():
    """pose_from_matrix (a single FK's encoding, on floats) gives each matrix of a stack the wire pose
    poses_from_matrices gives it: the same matrix rows and position, and the same quaternion (the float formula
    against the array one: within 4e-16), on random transforms, half turns and the identity."""
    from service.api.boundary import pose_from_matrix, poses_from_matrices
    from tests.arms import random_rigid

    rng = np.random.default_rng(47)
    stack = [random_rigid(rng, 2.0) for _ in range(40)]
    for diagonal in ([1.0, 1.0, 1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0], [1.0, -1.0, -1.0]):
        T = np.eye(4)
        T[:3, :3] = np.diag(diagonal)
        T[:3, 3] = rng.normal(size=3)
        stack.append(T)
    for T, expected in zip(stack, poses_from_matrices(np.stack(stack))):
        one = pose_from_matrix(T)
        assert set(one) == set(expected)
        assert one["matrix"] == expected["matrix"] and one["position"] == expected["position"]
        np.testing.assert_allclose(one["quaternion_wxyz"], expected["quaternion_wxyz"], rtol=0, atol=4e-16)
