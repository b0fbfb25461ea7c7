"""Near-singular sweeps: the configuration that generated a pose comes back, however close to the wrist singularity.

Each pose is FK of a random configuration whose middle wrist joint is ``eps`` (down to 1e-12, and 0). Near
``eps = 0`` the pose determines ``q4 + q6`` well but their split only to about ``1e-16 / eps``: two configurations
whose split differs by ``δ`` have orientations ``~ eps · δ`` apart. So a solution "is" the generating one when
every well-determined coordinate agrees to 1e-7 and the split agrees to what the pose can tell (``eps · δ`` at
most 1e-9, the FK acceptance). Before the fix of :func:`subproblems._paden_kahan._crossing_gap`,
``g = 1 - ||x0||²`` lost every digit at ``eps ≲ 1e-8``: the two wrist roots merged into one wrong one, and a whole
arm branch (6 or 7 solutions instead of 8) was gone with ``complete: true`` and no singularity reported.
"""

from __future__ import annotations

import numpy as np
import pytest

from service.robots.catalogue import load_catalogue
from service.config import BUILTIN_ROBOTS_DIR
from service.kinematics import forward_kinematics
from service.kinematics._tolerances import DUPLICATE_TOLERANCE
from service.kinematics.ik import joint_difference, solve_ik
from service.kinematics.ik.subproblems import subproblem_2_chain
from service.kinematics.ik._screws import rotate_about
from tests.arms import random_family_arm
from tests.ik_helpers import stretched_elbow, wrapped

EPSILONS = [1e-3, 1e-5, 1e-7, 3e-8, 1e-8, 5e-9, 3e-9, 2e-9, 1e-9, 1e-10, 1e-12, 0.0]
#: robot id → (first wrist joint, middle wrist joint, last wrist joint)
WRISTS = {"puma560_standard": (3, 4, 5), "puma560_modified": (3, 4, 5), "puma560_khalil": (3, 4, 5),
          "spong_ex4_3_elbow_with_wrist": (3, 4, 5),
          "spong_sec4_3_elbow_shoulder_offset_with_wrist": (3, 4, 5), "spong_ex3_5_stanford": (3, 4, 5)}


@pytest.fixture(scope="module")
def catalogue():
    return load_catalogue([BUILTIN_ROBOTS_DIR], max_joints=32)


def _recovered(robot, solutions: np.ndarray, q: np.ndarray, wrist: tuple[int, int, int], eps: float) -> bool:
    first, _, last = wrist
    d = joint_difference(robot, solutions, q)
    others = np.delete(np.abs(d), [first, last], axis=1).max(axis=1) if robot.dof > 3 else np.zeros(len(d))
    # near the singularity only q_first ± q_last is determined (the sign depends on the axes' directions)
    combined = np.minimum(np.abs(wrapped(d[:, first] + d[:, last])), np.abs(wrapped(d[:, first] - d[:, last])))
    split = np.abs(d[:, first]) * max(abs(np.sin(eps)), 1e-300)
    return bool(np.any((others <= 1e-7) & (combined <= 1e-7) & ((np.abs(d[:, first]) <= 1e-7) | (split <= 1e-9))))


@pytest.mark.parametrize("robot_id", sorted(WRISTS))
def test_wrist_sweep_returns_the_generating_configuration(catalogue, robot_id):
    robot = catalogue.get(robot_id).robot
    wrist = WRISTS[robot_id]
    rng = np.random.default_rng(11)
    failures = []
    for eps in EPSILONS:
        for trial in range(12):
            q = rng.uniform(-np.pi, np.pi, robot.dof)
            slides = ~robot.is_revolute
            q[slides] = rng.uniform(0.2, 1.0, slides.sum()) * robot.characteristic_length / 2
            q[wrist[1]] = eps if trial % 2 else -eps
            reference = q if trial % 3 else None  # with and without a reference: the free joint follows it
            result = solve_ik(robot, forward_kinematics(robot, q), reference=reference)
            solutions = np.array([s.joints for s in result.solutions]).reshape(-1, robot.dof)
            if not _recovered(robot, solutions, q, wrist, eps) and (reference is not None or eps > 1e-9):
                failures.append((eps, trial, len(solutions)))
            if reference is not None and result.singularities:
                # at the singularity the free joint takes the reference value: q itself is the representative
                assert np.abs(joint_difference(robot, solutions[0], q)).max() <= 1e-6, (eps, trial)
    assert not failures, failures


