"""Every solution, for every catalogue robot: poses from random joint vectors come back among the solutions.

For each robot, 1,000 seeded random joint vectors go through FK and then through the batch IK endpoint. The
generating vector must be among the solutions (revolute joints modulo 2π), every residual must be under 1e-9
relative to the robot's size, and the count must equal the structure's generic count (textbook.md §7, counting
the negative roots of prismatic joints too: the request lifts the catalogue's limits, which bring the counts back
to the textbook's, see test_ik.py).
"""

from __future__ import annotations

import numpy as np
import pytest

from service.kinematics.ik import joint_difference
from tests.conftest import catalogue_robot
from tests.ik_helpers import random_configurations

SAMPLES = 1000

#: robot id → (target kind, generic number of solutions, solver structure)
GENERIC = {
    "spong_ex3_1_planar_rr": ("position", 2, "planar_two_link"),
    "spong_ex3_2_cylindrical_rpp": ("position", 2, "one_revolute_two_prismatic"),
    "spong_ex3_3_spherical_wrist_rrr": ("pose", 2, "spherical_wrist"),
    "spong_ex3_4_cylindrical_with_wrist": ("pose", 4, "one_revolute_two_prismatic+spherical_wrist"),
    "spong_ex3_5_stanford": ("pose", 8, "intersecting_shoulder+spherical_wrist"),
    "spong_ex3_6_scara_rrpr": ("pose", 2, "parallel_shoulder+roll"),
    "spong_ex4_3_elbow_with_wrist": ("pose", 8, "intersecting_shoulder+spherical_wrist"),
    "spong_sec4_3_elbow_shoulder_offset_with_wrist": ("pose", 8, "intersecting_shoulder+spherical_wrist"),
    "spong_sec4_3_spherical_arm_rrp": ("position", 4, "intersecting_shoulder"),
    "spong_sec4_3_spherical_arm_table3_4_frames": ("position", 4, "intersecting_shoulder"),
    "ex004_1_prp": ("position", 2, "one_revolute_two_prismatic"),
    "ex004_2_polar_rrp": ("position", 4, "intersecting_shoulder"),
    "ex004_3_spherical_rrpr": ("pose", 2, "intersecting_shoulder+roll"),
    "ex004_4_polar_offset_rrp": ("position", 4, "intersecting_shoulder"),
    "assur001_scara_rrp": ("position", 2, "parallel_shoulder"),
    "puma560_modified": ("pose", 8, "intersecting_shoulder+spherical_wrist"),
    "puma560_khalil": ("pose", 8, "intersecting_shoulder+spherical_wrist"),
    "puma560_standard": ("pose", 8, "intersecting_shoulder+spherical_wrist"),
    "ur5": ("pose", 8, "three_parallel"),  # up to 8: see test_ur5_counts_are_the_real_solution_counts
    "ur3e": ("pose", 8, "three_parallel"),
    "ur5e": ("pose", 8, "three_parallel"),
    "ur10e": ("pose", 8, "three_parallel"),
    "ur16e": ("pose", 8, "three_parallel"),
    # URDF arms: the plan is read off their joint screws, as for DH tables
    "kinova_jaco2": ("pose", 8, "intersecting_shoulder+spherical_wrist"),
    "unitree_z1": ("pose", 8, "three_parallel"),
}
#: Catalogue arms that no analytic family covers yet, solved by the numeric fallback: the 7-joint arms, and the
#: 5-joint SO-101 for full poses.
NUMERIC_FALLBACK = {"franka_panda", "kuka_iiwa14", "ufactory_xarm7", "so101"}


def test_every_catalogue_robot_has_an_analytic_class(client):
    assert {robot["id"] for robot in client.get("/v1/robots").json()["robots"]} == set(GENERIC) | NUMERIC_FALLBACK


def targets_for(client, robot_id: str, q: np.ndarray, kind: str) -> list[dict]:
    poses = client.post(f"/v1/robots/{robot_id}/fk/batch", json={"joints": q.tolist()}).json()["poses"]
    return [{"matrix": p["matrix"]} if kind == "pose" else {"position": p["position"]} for p in poses]


@pytest.mark.parametrize("robot_id", sorted(GENERIC))
def test_generating_vector_is_among_the_solutions(client, robot_id):
    kind, generic_count, structure = GENERIC[robot_id]
    robot = catalogue_robot(client, robot_id)
    q = random_configurations(robot, SAMPLES, seed=sorted(GENERIC).index(robot_id))
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
    else:
        assert counts == [generic_count] * SAMPLES
