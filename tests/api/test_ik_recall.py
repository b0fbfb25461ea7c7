"""Every solution, for every catalogue robot: poses from random joint vectors come back among the solutions.

For each robot, 1,000 seeded random joint vectors go through FK and then through the batch IK endpoint. The
generating vector must be among the solutions (revolute joints modulo 2π), every residual must be under 1e-9
relative to the robot's size, and the count must equal the structure's generic count (textbook.md §7, counting
the negative roots of prismatic joints too: the request lifts the catalogue's limits, which bring the counts back
to the textbook's, see test_ik.py).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from service.kinematics.ik import joint_difference
from tests.arms import GENERIC_CATALOGUE_ARMS
from tests.conftest import catalogue_robot
from tests.ik_helpers import random_configurations
from tests.oracles.opw import OPW_SOURCES, opw_forward

SAMPLES = 1000

#: The 7-joint catalogue arms: every solution at each value of a free joint (the service's default choice), each
#: value's locked 6-joint arm solved by a family.
REDUNDANT = {"franka_panda": "spherical_wrist+intersecting_shoulder with q7 free",
             "kuka_iiwa14": "spherical_wrist+intersecting_shoulder with q7 free",
             "ufactory_xarm7": "general_6r with q7 free",
             "kinova_gen3": "intersecting_shoulder+spherical_wrist with q1 free"}
#: Answered elsewhere: the xArm 6 (no spherical wrist, a5 = 76 mm) by the general 6R solver
#: (tests/kinematics/ik/test_general_6r.py), the 5-joint SO-101 (its targets are position + direction,
#: tests/api/test_ik_direction.py; its full poses: an offset shoulder with a two-axis wrist, tests/kinematics/ik/
#: test_coaxial.py).
ELSEWHERE = {"so101", "ufactory_xarm6"}


def test_every_catalogue_robot_has_an_analytic_class(client):
    assert {robot["id"] for robot in client.get("/v1/robots").json()["robots"]} == (
        set(GENERIC_CATALOGUE_ARMS) | set(REDUNDANT) | ELSEWHERE)


@pytest.mark.parametrize("robot_id", sorted(REDUNDANT))
def test_redundant_catalogue_arms_return_the_generating_vector(client, robot_id):
    """Poses from random joint vectors; the generating vector's free-joint value among the requested values (with
    two others): the generating vector comes back, from the closed-form family the service chose."""
    robot = catalogue_robot(client, robot_id)
    q = random_configurations(robot, 12, seed=sorted(REDUNDANT).index(robot_id))
    poses = client.post(f"/v1/robots/{robot_id}/fk/batch", json={"joints": q.tolist()}).json()["poses"]
    free = int(REDUNDANT[robot_id].split(" with q")[1].split()[0]) - 1
    for q_true, pose in zip(q, poses):
        values = [float(q_true[free]), float(q_true[free]) + 0.3, float(q_true[free]) - 0.4]
        answer = client.post(f"/v1/robots/{robot_id}/ik", json={
            "target": {"matrix": pose["matrix"]}, "limits": [None] * robot.dof,  # no limits: no 2π copies
            "free_joints": [{"joint": free, "values": values}]}).json()
        assert answer["status"] == "ok", answer["detail"]
        assert answer["solver"] == {"method": "analytic", "structure": REDUNDANT[robot_id], "complete": True,
                                    "time_budget_exhausted": False}
        assert answer["free_joints"] == [free]
        solutions = np.array([solution["joints"] for solution in answer["solutions"]])
        assert np.abs(joint_difference(robot, solutions, q_true)).max(axis=1).min() < 1e-7, q_true


def targets_for(client, robot_id: str, q: np.ndarray, kind: str) -> list[dict]:
    poses = client.post(f"/v1/robots/{robot_id}/fk/batch", json={"joints": q.tolist()}).json()["poses"]
    return [{"matrix": p["matrix"]} if kind == "pose" else {"position": p["position"]} for p in poses]


@pytest.mark.parametrize("robot_id", sorted(GENERIC_CATALOGUE_ARMS))
def test_generating_vector_is_among_the_solutions(client, robot_id):
    kind, generic_count, structure = GENERIC_CATALOGUE_ARMS[robot_id]
    robot = catalogue_robot(client, robot_id)
    q = random_configurations(robot, SAMPLES, seed=sorted(GENERIC_CATALOGUE_ARMS).index(robot_id))
    unlimited = [None] * robot.dof  # the mathematical solution set: no limits, so no 2π expansion either
    response = client.post(f"/v1/robots/{robot_id}/ik/batch",
                           json={"targets": targets_for(client, robot_id, q, kind), "limits": unlimited})
    assert response.status_code == 200, response.text
    results = response.json()["results"]
    scale = robot.characteristic_length
    counts = []
    for q_true, result in zip(q, results):
        assert result["status"] == "ok"
        assert result["solver"] == {"method": "analytic", "structure": structure, "complete": True,
                                    "time_budget_exhausted": False}
        solutions = np.array([s["joints"] for s in result["solutions"]])
        assert np.abs(joint_difference(robot, solutions, q_true)).max(axis=1).min() < 1e-7, q_true
        for solution in result["solutions"]:
            assert solution["residual"]["position"] <= 1e-9 * scale
            if kind == "pose":
                assert solution["residual"]["orientation"] <= 1e-9
        counts.append(len(solutions))
    if structure == "three_parallel":  # UR-type arms: up to 8 real solutions, 8 at most poses
        assert set(counts) <= {2, 4, 6, 8} and counts.count(8) > SAMPLES // 2
    elif structure.startswith("offset_shoulder"):
        # a1 != 0: the shoulder sits a1 off axis 1, at two places (theta1 and theta1 + pi); each gives 4 real solutions
        # when the wrist centre lies within the elbow's annulus |c2 - k| .. c2 + k around it (k = |(a2, c3)|)
        assert counts == [_offset_shoulder_count(robot_id, q_true) for q_true in q]
    else:
        assert counts == [generic_count] * SAMPLES


def _offset_shoulder_count(robot_id: str, q: np.ndarray) -> int:
    """The real IK count at the pose of q: 4 for each shoulder place (near and far side of axis 1) that reaches
    the wrist centre (b = 0)."""
    p, signs, offsets = OPW_SOURCES[robot_id]
    pose = opw_forward(p, signs, offsets, q)
    centre = pose[:3, 3] - p["c4"] * pose[:3, 2]
    radial, height = math.hypot(centre[0], centre[1]), centre[2] - p["c1"]
    k = math.hypot(p["a2"], p["c3"])
    return sum(4 for distance in (math.hypot(radial - p["a1"], height), math.hypot(radial + p["a1"], height))
               if abs(p["c2"] - k) <= distance <= p["c2"] + k)