@pytest.mark.parametrize("robot_id", sorted(WRISTS))
def test_no_arm_branch_lost_near_the_wrist_singularity(catalogue, robot_id):
    """Above the singular tolerance each arm branch keeps both wrist roots: as many solutions as at 1e-3."""
    robot = catalogue.get(robot_id).robot
    wrist = WRISTS[robot_id]
    rng = np.random.default_rng(5)
    for trial in range(10):
        q = rng.uniform(-np.pi, np.pi, robot.dof)
        q[~robot.is_revolute] = 0.4 * robot.characteristic_length
        counts = []
        for eps in (1e-3, 1e-6, 1e-8, 3e-9):
            q[wrist[1]] = eps
            counts.append(len(solve_ik(robot, forward_kinematics(robot, q)).solutions))
        assert len(set(counts)) == 1, (trial, counts)


@pytest.mark.parametrize("eps", [1e-4, 1e-6, 1e-8, 5e-9, 2e-9])
def test_subproblem_2_keeps_both_roots_near_the_axis(eps):
    """R(z, θ1) R(y, θ2) z = t with t at angle eps from z: two roots ±eps, accurate to a few ulps of eps."""
    z, y = np.array([0.0, 0.0, 1.0]), np.array([0.0, 1.0, 0.0])
    target = rotate_about(z, 2.8, rotate_about(y, eps, z))
    solution = subproblem_2_chain(z, y, z, target)
    assert solution.valid.all() and not solution.merged and not solution.degenerate
    assert np.allclose(np.sort(solution.theta2), [-eps, eps], rtol=1e-9, atol=0.0)


#: robot id → the joints swept near 0 (every revolute joint but the wrist's middle one, swept above)
JOINT_SWEEPS = {"ur5": range(6), "puma560_standard": (0, 1, 2, 3, 5), "spong_ex4_3_elbow_with_wrist": (0, 1, 2, 3, 5),
                "spong_sec4_3_elbow_shoulder_offset_with_wrist": (0, 1, 2, 3, 5)}


@pytest.mark.parametrize("robot_id", sorted(JOINT_SWEEPS))
def test_every_joint_near_zero_returns_the_generating_configuration(catalogue, robot_id):
    """θ3 (the elbow), θ2, θ1, … of each family at ±eps from 1e-3 down to 1e-12 and 0, with a reference."""
    robot = catalogue.get(robot_id).robot
    rng = np.random.default_rng(2)
    failures = []
    for joint in JOINT_SWEEPS[robot_id]:
        for eps in (1e-3, 1e-6, 1e-8, 3e-9, 1e-9, 1e-10, 1e-12, 0.0):
            for trial in range(4):
                q = rng.uniform(-np.pi, np.pi, robot.dof)
                q[joint] = eps if trial % 2 else -eps
                result = solve_ik(robot, forward_kinematics(robot, q), reference=q)
                solutions = np.array([s.joints for s in result.solutions]).reshape(-1, robot.dof)
                distance = np.abs(joint_difference(robot, solutions, q)).max(axis=1).min() if len(solutions) else 9
                if distance > 1e-6:
                    failures.append((joint, eps, trial, float(distance)))
    assert not failures, failures


