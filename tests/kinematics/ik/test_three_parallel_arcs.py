"""UR-type arms at the wrist singularity (axis 6 along the parallel axes 2–4): every arc of q6 the elbow reaches with.

There the orientation leaves q6 free but the position does not: turning about axis 6 carries the point on axis 4
round axis 6, and the elbow reaches it only where its distance from axis 2 lies in the elbow's band. When that
band lies strictly inside the distances the turn sweeps, the reachable q6 form two separate arcs, each a separate
continuum of solutions. The answer must hold a solution on each (or say it is not complete).

The arcs are found here independently of the solver, by the arm's FK alone: with the target T held, turning joint 6
from q6 to q6' moves everything before it by ``T · FK(q with q6')⁻¹``; the elbow reaches the moved point on axis 4
when its distance from axis 2 (normal to the parallel axes) lies between the difference and the sum of the two
planar link lengths. q6' is sampled on a fine grid of [−π, π) and the arcs are the grid's connected runs
(tests/oracles/q6_arcs.py).
"""

from __future__ import annotations

import numpy as np
import pytest

from service.config import Settings
from service.kinematics import Robot, forward_kinematics
from service.kinematics.ik import joint_difference, solve_ik, solve_ik_arrays
from service.kinematics.ik import cached_plan
from service.robots.catalogue import load_catalogue
from tests.arms import random_ur_type_arm
from tests.ik_helpers import wrapped
from tests.oracles.q6_arcs import arc_holding, fk_miss, q6_grid, resolved_wrist_configuration

WRIST_OFFSETS = (0.0, 1e-12, -1e-12)
_CATALOGUE = load_catalogue([Settings().builtin_robots_dir], max_joints=32)


def _check(robot: Robot, q: np.ndarray, arcs: list[np.ndarray], solutions: np.ndarray, complete: bool,
           given: float) -> str | None:
    """What is wrong with an answer at the singular wrist of q, or None. The singular branch (q1 and q5 as q's)
    must hold exactly one q6 value per arc, one on each arc, and the value given (reference or 0) where it is
    clearly on an arc; the answer complete; every solution on the target (an FK of this test)."""
    if not complete:
        return "incomplete"
    miss = fk_miss(robot, solutions, forward_kinematics(robot, q)).max()
    if miss > 1e-9:
        return f"FK miss {miss:.1e}"
    branch = solutions[(np.abs(wrapped(solutions[:, 0] - q[0])) <= 1e-6)
                       & (np.abs(wrapped(solutions[:, 4] - q[4])) <= 1e-6)]
    values = []
    for q6 in branch[:, 5]:
        if not any(abs(wrapped(q6 - v)) <= 1e-6 for v in values):
            values.append(q6)
    held = {arc_holding(arcs, v) for v in values}
    if len(values) != len(arcs) or held != set(range(len(arcs))):
        return f"{len(arcs)} arcs, q6 values {np.round(values, 4).tolist()} on arcs {held}"
    generating = arc_holding(arcs, q[5])
    if generating not in held:
        return "the generating arc is missing"
    if arc_holding(arcs, given) is not None and not any(abs(wrapped(v - given)) <= 1e-9 for v in values):
        return f"the given q6 {given:.4f} reaches but is not kept"
    return None


