"""Two consecutive coaxial revolute joints: the answer reports the relation and holds the generating configuration.

PUMA-like arms with random lengths, made coaxial at one pair of consecutive joints (a_i = 0 and α_i = 0, or
α_i = π for reversed axes), checked against the arm's own FK: the target fixes only q_i + q_j (q_i − q_j when
reversed), every answer says so, joint j is listed free and takes the reference value, and with the generating
configuration as reference it comes back whole. The arm without joint j is a closed-form family (a planar
two-link or intersecting pair with a spherical wrist, or the shoulder with a two-axis wrist), so the answer
is complete up to that relation.
"""

from __future__ import annotations

import numpy as np
import pytest

from service.kinematics import forward_kinematics
from service.kinematics.ik import joint_difference, solve_ik
from service.robots.build import robot_from_description
from service.robots.schemas import DHRobot
from tests.ik_helpers import wrapped

HALF = np.pi / 2


def _coaxial_puma(rng: np.random.Generator, pair_start: int, reversed_axes: bool):
    """A PUMA-like table with random lengths whose joints ``pair_start`` and ``pair_start + 1`` are coaxial."""
    rows = [dict(a=0.0, alpha=HALF, d=rng.uniform(0.1, 0.4)), dict(a=rng.uniform(0.3, 0.5), alpha=0.0,
                                                                  d=rng.uniform(0.05, 0.2)),
            dict(a=rng.uniform(0.0, 0.05), alpha=-HALF, d=0.0), dict(a=0.0, alpha=HALF, d=rng.uniform(0.3, 0.5)),
            dict(a=0.0, alpha=-HALF, d=0.0), dict(a=0.0, alpha=0.0, d=rng.uniform(0.05, 0.15))]
    rows[pair_start] = dict(rows[pair_start], a=0.0, alpha=np.pi if reversed_axes else 0.0)
    return robot_from_description(DHRobot.model_validate({"id": "coaxial", "convention": "standard",
                                                          "joints": rows}), max_joints=32)


@pytest.mark.parametrize("reversed_axes", [False, True])
@pytest.mark.parametrize("pair_start", range(5))
def test_coaxial_pairs_report_the_relation_and_return_the_generating_configuration(pair_start, reversed_axes):
    rng = np.random.default_rng(10 * pair_start + reversed_axes)
    first, second = pair_start, pair_start + 1
    relation = "difference" if reversed_axes else "sum"
    sign = -1.0 if reversed_axes else 1.0
    for arm in range(3):
        robot = _coaxial_puma(rng, pair_start, reversed_axes)
        for trial in range(4):
            q = rng.uniform(-np.pi, np.pi, 6)
            target = forward_kinematics(robot, q)
            for reference in (q, None):
                result = solve_ik(robot, target, reference=reference)
                assert result.status == "ok", (arm, trial)
                assert result.complete and result.method == "analytic", (arm, trial, result.structure)
                assert second in result.free_joints
                assert any(s.kind == "coaxial" and s.joints == (first, second) and s.relation == relation
                           for s in result.singularities)
                solutions = np.array([s.joints for s in result.solutions])
                reached = forward_kinematics(robot, solutions)
                assert np.abs(reached[:, :3, 3] - target[:3, 3]).max() <= 1e-9 * robot.characteristic_length
                assert np.abs(reached[:, :3, :3] - target[:3, :3]).max() <= 1e-9
                held = 0.0 if reference is None else q[second]
                np.testing.assert_allclose(solutions[:, second], held, atol=1e-12)
                d = joint_difference(robot, solutions, q)
                combined = np.abs(wrapped(d[:, first] + sign * d[:, second]))
                others = np.delete(np.abs(d), [first, second], axis=1).max(axis=1)
                assert np.any((combined <= 1e-7) & (others <= 1e-7)), (arm, trial, reference is None)
                if reference is not None:  # the held joint at the generating value: the whole configuration
                    assert np.abs(d).max(axis=1).min() <= 1e-7, (arm, trial)
                # one representative per relation: no two solutions differ only in the split
                reduced = np.delete(solutions, second, axis=1)
                reduced[:, first] = solutions[:, first] + sign * solutions[:, second]
                gaps = np.abs(wrapped(reduced[:, None] - reduced[None])).max(axis=-1)
                assert (gaps[np.triu_indices(len(reduced), 1)] > 1e-6).all()


def test_position_targets_of_a_coaxial_shoulder_are_complete():
    """Joints 1 and 2 on one line: a position target is solved by the intersecting shoulder of the arm without
    joint 2, complete up to q1 + q2 (it was the numeric search, complete: false)."""
    robot = _coaxial_puma(np.random.default_rng(3), 0, False)
    rng = np.random.default_rng(4)
    for _ in range(5):
        q = rng.uniform(-np.pi, np.pi, 6)
        target = forward_kinematics(robot, q)
        result = solve_ik(robot, target, constrain_orientation=False, reference=q)
        assert result.status == "ok" and result.complete and result.method == "analytic"
        assert any(s.kind == "coaxial" and s.joints == (0, 1) for s in result.singularities)
        solutions = np.array([s.joints for s in result.solutions])
        assert np.abs(joint_difference(robot, solutions, q)).max(axis=1).min() <= 1e-7


def test_five_joint_arm_poses_by_a_two_axis_wrist():
    """The SO-101 (five joints, its last two axes meeting): full poses from its own FK are answered by the
    offset shoulder with a two-axis wrist, complete, the generating configuration among them (it was the
    numeric search, complete: false)."""
    from service.config import BUILTIN_ROBOTS_DIR
    from service.robots.catalogue import load_catalogue

    robot = load_catalogue([BUILTIN_ROBOTS_DIR], max_joints=32).get("so101").robot
    rng = np.random.default_rng(0)
    for _ in range(20):
        q = rng.uniform(-np.pi, np.pi, robot.dof)
        target = forward_kinematics(robot, q)
        result = solve_ik(robot, target)
        assert result.status == "ok" and result.complete and result.structure.endswith("two_axis_wrist")
        solutions = np.array([s.joints for s in result.solutions])
        reached = forward_kinematics(robot, solutions)
        assert np.abs(reached[:, :3, 3] - target[:3, 3]).max() <= 1e-9 * robot.characteristic_length
        assert np.abs(reached[:, :3, :3] - target[:3, :3]).max() <= 1e-9
        assert np.abs(joint_difference(robot, solutions, q)).max(axis=1).min() <= 1e-7


def test_nested_coaxial_pairs_name_the_arms_own_joints():
    """Three joints on one line: two pairs, one inside the other's reduced arm. The structure and the reports
    name the arm's joints (a probe saw "with q2 free (coaxial with q1)" repeated, in each reduced arm's numbers)."""
    from service.kinematics import Joint, Robot

    robot = Robot([Joint("q1", "revolute", 0.0, 0.0, 0.1, 0.0), Joint("q2", "revolute", 0.0, 0.0, 0.1, 0.0),
                   Joint("q3", "revolute", 0.5, 0.0, 0.1, 0.0)], name="three on one line")
    q = np.array([0.3, 0.2, 0.1])
    result = solve_ik(robot, forward_kinematics(robot, q))
    assert result.status == "ok"
    assert result.structure.endswith("with q3 free (coaxial with q1) with q2 free (coaxial with q1)")
    assert result.free_joints == [1, 2]
    assert sorted((s.kind, s.joints, s.relation) for s in result.singularities) == [
        ("coaxial", (0, 1), "sum"), ("coaxial", (0, 2), "sum")]
