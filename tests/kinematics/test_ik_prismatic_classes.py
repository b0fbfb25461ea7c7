"""Positioners with one slide and skew axes (RRP, RPR, PRR) in closed form: random arms, alone and with a wrist.

Each class is drawn as seeded random standard DH tables (as in :mod:`test_ik_spherical_wrist_classes`: the same
three conventions, base and tool, reversed axes), its joints 1–3 placing a point (3-DOF, position targets) and
then again carrying a spherical wrist (6-DOF, pose targets), or with the wrist at the base. Recall 100 %,
0 wrong solutions (FK computed here), nothing unreachable, the same solution sets in every statement; singular
poses report a singularity; slide limits filter like a real linear axis.
"""

from __future__ import annotations

import numpy as np
import pytest

from service.kinematics import Joint, Robot
from service.kinematics._forward import forward_kinematics
from service.kinematics.ik import joint_difference, solve_ik, solve_ik_arrays
from service.kinematics.ik._arrays import cached_plan
from service.kinematics.ik._subproblems import subproblem_5_prismatic
from tests.kinematics.test_ik_spherical_wrist_classes import (
    _positioner_singular_configurations,
    _random_rigid,
    _reverse_axis,
    assert_every_solution,
    configurations,
)

DEG = np.pi / 180
POSES = 400  # per statement; three statements (conventions) per class: 1,200 poses


def _rows(kind: str, rng: np.random.Generator) -> tuple[list[tuple[float, float, float, float]], str]:
    """Standard DH rows (a, alpha, d, theta offset) of a random arm of the class, and its joint kinds."""
    def length():
        return float(rng.uniform(0.1, 0.5))

    def twist():
        return float(rng.uniform(0.3, 2.8) * rng.choice([-1, 1]))

    def offset():
        return float(rng.uniform(-np.pi, np.pi))

    def free():
        return (length(), twist(), length(), offset())

    def right():  # a twist of ±90°: the next axis normal to this one
        return (length(), 90 * DEG * rng.choice([-1, 1]), length(), offset())

    t = twist()
    wrist = [(0.0, t, length(), offset()), (0.0, t * rng.choice([-1, 1]), 0.0, offset()), free()]
    t = twist()
    base_wrist = [(0.0, t, length(), offset()), (0.0, t * rng.choice([-1, 1]), 0.0, offset())]
    t = twist()
    positioners = {
        # skew axes 1 and 2, then an oblique slide
        "rrp": ([free(), free(), free()], "RRP"),
        # axes 1 ∥ 2 (alpha_1 = 0, a_1 ≠ 0) and an oblique slide: the height fixes it; 2 solutions
        "rrp_parallel": ([(length(), 0.0, length(), offset()), free(), free()], "RRP"),
        # a turret, a boom sliding at any angle, a skew elbow
        "rpr": ([free(), free(), free()], "RPR"),
        # the boom normal to axis 1: a harmonic equation and a quadratic
        "rpr_normal": ([right(), free(), free()], "RPR"),
        # axis 3 ∥ axis 1 (alpha_2 = −alpha_1 with the slide's fixed theta 0): 2 solutions
        "rpr_parallel": ([(length(), t, length(), offset()), (length(), -t, length(), 0.0), free()], "RPR"),
        # a linear axis carrying two skew revolute axes (a gantry with a skew head)
        "prr": ([free(), free(), free()], "PRR"),
        # the linear axis normal to axis 2
        "prr_normal": ([right(), free(), free()], "PRR"),
    }
    name, _, layout = kind.partition("+")
    if layout == "wrist":
        rows, kinds = positioners[name]
        return rows + wrist, kinds + "RRR"
    if layout == "base_wrist":  # the wrist at the base, then the positioner in reverse
        _, kinds = positioners[name]
        return base_wrist + [free() for _ in range(4)], "RRR" + kinds[::-1]
    return positioners[name]


#: class → (structure, generic count)
CLASSES = {
    **{name: ("skew_axes_with_slide", 2 if "parallel" in name else 4)
       for name in ("rrp", "rrp_parallel", "rpr", "rpr_normal", "rpr_parallel", "prr", "prr_normal")},
    **{f"{name}+wrist": ("skew_axes_with_slide+spherical_wrist", 4 if "parallel" in name else 8)
       for name in ("rrp", "rrp_parallel", "rpr", "rpr_normal", "rpr_parallel", "prr", "prr_normal")},
    **{f"{name}+base_wrist": ("spherical_wrist+skew_axes_with_slide", 8) for name in ("rrp", "rpr", "prr")},
}


