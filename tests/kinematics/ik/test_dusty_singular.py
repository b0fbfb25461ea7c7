"""Near-singular poses of arms whose special relations hold only to rounding dust (issue 22.6).

A vendor URDF writes π/2 as 1.57079632679 (5e-12 off): the relations a closed form relies on then hold within
``GEOMETRY_TOLERANCE`` but not exactly, and near a singularity that dust is amplified (over a small radius, or
through a fold's square root). CAD rounding of 1e-6…1e-5 moves the arm further: it is idealised and refined.
For each arm a random configuration is moved onto the singularity and perturbed by δ; the target is its own
FK. The promise (api.md): never ``unreachable``; ``complete`` only with the generating configuration among the
solutions, or with the singularity reported and the generating configuration a member of the family it
represents (asked again with it as the reference, the answer holds it).

* a 7R arm of the KUKA iiwa's geometry with q7 held, at the stretched elbow (q4 = 0: the point on axis 5);
* a 6R arm of the PUMA type (intersecting shoulder, spherical wrist) at the wrist singularity (q5 = 0);
* a general 6R arm whose axes 1 and 3 coincide, or nearly, at q2 = 0 (the xArm 7's shoulder with q7 held).
"""

from __future__ import annotations

import numpy as np
import pytest

from service.kinematics import Joint, Robot, ScrewJoint, forward_kinematics
from service.kinematics.ik import AnswerOptions, IKTargets, answer_ik, joint_difference, result_of, unlimited
from service.kinematics._tolerances import DUPLICATE_TOLERANCE
from tests.arms import kinova_j2n6s300, random_general_arm
from tests.ik_helpers import multistart_solutions, singular_configuration

DELTAS = (0.0, 1e-12, 1e-9, 1e-6, 1e-3)
HALF_PI_IN_A_URDF = 1.57079632679  # example-robot-data's iiwa and Jaco write it so


def _alpha(value: float, rng: np.random.Generator, dust: float) -> float:
    """A right angle (±π/2) as a file states it: 11 digits (dust 0) or off by ``dust`` (CAD rounding)."""
    if abs(abs(value) - np.pi / 2) > 1e-3:
        return value + (rng.choice([-1.0, 1.0]) * dust if dust else 0.0)
    return np.sign(value) * (HALF_PI_IN_A_URDF + (rng.uniform(-1.0, 1.0) * dust if dust else 0.0))


def _iiwa_like(rng: np.random.Generator, dust: float) -> Robot:
    """The KUKA LBR iiwa 14's standard DH table (d = 0.36, 0.42, 0.4, 0.126), right angles as a URDF writes them."""
    rows = [(0.36, -np.pi / 2), (0.0, np.pi / 2), (0.42, np.pi / 2), (0.0, -np.pi / 2), (0.4, -np.pi / 2),
            (0.0, np.pi / 2), (0.126, 0.0)]
    return Robot([Joint(f"j{i + 1}", "revolute", 0.0, _alpha(alpha, rng, dust), d, 0.0)
                  for i, (d, alpha) in enumerate(rows)])


def _puma_like(rng: np.random.Generator, dust: float) -> Robot:
    """The PUMA 560's standard DH table, right angles as a URDF writes them."""
    rows = [(0.0, 0.0, np.pi / 2), (0.0, 0.4318, 0.0), (0.15005, 0.0203, -np.pi / 2), (0.4318, 0.0, np.pi / 2),
            (0.0, 0.0, -np.pi / 2), (0.0, 0.0, 0.0)]
    return Robot([Joint(f"j{i + 1}", "revolute", a, _alpha(alpha, rng, dust), d, 0.0)
                  for i, (d, a, alpha) in enumerate(rows)])


def _coaxial_shoulder(rng: np.random.Generator, offset: float) -> Robot:
    """A general 6R arm whose axis 3 lies on axis 1 at q2 = 0 (the xArm 7's shoulder with q7 held), or ``offset``
    beside it; axis 2 crosses 0.05 beside them (so no three axes meet: no closed form), and axes 4-6 are random.
    Screws at q = 0 in the base frame, lengths in metres."""
    z, x = (0.0, 0.0, 1.0), (1.0, 0.0, 0.0)
    joints = [ScrewJoint("j1", "revolute", z, (0.0, 0.0, 0.0)), ScrewJoint("j2", "revolute", x, (0.0, 0.05, 0.3)),
              ScrewJoint("j3", "revolute", z, (offset, 0.0, 0.0))]
    for name in ("j4", "j5", "j6"):
        axis = rng.normal(size=3)
        joints.append(ScrewJoint(name, "revolute", tuple(axis / np.linalg.norm(axis)),
                                 tuple(rng.uniform(-0.3, 0.3, 2)) + (rng.uniform(0.4, 0.9),)))
    flange = np.eye(4)
    flange[:3, 3] = (0.1, 0.0, 1.0)
    return Robot.from_screws(joints, flange)