@pytest.mark.parametrize("joint", [1])  # the slide d3 near 0: test_slides_near_zero_… below
def test_stanford_shoulder_and_slide_near_their_fold_return_the_generating_configuration(catalogue, joint):
    """θ2 → 0 (the wrist centre as near axis 1 as the offset d2 allows) and d3 → 0 (the slide at its nearest
    reach) are folds: two solutions ``~eps`` apart meet. Each answer holds the generating configuration to 1e-7,
    or reports the meeting at the shoulder / reach and holds it within ``DUPLICATE_TOLERANCE`` (the project's
    "same solution"; the representative is the midpoint of two roots at most that far apart). Before the
    subproblem-2 merge was bounded in angle, θ2 = 6e-7 came back 1.0–1.5e-6 off, merged with its neighbour."""
    robot = catalogue.get("spong_ex3_5_stanford").robot
    size = robot.characteristic_length
    rng = np.random.default_rng(2)
    failures = []
    for eps in (1e-3, 1e-5, 1e-6, 6e-7, 3e-7, 1e-7, 3e-8, 1e-8, 1e-9, 1e-10, 1e-12, 0.0):
        for trial in range(6):
            q = rng.uniform(-np.pi, np.pi, robot.dof)
            q[2] = rng.uniform(0.2, 1.0) * size
            q[joint] = (eps if trial % 2 else -eps) * (size if joint == 2 else 1.0)
            result = solve_ik(robot, forward_kinematics(robot, q), reference=q if trial % 3 else None)
            solutions = np.array([s.joints for s in result.solutions]).reshape(-1, robot.dof)
            scaled = joint_difference(robot, solutions, q) / np.where(robot.is_revolute, 1.0, size)
            distance = np.abs(scaled).max(axis=1).min() if len(solutions) else 9.0
            met = any(s.relation == "boundary" for s in result.singularities)
            if not (distance <= 1e-7 or (met and distance <= DUPLICATE_TOLERANCE)) or not result.complete:
                failures.append((eps, trial, len(solutions), float(distance), met))
    assert not failures, failures


#: robot id → whether its sweep targets are poses (else points): every catalogue arm with a slide among its
#: positioning joints, swept near the slide's zero (where the Stanford and polar arms put the point on axis 2
#: or at the shoulder's centre, and the cylindrical arms on axis 1)
SLIDE_SWEEPS = {"spong_ex3_5_stanford": True, "spong_sec4_3_spherical_arm_rrp": False,
                "spong_sec4_3_spherical_arm_table3_4_frames": False, "ex004_2_polar_rrp": False,
                "ex004_4_polar_offset_rrp": False, "ex004_1_prp": False, "ex004_3_spherical_rrpr": False,
                "spong_ex3_2_cylindrical_rpp": False, "spong_ex3_4_cylindrical_with_wrist": True,
                "spong_ex3_6_scara_rrpr": False, "assur001_scara_rrp": False}
SLIDE_EPSILONS = (1e-3, 1e-5, 1e-6, 1e-7, 3e-8, 1e-8, 1e-9, 1e-10, 1e-12, 0.0)