def statements(kind: str, seed: int, limits: tuple[float, float] | None = None) -> list[Robot]:
    """One random arm of the class in the standard, modified and Khalil conventions (same base, tool, FK)."""
    rng = np.random.default_rng(seed)
    table, kinds = _rows(kind, rng)
    n = len(kinds)
    rows = [list(row) for row in table]
    base = _random_rigid(rng, 0.5)
    for joint in np.flatnonzero(rng.random(n) < 0.4):
        base = _reverse_axis(rows, int(joint), base)
    tool = _random_rigid(rng, 0.2)
    joint_kind = {"R": "revolute", "P": "prismatic"}
    bounds = [limits if (k == "P" and limits) else (-np.inf, np.inf) for k in kinds]
    standard = Robot([Joint(f"j{i + 1}", joint_kind[k], *row, *bound)
                      for i, (row, k, bound) in enumerate(zip(rows, kinds, bounds))],
                     convention="standard", world_T_base=base, flange_T_tool=tool)
    craig = [(0.0 if i == 0 else rows[i - 1][0], 0.0 if i == 0 else rows[i - 1][1], rows[i][2], rows[i][3])
             for i in range(n)]
    last = np.eye(4)
    a, alpha = rows[-1][0], rows[-1][1]
    last[:3, :3] = [[1, 0, 0], [0, np.cos(alpha), -np.sin(alpha)], [0, np.sin(alpha), np.cos(alpha)]]
    last[0, 3] = a
    modified_joints = [Joint(f"j{i + 1}", joint_kind[k], *row, *bound)
                       for i, (row, k, bound) in enumerate(zip(craig, kinds, bounds))]
    modified = Robot(modified_joints, convention="modified", world_T_base=base, flange_T_tool=last @ tool)
    khalil = Robot(modified_joints, convention="khalil", world_T_base=base, flange_T_tool=last @ tool)
    return [standard, modified, khalil]


def _assert_points(robot: Robot, q: np.ndarray, targets: np.ndarray, answer) -> None:
    """Position targets: recall and 0 wrong by the tool point alone."""
    assert (answer.count >= 1).all(), f"{(answer.count == 0).sum()} FK poses answered unreachable"
    rows, slots = np.nonzero(answer.valid)
    reached = forward_kinematics(robot, answer.joints[rows, slots])[:, :3, 3]
    wrong = np.linalg.norm(reached - targets[rows, :3, 3], axis=-1) > 1e-9 * robot.characteristic_length
    assert not wrong.any(), f"{wrong.sum()} wrong solutions"
    missed = [row for row in range(len(q)) if np.abs(joint_difference(
        robot, answer.joints[row, :answer.count[row]], q[row])).max(axis=1).min() > 1e-7]
    assert not missed, f"generating vector missing for {len(missed)} of {len(q)} poses, e.g. {q[missed[0]]}"


@pytest.mark.parametrize("kind", sorted(CLASSES))
def test_random_arms_of_every_slide_class_in_every_convention(kind):
    structure, generic = CLASSES[kind]
    robots = statements(kind, seed=sorted(CLASSES).index(kind))
    answers = []
    for index, robot in enumerate(robots):
        pose = robot.dof == 6
        plan = cached_plan(robot, constrain_orientation=pose, reference=None)
        assert plan is not None and plan.structure == structure
        assert plan.generic_count == generic
        q = configurations(robot, POSES, seed=index)
        targets = forward_kinematics(robot, q)
        answer = solve_ik_arrays(robot, targets, constrain_orientation=pose)
        assert answer.count.max() <= generic
        if pose:
            assert_every_solution(robot, q, targets, answer)
        else:
            _assert_points(robot, q, targets, answer)
        answers.append(answer)
    # the three statements are one arm: the same targets get the same solution sets
    q = configurations(robots[0], POSES, seed=0)
    targets = forward_kinematics(robots[0], q)
    first = answers[0]
    for robot in robots[1:]:
        assert np.allclose(forward_kinematics(robot, q), targets, atol=1e-12)
        other = solve_ik_arrays(robot, targets, constrain_orientation=pose)
        assert (other.count == first.count).all()
        for row in range(0, POSES, 7):
            a, b = first.joints[row, :first.count[row]], other.joints[row, :other.count[row]]
            gaps = np.abs(joint_difference(robots[0], a[:, None, :], b[None, :, :])).max(axis=-1)
            assert (gaps.min(axis=1) < 1e-7).all()