def _answer(robot: Robot, target: np.ndarray, reference: np.ndarray | None, held: float | None):
    free = None if held is None else [(robot.dof - 1, [held], None)]
    options = AnswerOptions(reference=reference, limits=unlimited(robot), filter_limits=False, free_joints=free)
    return result_of(answer_ik(robot, IKTargets.poses(target[None]), options), 0)


def _nearest(robot: Robot, result, q: np.ndarray) -> float:
    solutions = np.array([s.joints for s in result.solutions]).reshape(-1, robot.dof)
    return float(np.abs(joint_difference(robot, solutions, q)).max(axis=1).min()) if len(solutions) else np.inf


def _check_promises(robot: Robot, q_singular: np.ndarray, joint: int, *, held: bool) -> list[str]:
    """The promise at each δ; returns the structures that answered (to check the family the test is about)."""
    structures = []
    for delta in DELTAS:
        q = q_singular.copy()
        q[joint] += delta
        target = forward_kinematics(robot, q)
        value = float(q[-1]) if held else None
        result = _answer(robot, target, None, value)
        structures.append(result.structure)
        where = (delta, q.tolist(), result.structure, result.detail)
        assert result.status != "unreachable", where
        if not result.complete or _nearest(robot, result, q) <= 1e-6:
            continue
        assert result.singularities, (*where, "complete without the generating configuration, and no singularity")
        folds = {"boundary", "stretched", "folded", "stretched_or_folded"}
        tolerance = 2e-6 if any(s.relation in folds for s in result.singularities) else 1e-6
        again = _answer(robot, target, q, value)
        assert _nearest(robot, again, q) <= tolerance, (*where, result.singularities)
    return structures


@pytest.mark.parametrize("seed", range(6))
def test_iiwa_like_stretched_elbow_with_q7_held(seed):
    """The point on axis 5 (q4 = 0): subproblem 2 of the shoulder (joints 6, 5 of the reversed chain) is
    degenerate in its second joint, not its first, and at q4 = 1e-6 the fold's square root of the 5e-12 dust
    splits the cones by 5e-8 (before: not_found at δ ≤ 1e-9, a false 'unreachable' at 1e-6)."""
    rng = np.random.default_rng(seed)
    robot = _iiwa_like(rng, 0.0)
    q = rng.uniform(-1.5, 1.5, 7)
    q[3] = 0.0
    structures = _check_promises(robot, q, 3, held=True)
    assert all(s.startswith("spherical_wrist+intersecting_shoulder") for s in structures), structures


@pytest.mark.parametrize("dust", [1e-6, 1e-5])
def test_iiwa_like_with_cad_rounding_near_the_stretched_elbow(dust):
    rng = np.random.default_rng(int(dust * 1e7))
    robot = _iiwa_like(rng, dust)
    for _ in range(3):
        q = rng.uniform(-1.5, 1.5, 7)
        q[3] = 0.0
        _check_promises(robot, q, 3, held=True)


@pytest.mark.parametrize("seed", range(6))
def test_puma_like_wrist_with_urdf_dust(seed):
    """q5 = 0 of a PUMA written with 11-digit right angles: R_w carries the dust, q4 seen over the radius
    sin(q5) turned by dust / sin(q5) (before: 0.017 rad off at q5 = 1e-9, no singularity reported)."""
    rng = np.random.default_rng(seed)
    robot = _puma_like(rng, 0.0)
    q = rng.uniform(-1.5, 1.5, 6)
    q[4] = 0.0
    structures = _check_promises(robot, q, 4, held=False)
    assert all(s == "intersecting_shoulder+spherical_wrist" for s in structures), structures


@pytest.mark.parametrize("dust", [1e-6, 1e-5])
def test_puma_like_wrist_with_cad_rounding(dust):
    """Right angles 1e-6/1e-5 off: the wrist's flip pair folds at q5 = 0 (the axes span no volume there). Before:
    at q5 = 1e-12 subproblem 2 merged the pair and its representative lay 4e-6 from the generating configuration;
    at q5 = 1e-9 (dust 1e-5) the pair was two roots, one 1.4e-6 off (q4 seen through a volume of 2e-11), and no
    singularity was reported. Now the wrist reports the fold (or the near alignment) and holds q4 at the
    reference where that reaches the target."""
    rng = np.random.default_rng(int(dust * 1e7) + 1)
    robot = _puma_like(rng, dust)
    for _ in range(3):
        q = rng.uniform(-1.5, 1.5, 6)
        q[4] = 0.0
        _check_promises(robot, q, 4, held=False)


COAXIAL_CASES = [(seed, offset) for seed in range(4) for offset in (0.0, 1e-9, 1e-7, 1e-6, 1e-5)]