@pytest.mark.parametrize("robot_id", sorted(SLIDE_SWEEPS))
def test_slides_near_zero_return_the_generating_configuration(catalogue, robot_id):
    """Each slide at ±eps of the arm's size, eps from 1e-3 down to 1e-12 and 0: never ``unreachable``, always
    complete, every solution on the target, and the generating configuration back.

    With the generating configuration as reference it comes back to 1e-7 (or, where a fold is reported, to
    ``DUPLICATE_TOLERANCE``). Without one, near the Stanford arm's d3 = 0 the pose itself does not tell it
    apart from its neighbours: joint 2 moves the point by ``d3 · δ`` and the shoulder's fold shows ``d3`` only
    through its square, so at d3 = 1e-6 of the arm's size q2 ± 1e-4 reproduces the pose to rounding. The
    answer then holds the generating configuration to 1e-7, or one whose FK is the target to 1e-13 of the
    arm's size (the pose cannot tell them apart), or reports joints free and holds every other one to 1e-7
    (a point within ``GEOMETRY_TOLERANCE`` of the cylindrical arm's axis: joint 1 is free, set to 0). Before, d3 in [1e-9, 1e-7] came back ``unreachable`` with ``complete: true``: the
    slide was solved from the reach alone (``‖y‖² = d2² + d3²``), its roots ±d3 merged into 0, which puts the
    point on axis 2 where the shoulder cannot tilt it back by d3 / d2.
    """
    robot = catalogue.get(robot_id).robot
    pose = SLIDE_SWEEPS[robot_id]
    size = robot.characteristic_length
    compared = slice(None) if pose else slice(0, 3)  # position targets fix the positioning joints only
    rng = np.random.default_rng(6)
    failures, count = [], 0
    for joint in np.flatnonzero(~robot.is_revolute):
        for eps in SLIDE_EPSILONS:
            for trial in range(8):
                q = rng.uniform(-np.pi, np.pi, robot.dof)
                q[~robot.is_revolute] = rng.uniform(0.2, 1.0, (~robot.is_revolute).sum()) * size
                q[joint] = (eps if trial % 2 else -eps) * size
                reference = q if trial % 4 else None
                target = forward_kinematics(robot, q)
                result = solve_ik(robot, target, constrain_orientation=pose, reference=reference)
                count += 1
                solutions = np.array([s.joints for s in result.solutions]).reshape(-1, robot.dof)
                if result.status != "ok" or not result.complete:
                    failures.append((int(joint), eps, trial, result.status, result.complete))
                    continue
                reached = forward_kinematics(robot, solutions)
                off = np.abs(reached[:, :3, 3] - target[:3, 3]).max() / size
                if pose:
                    off = max(off, np.abs(reached[:, :3, :3] - target[:3, :3]).max())
                assert off <= 1e-9, (joint, eps, trial, off)
                scaled = joint_difference(robot, solutions, q) / np.where(robot.is_revolute, 1.0, size)
                distance = np.abs(scaled[:, compared]).max(axis=1)
                if distance.min() <= 1e-7:
                    continue
                if reference is not None:
                    met = any(s.relation == "boundary" for s in result.singularities)
                    if not (met and distance.min() <= DUPLICATE_TOLERANCE):
                        failures.append((int(joint), eps, trial, "reference", float(distance.min())))
                    continue
                apart = np.abs(reached[:, :3, 3] - target[:3, 3]).max(axis=-1) / size
                if pose:
                    apart = np.maximum(apart, np.abs(reached[:, :3, :3] - target[:3, :3]).max(axis=(1, 2)))
                free = [j for s in result.singularities if s.relation == "free" for j in s.joints]
                fixed = np.delete(np.abs(scaled[:, compared]), free, axis=1).max(axis=1, initial=0.0)
                if apart.min() > 1e-13 and not (free and fixed.min() <= 1e-7):
                    failures.append((int(joint), eps, trial, "no reference", float(distance.min()), float(apart.min())))
    assert count >= 80
    assert not failures, failures


def test_zero_length_links_report_every_free_shoulder_joint():
    """All lengths zero: the wrist centre is the shoulder's centre whatever q1, q2, q3; both shoulder joints are
    reported free and take the reference values, so the generating configuration comes back (q2 was left at 0,
    unflagged, before)."""
    from service.robots.build import robot_from_description
    from service.robots.schemas import DHRobot

    half = np.pi / 2
    robot = robot_from_description(DHRobot.model_validate({"id": "zero", "convention": "standard", "joints": [
        {"a": 0, "alpha": half, "d": 0}, {"a": 0, "alpha": 0, "d": 0}, {"a": 0, "alpha": half, "d": 0},
        {"a": 0, "alpha": -half, "d": 0}, {"a": 0, "alpha": half, "d": 0}, {"a": 0, "alpha": 0, "d": 0}]}),
        max_joints=32)
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = rng.uniform(-np.pi, np.pi, 6)
        result = solve_ik(robot, forward_kinematics(robot, q), reference=q)
        assert any(s.kind == "shoulder" and tuple(s.joints) == (0, 1) for s in result.singularities)
        solutions = np.array([s.joints for s in result.solutions])
        assert np.abs(joint_difference(robot, solutions, q)).max(axis=1).min() <= 1e-7