def _poses(robot: Robot, seed: int, count: int) -> list[tuple[np.ndarray, list[np.ndarray]]]:
    """Random configurations at the singular wrist (q5 = 0, ±1e-12) whose arcs the grid resolves, with their
    arcs (those of q5 = 0: the offsets move them by ~1e-12)."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < count:
        q, arcs = resolved_wrist_configuration(robot, rng)
        q[4] = WRIST_OFFSETS[len(out) % len(WRIST_OFFSETS)]
        out.append((q, arcs))
    return out


def _nearest_to_zero(arcs: list[np.ndarray]) -> int:
    distance = [np.abs(wrapped(q6_grid()[arc])).min() for arc in arcs]
    return int(np.argmin(distance))


CONVENTIONS = ("standard", "modified")


@pytest.mark.parametrize("convention", CONVENTIONS)
@pytest.mark.parametrize("seed", range(3))
def test_each_arc_of_q6_the_elbow_reaches_with_has_a_solution(seed, convention):
    """Arms whose d5 is longer than the shorter planar link: singular poses with two arcs (and some with one),
    the generating q6 on the arc nearest 0 and on the other, each pose alone (solve_ik, with and without the
    generating configuration as reference, and with a reference on the other arc) and all in one batch
    (solve_ik_arrays, no reference). Before, only the arc of the reference (or 0), or of the nearer middle value,
    came back, with ``complete: true``."""
    robot = random_ur_type_arm(seed, convention, two_arcs=True)
    assert cached_plan(robot, constrain_orientation=True, reference=None).structure == "three_parallel"
    poses = _poses(robot, 100 + seed, 30)
    kinds = {"two arcs, generating on the arc nearest 0": 0, "two arcs, generating on the other": 0, "one arc": 0}
    batch = solve_ik_arrays(robot, forward_kinematics(robot, np.array([q for q, _ in poses])))
    failures = []
    for row, (q, arcs) in enumerate(poses):
        generating = arc_holding(arcs, q[5])
        if len(arcs) == 2:
            other = arcs[1 - generating]
            kinds["two arcs, generating on the " + ("arc nearest 0" if generating == _nearest_to_zero(arcs)
                                                     else "other")] += 1
        else:
            other = None
            kinds["one arc"] += 1
        T = forward_kinematics(robot, q)
        elsewhere = q.copy()
        if other is not None:
            elsewhere[5] = q6_grid()[other[len(other) // 2]]
        answers = [("batch", batch.joints[row, :batch.count[row]], bool(batch.complete[row]), 0.0)]
        for name, reference in (("alone", None), ("reference", q), ("reference elsewhere", elsewhere)):
            result = solve_ik(robot, T, reference=reference)
            solutions = np.array([s.joints for s in result.solutions]).reshape(-1, 6)
            answers.append((name, solutions, result.complete, 0.0 if reference is None else reference[5]))
            if name == "reference":  # the generating configuration is the representative of its arc, and first
                assert np.abs(joint_difference(robot, solutions[0], reference)).max() <= 1e-6, (row, name)
        for name, solutions, complete, given in answers:
            problem = _check(robot, q, arcs, solutions, complete, given)
            if problem:
                failures.append((row, name, float(q[4]), problem))
    assert not failures, failures
    assert min(kinds.values()) >= 3, kinds


@pytest.mark.parametrize("convention", CONVENTIONS)
@pytest.mark.parametrize("seed", range(3))
def test_one_arc_geometries_keep_their_single_representative(seed, convention):
    """Arms with the UR5's proportions (d5 short) and the UR5 itself: the reachable q6 are always one arc, and the
    singular branch keeps its one q6 value: the reference (or 0) where the elbow reaches with it, as before."""
    robot = _CATALOGUE.get("ur5").robot if seed == 0 and convention == "standard" else \
        random_ur_type_arm(seed, convention, two_arcs=False)
    poses = _poses(robot, 200 + seed, 20)
    batch = solve_ik_arrays(robot, forward_kinematics(robot, np.array([q for q, _ in poses])))
    failures = []
    for row, (q, arcs) in enumerate(poses):
        assert len(arcs) == 1
        result = solve_ik(robot, forward_kinematics(robot, q), reference=q)
        for name, solutions, complete, given in (
                ("batch", batch.joints[row, :batch.count[row]], bool(batch.complete[row]), 0.0),
                ("reference", np.array([s.joints for s in result.solutions]), result.complete, q[5])):
            problem = _check(robot, q, arcs, solutions, complete, given)
            if problem:
                failures.append((row, name, problem))
    assert not failures, failures
