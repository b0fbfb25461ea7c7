"""UR-type arms with a skew wrist (axes 2–4 parallel, axes 5 and 6 skew: three_parallel_skew_wrist) at and near the
wrist singularity, where joint 5 turns axis 6 along axes 2–4.

There subproblem 6 has a double root in (q1, q5): the heights along the parallel axes that it equates are both at
an extreme. Before, its pair of equations held that root only to ~1e-7, step 3 turned q6 by whatever that error
pointed to, and the elbow could not reach: poses from the arm's own FK came back with no solution and
``complete: true`` (a UR5 with a5 = 0.07 lost a quarter of them at q5 = 0), and near the singularity (q5 ~ 1e-9)
the second of the two roots, merged into the first, took the generating configuration with it.

Each pose is FK of a random configuration with q5 = 0, ±1e-12, ±1e-9, ±1e-6 or ±1e-3, solved alone (solve_ik)
and in one batch (solve_ik_arrays). Every answer must be complete, hold at least one solution, every solution must
reach the target by an FK of this test, and the generating configuration must be back: where the wrist singularity
is reported, its (q1, q5) with a q6 on the same arc of values the elbow reaches with (found by FK alone, as in
test_three_parallel_arcs.py); elsewhere the configuration itself, up to what the pose tells of the planar
self-motion (configurations δ apart along it have poses ~|q5|·δ apart, as in test_near_singular.py).
"""

from __future__ import annotations

import numpy as np
import pytest

from service.kinematics import Joint, Robot, forward_kinematics
from service.kinematics.ik import joint_difference, solve_ik, solve_ik_arrays
from service.kinematics.ik import cached_plan
from tests.arms import random_ur_type_arm
from tests.oracles.q6_arcs import arc_holding, fk_miss, resolved_wrist_configuration

WRIST_ANGLES = (0.0, 1e-12, -1e-12, 1e-9, -1e-9, 1e-6, -1e-6, 1e-3, -1e-3)
POSES_PER_ANGLE = 5
#: q2, q3, q4 and q6: the joints of the planar self-motion that the singular wrist leaves to one relation
COUPLED = np.array([False, True, True, True, False, True])


def skew_wrist_arm(seed: int, convention: str) -> Robot:
    """A random UR-type arm whose axes 5 and 6 are skew (a5 ≠ 0), with a random base and tool; the offset d5 long
    (two arcs of q6 possible) for odd seeds, short for even ones."""
    return random_ur_type_arm(seed, convention, two_arcs=bool(seed % 2), skew=True)


def ur5_with_skew_wrist() -> Robot:
    """The UR5's published DH table with a 7 cm link between axes 5 and 6."""
    a, d = [0.0, -0.425, -0.39225, 0.0, 0.07, 0.0], [0.089159, 0.0, 0.0, 0.10915, 0.09465, 0.0823]
    alpha = [np.pi / 2, 0.0, 0.0, np.pi / 2, -np.pi / 2, 0.0]
    return Robot([Joint(f"j{i + 1}", "revolute", a[i], alpha[i], d[i], 0.0) for i in range(6)])


def _poses(robot: Robot, seed: int) -> list[tuple[np.ndarray, list[np.ndarray]]]:
    """Configurations at each wrist angle whose arcs of q6 (those of q5 = 0) the grid resolves, with the arcs."""
    rng = np.random.default_rng(seed)
    out = []
    for angle in WRIST_ANGLES:
        for _ in range(POSES_PER_ANGLE):
            q, arcs = resolved_wrist_configuration(robot, rng)
            q[4] = angle
            out.append((q, arcs))
    return out


def _problem(robot: Robot, q: np.ndarray, arcs: list[np.ndarray], solutions: np.ndarray, complete: bool,
             wrist_reported: bool) -> str | None:
    """What is wrong with one answer for FK(q), or None."""
    if not complete:
        return "incomplete"
    if len(solutions) == 0:
        return "no solution"
    miss = fk_miss(robot, solutions, forward_kinematics(robot, q)).max()
    if miss > 1e-9:
        return f"FK miss {miss:.1e}"
    gaps = np.abs(joint_difference(robot, solutions, q))
    branch = gaps[:, ~COUPLED].max(axis=1) <= 1e-6
    split = max(1e-6, 1e-9 / max(abs(q[4]), 1e-300))
    if (branch & (gaps[:, COUPLED].max(axis=1) <= split)).any():
        return None
    if wrist_reported:
        generating = arc_holding(arcs, q[5])
        if any(arc_holding(arcs, q6) == generating for q6 in solutions[branch, 5]):
            return None
        return "the generating arc of q6 is missing"
    return f"the generating configuration is missing ({int(branch.sum())} on its (q1, q5))"


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("seed", range(3))
def test_skew_wrist_arms_at_the_wrist_singularity_return_the_generating_configuration(seed, convention):
    robot = ur5_with_skew_wrist() if seed == 0 and convention == "standard" else skew_wrist_arm(seed, convention)
    assert cached_plan(robot, constrain_orientation=True, reference=None).structure == "three_parallel_skew_wrist"
    poses = _poses(robot, 300 + seed)
    batch = solve_ik_arrays(robot, forward_kinematics(robot, np.array([q for q, _ in poses])))
    failures = []
    for row, (q, arcs) in enumerate(poses):
        result = solve_ik(robot, forward_kinematics(robot, q))
        wrist_reported = any(s.kind == "wrist" for s in result.singularities)
        for name, solutions, complete in (
                ("alone", np.array([s.joints for s in result.solutions]).reshape(-1, 6), result.complete),
                ("batch", batch.joints[row, :batch.count[row]], bool(batch.complete[row]))):
            problem = _problem(robot, q, arcs, solutions, complete, wrist_reported)
            if problem:
                failures.append((row, name, float(q[4]), problem))
    assert not failures, failures