def test_coincident_first_axes_are_not_taken_for_a_spherical_wrist():
    """Joints 1 and 2 on one line (α1 = 0, a1 = 0) turn the tool about that line together: only q1 + q2 counts.
    The three axes through one point were taken for a spherical wrist at the base, which cannot reach an FK
    pose of this arm: ``unreachable`` with ``complete: true``. Now every answer reports the relation (q1 + q2
    fixed, q2 free at the reference) and holds the generating configuration up to the split, complete: the arm
    without joint 2 is an intersecting shoulder (position targets) with a two-axis wrist (poses)."""
    from service.robots.build import robot_from_description
    from service.robots.schemas import DHRobot

    half = np.pi / 2
    robot = robot_from_description(DHRobot.model_validate({"id": "coaxial", "convention": "standard", "joints": [
        {"a": 0, "alpha": 0, "d": 0.3}, {"a": 0, "alpha": half, "d": 0.1}, {"a": 0.4, "alpha": 0, "d": 0},
        {"a": 0.05, "alpha": half, "d": 0.35}, {"a": 0, "alpha": -half, "d": 0}, {"a": 0, "alpha": 0, "d": 0.1}]}),
        max_joints=32)
    q = np.random.default_rng(1).uniform(-np.pi, np.pi, 6)
    target = forward_kinematics(robot, q)
    for constrain_orientation in (True, False):
        result = solve_ik(robot, target, constrain_orientation=constrain_orientation, reference=q)
        assert result.status == "ok" and result.complete and result.method == "analytic"
        assert any(s.kind == "coaxial" and s.joints == (0, 1) and s.relation == "sum" for s in result.singularities)
        assert 1 in result.free_joints
        solutions = np.array([s.joints for s in result.solutions])
        d = joint_difference(robot, solutions, q)
        same_sum = np.abs(wrapped(d[:, 0] + d[:, 1])) <= 1e-7
        others = np.abs(d[:, 2:]).max(axis=1) <= 1e-7 if constrain_orientation else np.ones(len(d), bool)
        assert np.any(same_sum & others)
        np.testing.assert_allclose([forward_kinematics(robot, s)[:3, 3] for s in solutions],
                                   np.broadcast_to(target[:3, 3], (len(solutions), 3)), atol=1e-9)


#: the UR5 and random UR-type arms (axes 2 ∥ 3 ∥ 4, axes 5 and 6 meeting, their twists equal so the wrist can be
#: singular) in each convention, with random base and tool frames
UR_TYPE_ARMS = ["ur5"] + [f"{convention}-{seed}" for convention in ("standard", "modified", "khalil")
                          for seed in (0, 1)]
UR_TYPE_EPSILONS = (1e-3, 1e-6, 3e-7, 1e-7, 3e-8, 1e-8, 3e-9, 1e-9, 1e-10, 1e-12, 0.0)


