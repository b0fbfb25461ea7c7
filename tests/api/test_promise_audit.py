"""The promise audit across routes (issue 22): on every route that can say ``unreachable`` or ``complete: true``,
targets made by the arm's own FK are never ``unreachable``, and an answer that says it is complete holds the
configuration that made its target (revolute joints modulo 2π).

Routes: single IK (pose and position-only), the batch in both forms, the trajectory, a redundant arm with a free
joint held at the generating value, and a 5-joint arm's direction target. Arms: one catalogue arm of each family
(spherical wrist, three parallel axes, offset shoulder, general 6R, prismatic, SCARA, 5 and 7 joints) at random
configurations over ±π (slides over half the arm's size), with no limits, so that every solution counts.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.ik_helpers import find, joints_of, random_configurations

#: One catalogue arm per family the closed forms and the families cover.
ARMS = ["puma560_standard", "ur5", "kuka_kr6_r900_2", "kinova_jaco2", "abb_irb120", "unitree_z1",
        "spong_ex3_5_stanford", "assur001_scara_rrp", "ex004_2_polar_rrp", "spong_ex3_1_planar_rr"]
CONFIGURATIONS = 4
#: Looser than tests.ik_helpers.SAME: a numeric or near-singular answer is polished to ~1e-9 in the pose.
FOUND = 1e-6


def _robot(client, robot_id: str):
    return client.app.state.catalogue.get(robot_id).robot


def _targets(client, robot_id: str, seed: int) -> tuple[np.ndarray, list[np.ndarray]]:
    robot = _robot(client, robot_id)
    q = random_configurations(robot, CONFIGURATIONS, seed)
    poses = client.post(f"/v1/robots/{robot_id}/fk/batch", json={"joints": q.tolist()}).json()["poses"]
    return q, [np.array(pose["matrix"]) for pose in poses]


def _kept_promise(robot, answer: dict, q: np.ndarray, route: str) -> None:
    """Never unreachable; complete → the generating configuration is among the solutions. An answer over held
    free joints (a position-only target on a 6-joint arm holds its wrist) promises every solution at the values it
    held: the generating configuration counts only where it has those values."""
    assert answer["status"] != "unreachable", (route, q.tolist(), answer.get("detail"))
    held = {int(joint): value for s in answer["solutions"] for joint, value in s.get("free_values", {}).items()}
    if any(abs(q[joint] - value) > FOUND for joint, value in held.items()):
        return
    if answer["solver"]["complete"]:
        assert answer["solutions"], (route, q.tolist(), answer["status"], answer.get("detail"))
        assert find(robot, joints_of(answer), q, FOUND) is not None, (route, q.tolist(), answer["solver"])


def _target(T: np.ndarray, kind: str) -> dict:
    return {"matrix": T.tolist()} if kind == "pose" else {"position": T[:3, 3].tolist()}


@pytest.mark.parametrize("kind", ["pose", "position"])
@pytest.mark.parametrize("robot_id", ARMS)
def test_single_and_batch_answers_keep_their_promises(client, robot_id, kind):
    robot = _robot(client, robot_id)
    q, poses = _targets(client, robot_id, seed=ARMS.index(robot_id) + 100 * (kind == "position"))
    options = {"limits": [None] * robot.dof, "filter_limits": False}
    for qi, T in zip(q, poses):
        single = client.post(f"/v1/robots/{robot_id}/ik", json={"target": _target(T, kind), **options})
        assert single.status_code == 200, single.text
        _kept_promise(robot, single.json(), qi, f"single {kind}")
    batch = client.post(f"/v1/robots/{robot_id}/ik/batch",
                        json={"targets": [_target(T, kind) for T in poses], **options})
    assert batch.status_code == 200, batch.text
    for qi, result in zip(q, batch.json()["results"]):
        _kept_promise(robot, result, qi, f"batch objects {kind}")
    arrays = client.post(f"/v1/robots/{robot_id}/ik/batch",
                         json={"targets": [_target(T, kind) for T in poses], "format": "arrays", **options}).json()
    table = arrays["solutions"]
    for row, qi in enumerate(q):
        held = table.get("free_values") or {}
        rows = [{"joints": j, "free_values": {joint: values[k] for joint, values in held.items()
                                              if values[k] is not None}}
                for k, (j, target) in enumerate(zip(table["joints"], table["target"])) if target == row]
        answer = {"status": arrays["targets"]["status"][row], "detail": arrays["targets"]["detail"][row],
                  "solver": arrays["solvers"][arrays["targets"]["solver"][row]], "solutions": rows}
        _kept_promise(robot, answer, qi, f"batch arrays {kind}")


@pytest.mark.parametrize("robot_id", ["puma560_standard", "ur5", "kuka_kr6_r900_2", "spong_ex3_5_stanford"])
def test_trajectory_samples_at_fk_poses_are_never_unreachable(client, robot_id):
    """A short smooth joint path; the first sample chooses the generating branch by ``reference``."""
    robot = _robot(client, robot_id)
    start = np.random.default_rng(3).uniform(0.7 * robot.lower + 0.3 * robot.upper,
                                             0.3 * robot.lower + 0.7 * robot.upper)  # inside the limits
    times = np.linspace(0.0, 1.0, 6)
    path = start + np.outer(times, np.linspace(0.05, 0.2, robot.dof))
    poses = client.post(f"/v1/robots/{robot_id}/fk/batch", json={"joints": path.tolist()}).json()["poses"]
    answer = client.post(f"/v1/robots/{robot_id}/ik/trajectory", json={
        "samples": [{"time": float(t), "pose": {"matrix": pose["matrix"]}} for t, pose in zip(times, poses)],
        "reference": start.tolist()})
    assert answer.status_code == 200, answer.text
    for q, sample in zip(path, answer.json()["samples"]):
        assert sample["status"] != "unreachable", (q.tolist(), sample)
        assert find(robot, np.array([sample["joints"]]), q, FOUND) is not None, (q.tolist(), sample["joints"])


@pytest.mark.parametrize("robot_id, joint", [("franka_panda", 2), ("kinova_gen3", 2), ("ufactory_xarm7", 2)])
def test_a_free_joint_held_at_its_generating_value_keeps_the_promise(client, robot_id, joint):
    robot = _robot(client, robot_id)
    q, poses = _targets(client, robot_id, seed=11)
    for qi, T in zip(q, poses):
        answer = client.post(f"/v1/robots/{robot_id}/ik", json={
            "target": {"matrix": T.tolist()}, "limits": [None] * robot.dof, "filter_limits": False,
            "free_joints": [{"joint": joint, "values": [float(qi[joint])]}]})
        assert answer.status_code == 200, answer.text
        _kept_promise(robot, answer.json(), qi, "free-joint family")


def test_a_five_joint_direction_target_keeps_the_promise(client):
    robot = _robot(client, "so101")
    q, poses = _targets(client, "so101", seed=5)
    for qi, T in zip(q, poses):
        target = {"position": T[:3, 3].tolist(),
                  "orientation": {"type": "direction", "tool_axis": [0, 0, 1], "world_direction": T[:3, 2].tolist()}}
        answer = client.post("/v1/robots/so101/ik", json={"target": target, "limits": [None] * robot.dof,
                                                           "filter_limits": False})
        assert answer.status_code == 200, answer.text
        _kept_promise(robot, answer.json(), qi, "direction target")


@pytest.mark.parametrize("dust", [1e-6, 1e-5])
@pytest.mark.parametrize("robot_id", ["puma560_standard", "ur5", "kuka_kr6_r900_2", "abb_irb120", "kinova_jaco2"])
def test_cad_rounded_arms_inline_keep_their_promises(client, robot_id, dust):
    """The arm's screws export with every axis and point moved by ``dust`` (as CAD exports round), sent inline:
    its own FK targets (the inline routes have no batch)."""
    rng = np.random.default_rng(int(dust * 1e7) + ARMS.index(robot_id))
    description = client.get(f"/v1/robots/{robot_id}?form=screws").json()
    inline = {key: description[key] for key in ("format", "angle_unit", "length_unit", "home")}
    inline["joints"] = []
    for joint in description["joints"]:
        axis = np.array(joint["axis"]) + rng.uniform(-dust, dust, 3)
        inline["joints"].append({"type": joint["type"], "axis": (axis / np.linalg.norm(axis)).tolist(),
                                 "point": (np.array(joint["point"]) + rng.uniform(-dust, dust, 3)).tolist()})
    dof = len(inline["joints"])
    q = rng.uniform(-np.pi, np.pi, (CONFIGURATIONS, dof))
    targets = [{"matrix": client.post("/v1/fk", json={"robot": inline, "joints": qi.tolist()}).json()["pose"]["matrix"]}
               for qi in q]
    robot = client.app.state.catalogue.get(robot_id).robot  # its joint kinds: what matching modulo 2π needs
    for qi, target in zip(q, targets):
        answer = client.post("/v1/ik", json={"robot": inline, "target": target, "limits": [None] * dof})
        assert answer.status_code == 200, answer.text
        _kept_promise(robot, answer.json(), qi, "inline single, rounded")


class _Kinds:
    """What matching modulo 2π needs of an inline arm: its joint kinds."""

    def __init__(self, kinds: str) -> None:
        self.is_revolute = np.array([kind == "R" for kind in kinds])


@pytest.mark.parametrize("slide, convention", [(0, "standard"), (3, "modified")])
def test_six_joint_arms_with_a_slide_of_general_geometry_answer_complete(client, slide, convention):
    """A slide and five revolute joints that no closed form covers (CAD-rounded DH entries, sent inline): the
    general solver answers, and its promise holds, with the generating configuration in every answer."""
    rng = np.random.default_rng(40 + slide)
    rows = np.round(rng.uniform(-1, 1, (6, 4)), 6)
    inline = {"convention": convention, "angle_unit": "rad", "joints": [
        {"type": "prismatic" if i == slide else "revolute", "a": a, "alpha": alpha, "d": d, "theta": theta}
        for i, (a, alpha, d, theta) in enumerate(rows.tolist())]}
    q = rng.uniform(-np.pi, np.pi, (CONFIGURATIONS, 6))
    arm = _Kinds("".join("P" if i == slide else "R" for i in range(6)))
    for qi in q:
        target = client.post("/v1/fk", json={"robot": inline, "joints": qi.tolist()}).json()["pose"]["matrix"]
        answer = client.post("/v1/ik", json={"robot": inline, "target": {"matrix": target}, "limits": [None] * 6})
        assert answer.status_code == 200, answer.text
        body = answer.json()
        assert body["solver"] == {**body["solver"], "method": "analytic", "structure": "general_5r1p",
                                  "complete": True}
        _kept_promise(arm, body, qi, "inline single, general 5R1P")
