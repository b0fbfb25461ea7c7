"""URDF and joint-screw descriptions, descriptions out (``?form=``), per-request base and tool.

* Every DH catalogue robot restated as screws and as URDF gives the same FK and the same IK solution sets as its
  DH table (the URDF in metres: lengths compared after scaling).
* Per-request base and tool equal the same robot with them in its description.
* URDF errors name the joint or link; hostile XML gets a 4xx and the server keeps answering.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from service.robots.export import METRES_PER_UNIT
from tests.conftest import assert_problem
from tests.ik_helpers import wrapped

RNG_SEED = 13


def _catalogue(client) -> list[dict]:
    return client.get("/v1/robots").json()["robots"]


def _dh_ids(client) -> list[str]:
    return [r["id"] for r in _catalogue(client) if r["format"] == "dh"]


def _fk(client, robot: dict, q, **extra) -> np.ndarray:
    response = client.post("/v1/fk", json={"robot": robot, "joints": list(q), **extra})
    assert response.status_code == 200, response.text
    return np.array(response.json()["pose"]["matrix"])


def _ik(client, robot: dict, target: dict, **extra) -> dict:
    response = client.post("/v1/ik", json={"robot": robot, "target": target, "filter_limits": False, **extra})
    assert response.status_code == 200, response.text
    return response.json()


def _target(T: np.ndarray, dof: int) -> dict:
    return {"matrix": T.tolist()} if dof >= 6 else {"position": T[:3, 3].tolist()}


def _same_solution_sets(a: list[dict], b: list[dict], revolute: np.ndarray, tol: float = 1e-7) -> None:
    """Every solution of ``a`` is in ``b`` and the other way round (revolute joints compared across 2π)."""
    assert len(a) == len(b), (len(a), len(b))
    if not a:
        return
    A = np.array([s["joints"] for s in a])
    B = np.array([s["joints"] for s in b])
    delta = A[:, None, :] - B[None, :, :]
    delta = np.where(revolute, wrapped(delta), delta)
    distance = np.abs(delta).max(axis=2)
    assert distance.min(axis=1).max() < tol and distance.min(axis=0).max() < tol, distance.min(axis=1).max()


def test_every_dh_robot_as_screws_and_urdf_gives_the_same_fk_and_ik(client):
    rng = np.random.default_rng(RNG_SEED)
    checked = {"screws": 0, "urdf": 0}
    for robot_id in _dh_ids(client):
        dh = client.get(f"/v1/robots/{robot_id}").json()
        revolute = np.array([j["type"] == "revolute" for j in dh["joints"]])
        dof = len(revolute)
        forms = {"screws": client.get(f"/v1/robots/{robot_id}", params={"form": "screws"})}
        forms["urdf"] = client.get(f"/v1/robots/{robot_id}", params={"form": "urdf"})
        assert forms["screws"].status_code == 200, forms["screws"].text
        half_open = any(j.get("limits") and (j["limits"]["lower"] is None) != (j["limits"]["upper"] is None)
                        for j in dh["joints"])
        if half_open:  # URDF cannot state a limit on one side only
            assert_problem(forms["urdf"], 422, loc=["query", "form"], match="one side")
            del forms["urdf"]
        else:
            assert forms["urdf"].status_code == 200, forms["urdf"].text
        metres = METRES_PER_UNIT[dh["length_unit"]]
        for q in rng.uniform(-math.pi, math.pi, (2, dof)):
            q = np.where(revolute, q, q * 0.3)
            T = _fk(client, dh, q)
            reference = _ik(client, dh, _target(T, dof))
            assert reference["solutions"], robot_id
            for form, response in forms.items():
                other = response.json()
                scale = metres if form == "urdf" else 1.0
                q_other = np.where(revolute, q, q * scale)
                T_other = _fk(client, other, q_other)
                expected = T.copy()
                expected[:3, 3] *= scale
                np.testing.assert_allclose(T_other, expected, atol=1e-12 * max(1.0, scale * 1e3), rtol=0,
                                           err_msg=f"{robot_id} as {form}")
                answer = _ik(client, other, _target(expected, dof))
                assert answer["solver"]["method"] == reference["solver"]["method"], (robot_id, form)
                assert answer["solver"]["complete"] == reference["solver"]["complete"], (robot_id, form)
                for solution in answer["solutions"]:
                    solution["joints"] = np.where(revolute, solution["joints"],
                                                  np.array(solution["joints"]) / scale).tolist()
                if reference["solver"]["complete"]:  # a numeric search (xArm 6) promises no particular set
                    _same_solution_sets(answer["solutions"], reference["solutions"], revolute)
                checked[form] += 1
    assert checked["screws"] >= 2 * 20 and checked["urdf"] >= 2 * 14, checked


def test_forms_round_trip_and_refuse_what_is_not_exact(client):
    # A Khalil table is a Craig table renamed: exact both ways.
    modified = client.get("/v1/robots/puma560_khalil", params={"form": "modified"}).json()
    assert modified["convention"] == "modified"
    craig = client.get("/v1/robots/puma560_modified").json()
    q = [0.3, -0.4, 0.5, 0.6, -0.7, 0.8]
    np.testing.assert_allclose(_fk(client, modified, q), _fk(client, craig, q), atol=1e-14)
    # ur5's last row has a = alpha = 0: as a modified table the flange stays where it is.
    ur5 = client.get("/v1/robots/ur5").json()
    as_modified = client.get("/v1/robots/ur5", params={"form": "modified"}).json()
    assert as_modified["convention"] == "modified"
    np.testing.assert_allclose(_fk(client, as_modified, q), _fk(client, ur5, q), atol=1e-14)
    back = client.get("/v1/robots/ur5", params={"form": "standard"}).json()
    assert back == ur5
    # The Stanford arm's first standard row has alpha = -90°, so as a modified table... exact; PUMA standard
    # has a3 in its third row but an empty last row; a standard robot with a twisted last row is refused:
    twisted = client.get("/v1/robots/spong_ex3_1_planar_rr", params={"form": "modified"})
    assert_problem(twisted, 422, loc=["query", "form"], match="last row")
    # URDF and screws robots have no DH table.
    for robot_id in ("franka_panda", "unitree_z1"):
        for form in ("dh", "standard", "modified"):
            assert_problem(client.get(f"/v1/robots/{robot_id}", params={"form": form}), 422, match="no DH table")
        screws = client.get(f"/v1/robots/{robot_id}", params={"form": "screws"}).json()
        urdf = client.get(f"/v1/robots/{robot_id}", params={"form": "urdf"}).json()
        native = client.get(f"/v1/robots/{robot_id}").json()
        dof = len(screws["joints"])
        for q in np.random.default_rng(1).uniform(-1, 1, (5, dof)):
            T = _fk(client, native, q)
            np.testing.assert_allclose(_fk(client, screws, q), T, atol=1e-13)
            np.testing.assert_allclose(_fk(client, urdf, q), T, atol=1e-13)
    assert_problem(client.get("/v1/robots/ur5", params={"form": "mdh"}), 422, loc=["query", "form"])


def _random_transform(rng) -> list[list[float]]:
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    angle = rng.uniform(-math.pi, math.pi)
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    T = np.eye(4)
    T[:3, :3] = np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K
    T[:3, 3] = rng.uniform(-0.3, 0.3, 3)
    return T.tolist()


@pytest.mark.parametrize("robot_id", ["ur5e", "puma560_modified", "kinova_jaco2", "so101", "spong_ex3_5_stanford"])
def test_per_request_base_and_tool_equal_the_robot_with_them_in_its_description(client, robot_id):
    rng = np.random.default_rng(7)
    description = client.get(f"/v1/robots/{robot_id}").json()
    base, tool = _random_transform(rng), _random_transform(rng)
    with_frames = {**description, "base": base, "tool": tool}
    robot = client.get("/v1/robots").json()["robots"]
    dof = next(r["dof"] for r in robot if r["id"] == robot_id)
    q = rng.uniform(-1, 1, dof).tolist()
    per_request = client.post(f"/v1/robots/{robot_id}/fk", json={"joints": q, "base": base, "tool": tool}).json()
    inline = client.post("/v1/fk", json={"robot": with_frames, "joints": q}).json()
    np.testing.assert_allclose(per_request["pose"]["matrix"], inline["pose"]["matrix"], atol=1e-14)
    plain = client.post(f"/v1/robots/{robot_id}/fk", json={"joints": q}).json()
    assert not np.allclose(plain["pose"]["matrix"], inline["pose"]["matrix"])  # the tool did change the answer
    # the inline twin takes them too, and they replace the description's own
    replaced = client.post("/v1/fk", json={"robot": {**description, "tool": _random_transform(rng)}, "joints": q,
                                            "base": base, "tool": tool}).json()
    np.testing.assert_allclose(replaced["pose"]["matrix"], inline["pose"]["matrix"], atol=1e-14)
    batch = client.post(f"/v1/robots/{robot_id}/fk/batch", json={"joints": [q], "base": base, "tool": tool}).json()
    np.testing.assert_allclose(batch["poses"][0]["matrix"], inline["pose"]["matrix"], atol=1e-14)

    target = {"matrix": inline["pose"]["matrix"]} if dof >= 6 else {"position": inline["pose"]["position"]}
    ik = client.post(f"/v1/robots/{robot_id}/ik", json={"target": target, "base": base, "tool": tool,
                                                          "filter_limits": False}).json()
    ik_inline = _ik(client, with_frames, target)
    revolute = np.array([j.get("type", "revolute") == "revolute" for j in description.get("joints", [])] or
                        [True] * dof)
    if len(revolute) != dof:
        revolute = np.ones(dof, dtype=bool)
    assert ik["solutions"], ik
    _same_solution_sets(ik["solutions"], ik_inline["solutions"], revolute)
    if dof == 6:  # a 6-DOF arm has finitely many solutions, and q is one of them
        assert any(np.allclose(s["joints"], q, atol=1e-7) for s in ik["solutions"])
    batch_ik = client.post(f"/v1/robots/{robot_id}/ik/batch", json={"targets": [target], "base": base, "tool": tool,
                                                                    "filter_limits": False}).json()
    _same_solution_sets(batch_ik["results"][0]["solutions"], ik_inline["solutions"], revolute)
    limits = client.post(f"/v1/robots/{robot_id}/limits", json={"joints": [q], "base": base, "tool": tool})
    assert limits.status_code == 200 and limits.json()["joint_names"] == ik["joint_names"]
    assert ik["joint_names"] == per_request["joint_names"] == inline["joint_names"]


def test_per_request_frames_are_validated_like_every_transform(client):
    skewed = np.eye(4)
    skewed[0, 1] = 0.1
    response = client.post("/v1/robots/ur5/fk", json={"joints": [0] * 6, "tool": skewed.tolist()})
    assert_problem(response, 422, loc=["body", "tool"])
    response = client.post("/v1/robots/ur5/ik", json={"target": {"position": [0.3, 0.1, 0.2]},
                                                      "base": [[1, 0, 0, 0]] * 4})
    assert_problem(response, 422, loc=["body", "base"])
    trajectory = client.post("/v1/robots/ur5/ik/trajectory",
                             json={"samples": [{"time": 0, "pose": {"position": [0.3, 0.1, 0.2]}}],
                                   "tool": skewed.tolist()})
    assert_problem(trajectory, 422, loc=["body", "tool"])


def test_trajectory_takes_the_request_tool(client):
    tool = np.eye(4)
    tool[:3, 3] = [0.0, 0.0, 0.1]
    description = client.get("/v1/robots/ur5e").json()
    q = [0.2, -1.0, 1.2, -0.5, 1.1, 0.3]
    pose = _fk(client, {**description, "tool": tool.tolist()}, q)
    body = {"samples": [{"time": 0.0, "pose": {"matrix": pose.tolist()}}], "reference": q}
    per_request = client.post("/v1/robots/ur5e/ik/trajectory", json={**body, "tool": tool.tolist()})
    inline = client.post("/v1/ik/trajectory", json={**body, "robot": {**description, "tool": tool.tolist()}})
    assert per_request.status_code == 200, per_request.text
    assert per_request.json()["samples"] == inline.json()["samples"]
    np.testing.assert_allclose(per_request.json()["samples"][0]["joints"], q, atol=1e-8)
    assert per_request.json()["joint_names"] == ["base", "shoulder", "elbow", "wrist1", "wrist2", "wrist3"]