@pytest.mark.parametrize("seed, offset", COAXIAL_CASES)
def test_general_6r_with_nearly_coaxial_joints_1_and_3(seed, offset):
    """q2 = 0 puts axis 3 on (or ``offset`` from) axis 1: the general solver's roots land anywhere on the
    family q1 + t, q3 − t (before: complete with a member 0.01-0.02 rad off and no singularity)."""
    rng = np.random.default_rng(seed)
    robot = _coaxial_shoulder(rng, offset)
    q = rng.uniform(-1.5, 1.5, 6)
    q[1] = 0.0
    structures = _check_promises(robot, q, 1, held=False)
    assert "general_6r" in structures, structures


@pytest.mark.parametrize("arm", ["kinova_j2n6s300", "random_general_arm"])
def test_general_6r_where_two_solutions_meet(arm):
    """det J = 0 on a general 6R arm (found by bisection along a random segment), the configuration's joint 1 then
    moved by δ: two roots of the elimination meet there, and each is found only to about 1e-6 along the null
    motion (before: complete, the listed root 1e-6…9e-6 from the generating configuration, no singularity; 57
    of 525 such requests on five general arms)."""
    robot = kinova_j2n6s300() if arm == "kinova_j2n6s300" else random_general_arm(np.random.default_rng(11),
                                                                                  "standard")
    rng = np.random.default_rng(7)
    for _ in range(6):
        structures = _check_promises(robot, singular_configuration(robot, rng), 0, held=False)
        assert "general_6r" in structures or "general" in structures, structures


def test_general_6r_keeps_the_closed_form_where_two_solutions_meet():
    """The Jaco 2's second configuration at det J = 0 of the test above (joint 1 moved by each δ): the elimination
    gives the two meeting roots as one (1e-6…9e-6 off), so before, every answer went to the numeric search. Its
    two roots are split by Newton's steps from either side along the null motion: the closed form answers,
    complete, reports the fold, and with the generating configuration as the reference lists it (to Newton's
    accuracy)."""
    robot = kinova_j2n6s300()
    rng = np.random.default_rng(7)
    for _ in range(2):
        q_singular = singular_configuration(robot, rng)
    for delta in DELTAS:
        q = q_singular.copy()
        q[0] += delta
        target = forward_kinematics(robot, q)
        result = _answer(robot, target, None, None)
        assert (result.method, result.complete) == ("analytic", True), (delta, result.detail)
        assert [s.relation for s in result.singularities] == ["boundary"], (delta, result.singularities)
        assert _nearest(robot, _answer(robot, target, q, None), q) <= 1e-12, delta


@pytest.mark.parametrize("arm", ["kinova_j2n6s300", "random_general_arm"])
def test_general_6r_answers_a_double_root_once_in_closed_form(arm):
    """Targets made by FK at det J = 0 (bisection, 6 per arm): two of the 16 roots meet there, and the eigenproblem
    gives them as a pair neither clearly real nor clearly complex, or as two real roots a rounding apart. Before,
    every such answer went to the numeric search (197 of 525 near-singular requests in benchmarks.general_6r_singular);
    now the pair is split along the null motion, and where both sides meet within DUPLICATE_TOLERANCE it is one
    double root: listed once, the fold reported, the answer complete. The generating configuration is listed
    (within 1e-6 with no reference; to Newton's accuracy with it as the reference), no two listed solutions are
    the same solution, and a 600-start search finds none farther than 1e-4 from a listed one."""
    robot = kinova_j2n6s300() if arm == "kinova_j2n6s300" else random_general_arm(np.random.default_rng(11),
                                                                                  "standard")
    rng = np.random.default_rng(21)
    for _ in range(6):
        q = singular_configuration(robot, rng)
        target = forward_kinematics(robot, q)
        result = _answer(robot, target, None, None)
        where = (q.tolist(), result.detail)
        assert (result.method, result.structure, result.complete) == ("analytic", "general_6r", True), where
        assert [s.relation for s in result.singularities] == ["boundary"], where
        listed = np.array([s.joints for s in result.solutions])
        gaps = np.abs(joint_difference(robot, listed[:, None, :], listed[None, :, :])).max(axis=-1)
        assert (gaps[~np.eye(len(listed), dtype=bool)] > DUPLICATE_TOLERANCE).all(), where
        assert _nearest(robot, result, q) <= 1e-6, where
        assert _nearest(robot, _answer(robot, target, q, None), q) <= 1e-12, where
        oracle = multistart_solutions(robot, target, 600, rng)
        assert all(_nearest_to(robot, listed, s) <= 1e-4 for s in oracle), where


def _nearest_to(robot: Robot, listed: np.ndarray, q: np.ndarray) -> float:
    return float(np.abs(joint_difference(robot, listed, q)).max(axis=1).min())