def _turn_onto(k: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """The angle about the unit axis k that turns a's part normal to k onto b's direction."""
    a, b = a - (a @ k) * k, b - (b @ k) * k
    return float(np.arctan2(k @ np.cross(a, b), a @ b))


def _ur_type_singular_values(plan, q: np.ndarray, kind: str) -> tuple[int, float]:
    """The joint swept and its singular value for q's other joints: θ5 with axis 6 along the parallel axes (the
    wrist), θ3 with the elbow stretched, θ4 with θ2 + θ3 + θ4 turning axis 5 as near axis 1 as it goes."""
    g = plan.geometry
    w_p = g.direction(1)
    if kind == "wrist":
        k, six = g.direction(4), g.direction(5)
        side = 1.0 if abs(six @ k - w_p @ k) <= abs(six @ k + w_p @ k) else -1.0
        return 4, _turn_onto(k, six, side * w_p)
    if kind == "elbow":
        return 2, stretched_elbow(plan, q)
    s2, s3, s4 = plan.signs
    total = _turn_onto(w_p, g.direction(4), g.direction(0))
    return 3, float(s4 * (total - s2 * q[1] - s3 * q[2]))


@pytest.mark.parametrize("kind", ["wrist", "elbow", "alignment"])
@pytest.mark.parametrize("arm", UR_TYPE_ARMS)
def test_ur_type_arms_near_their_singularities_return_the_generating_configuration(catalogue, arm, kind):
    """θ5 at ±eps from the wrist singularity (axis 6 along axes 2–4), θ3 from the stretched elbow, θ2 + θ3 + θ4
    from axis 5's nearest approach to axis 1, eps from 1e-3 down to 1e-12 and 0, each pose alone (solve_ik, the
    scalar path where it answers) and all in one batch (solve_ik_arrays): ``complete`` and the generating
    configuration back, up to the relation a reported wrist singularity leaves free (q2, q3, q4 and q6 along a
    self-motion; q1 and q5 still hold). Before subproblem 2 gave the wrist, its roots came from the height
    ω_p·R ω6 = cos q5, which merged ±q5 below 5e-7 into q5 = 0, where q6 was set to 0 whether the elbow reached
    or not: the UR5 lost a whole shoulder branch (4 of 8 solutions) with ``complete: true``."""
    from service.kinematics.ik import solve_ik_arrays
    from service.kinematics.ik import cached_plan

    if arm == "ur5":
        robot = catalogue.get("ur5").robot
    else:
        convention, seed = arm.split("-")
        robot = random_family_arm("three_parallel", convention, int(seed), wrist_singular=True)
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    assert plan.structure == "three_parallel"
    rng = np.random.default_rng(7)
    generating = []
    for eps in UR_TYPE_EPSILONS:
        for trial in range(4):
            q = rng.uniform(-np.pi, np.pi, 6)
            joint, singular = _ur_type_singular_values(plan, q, kind)
            q[joint] = singular + (eps if trial % 2 else -eps)
            generating.append((eps, trial, q))
    poses = forward_kinematics(robot, np.array([q for _, _, q in generating]))
    batch = solve_ik_arrays(robot, poses)
    failures = []
    for row, ((eps, trial, q), pose) in enumerate(zip(generating, poses)):
        result = solve_ik(robot, pose)
        # Near the wrist singularity the pose holds q2, q3, q4 and q6 (the planar self-motion) only to what it can
        # tell: configurations δ apart along it have poses ~eps·δ apart, so δ up to the FK acceptance (1e-9) over
        # eps is the generating one (as _recovered above); where the singularity is reported they are free. Near the
        # elbow fold two roots ~eps apart meet: each is good to about √(rounding) over the arm's conditioning.
        coupled = np.array([False, True, True, True, False, True]) if kind == "wrist" else np.zeros(6, bool)
        split = np.inf if any(s.kind == "wrist" for s in result.singularities) else max(1e-6, 1e-9 / max(eps, 1e-300))
        tolerance = np.where(coupled, split, 1e-5 if kind == "elbow" else 1e-6)
        for answer, joints in (("alone", np.array([s.joints for s in result.solutions]).reshape(-1, 6)),
                               ("batch", batch.joints[row, :batch.count[row]])):
            complete = result.complete if answer == "alone" else bool(batch.complete[row])
            gaps = (np.abs(joint_difference(robot, joints, q)) / tolerance).max(axis=1) if len(joints) else [9.0]
            if not complete or np.min(gaps) > 1.0:
                failures.append((answer, eps, trial, len(joints), complete, float(np.min(gaps))))
    assert not failures, failures
