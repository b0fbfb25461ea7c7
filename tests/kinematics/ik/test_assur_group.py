"""The IK of an RRP SCARA names the RRR group's singular cases as the paper does (textbook.md §4.2 item 6, §4.3)."""

from __future__ import annotations

import numpy as np

from service.kinematics import Joint, Robot, forward_kinematics
from service.kinematics.ik import solve_ik


def scara(l_AB: float, l_BC: float) -> Robot:
    """The paper's SCARA in standard DH (textbook.md §4.1), l_OA = 150 mm."""
    return Robot([Joint("theta1", "revolute", l_AB, 0, 150.0, 0), Joint("q2", "revolute", l_BC, np.pi, 0, 0),
                  Joint("l3", "prismatic", 0, 0, 0, 0)])


def target(x: float, y: float, z: float) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = x, y, z
    return T


def relations(result) -> list[tuple[str, str]]:
    return [(s.kind, s.relation) for s in result.singularities]


def test_point_on_the_shoulder_axis_with_equal_arms_is_coincident_and_joint_1_is_free():
    arm = scara(50.0, 50.0)
    result = solve_ik(arm, target(0.0, 0.0, 60.0), constrain_orientation=False, reference=np.array([0.7, 0, 0]))
    assert relations(result) == [("assur_group", "coincident")]
    assert len(result.solutions) == 1  # one representative of the family
    q = result.solutions[0].joints
    np.testing.assert_allclose(q, [0.7, np.pi, 90.0], atol=1e-12)  # θ1 = reference, folded elbow
    for theta1 in (-2.0, 0.3, 1.9):  # every θ1 reaches the point: increased mobility
        np.testing.assert_allclose(forward_kinematics(arm, [theta1, q[1], q[2]])[:3, 3], [0, 0, 60], atol=1e-12)


def test_stretched_and_folded_are_aligned_not_coincident():
    arm = scara(80.0, 50.0)
    for reach, elbow in ((130.0, 0.0), (30.0, np.pi)):
        result = solve_ik(arm, target(reach, 0.0, 60.0), constrain_orientation=False)
        assert relations(result) == [("assur_group", "aligned")]
        assert len(result.solutions) == 1
        np.testing.assert_allclose(np.abs(result.solutions[0].joints), [0.0, elbow, 90.0], atol=1e-6)


def test_regular_point_has_two_assembly_modes_and_no_singularity():
    result = solve_ik(scara(80.0, 50.0), target(100.0, -20.0, 50.0), constrain_orientation=False)
    assert relations(result) == []
    assert sorted(s.branch["assembly_mode"] for s in result.solutions) == [1, 2]
