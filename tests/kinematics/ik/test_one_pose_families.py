"""The scalar path for one pose (``solve_one``, ik/_scalar.py) against the array path, on random arms of its two
families in every convention with random base and tool frames, and on poses approaching the wrist and elbow
singularities: the same solutions, labels and residuals whichever path answers."""

from __future__ import annotations

import numpy as np
import pytest

from service.kinematics import CONVENTIONS, Robot, forward_kinematics
from service.kinematics.ik import joint_difference, solve_ik, solve_ik_arrays
from service.kinematics.ik import cached_plan
from service.robots.catalogue import load_catalogue
from service.config import Settings
from tests.arms import RandomDHRows, random_family_arm, random_stanford_type_arm, rounded, stated_three_ways
from tests.ik_helpers import random_configurations, stretched_elbow

FAMILIES = ("intersecting_shoulder+spherical_wrist", "offset_shoulder_parallel_elbow+spherical_wrist", "three_parallel")


def _array_path(monkeypatch, plan) -> None:
    monkeypatch.setattr(type(plan), "solve_one", lambda self, world_T_target, reference=None: None)


def assert_same_answers(robot: Robot, fast: list, slow: list, tolerance: float) -> None:
    """The same status, singularities and number of solutions; each solution of one found in the other within
    ``tolerance`` (radians), with the same branch labels and residuals."""
    for a, b in zip(fast, slow):
        assert (a.status, a.structure, a.singularities, a.free_joints, a.complete, a.detail) == \
               (b.status, b.structure, b.singularities, b.free_joints, b.complete, b.detail)
        assert len(a.solutions) == len(b.solutions)
        if not b.solutions:
            continue
        others = np.array([s.joints for s in b.solutions])
        matched = set()
        for solution in a.solutions:
            gaps = np.abs(joint_difference(robot, others, solution.joints)).max(axis=1)
            index = int(np.argmin(gaps))
            assert gaps[index] <= tolerance
            matched.add(index)
            assert solution.branch == b.solutions[index].branch
            assert abs(solution.position_residual - b.solutions[index].position_residual) <= 1e-12 * \
                robot.characteristic_length
            orientation = solution.orientation_residual, b.solutions[index].orientation_residual
            assert abs(orientation[0] - orientation[1]) <= 1e-12 or np.isnan(orientation).all()  # (NaN: a position)
        assert len(matched) == len(a.solutions)


def answers_on_both_paths(robot: Robot, plan, poses: np.ndarray, references: list, constrain_orientation: bool,
                          monkeypatch) -> tuple[list, int]:
    """``solve_ik`` of each pose (with its reference) with the scalar path, then held to the array path's answers
    (:func:`assert_same_answers`); returns the scalar-path answers and how many poses the scalar path took."""
    answered = sum(plan.solve_one(T, reference) is not None for T, reference in zip(poses, references))
    fast = [solve_ik(robot, T, constrain_orientation=constrain_orientation, reference=reference)
            for T, reference in zip(poses, references)]
    _array_path(monkeypatch, plan)
    slow = [solve_ik(robot, T, constrain_orientation=constrain_orientation, reference=reference)
            for T, reference in zip(poses, references)]
    monkeypatch.undo()
    assert_same_answers(robot, fast, slow, 1e-9)
    return fast, answered


def holds_the_generating_vector(robot: Robot, result, generating: np.ndarray) -> bool:
    joints = np.array([s.joints for s in result.solutions]).reshape(-1, robot.dof)
    return len(joints) > 0 and np.abs(joint_difference(robot, joints, generating)).max(axis=1).min() <= 1e-7


@pytest.mark.parametrize("convention", CONVENTIONS)
@pytest.mark.parametrize("family", FAMILIES)
def test_random_arms_of_the_families_answer_alike_on_both_paths(family, convention, monkeypatch):
    """Every pose from the arm's FK: the scalar path answers most of them (it is the common case) and finds the
    generating vector; with it switched off the array path gives the same solutions, labels and residuals; the
    array form (solve_ik_arrays of one pose) holds the same solutions as the object form."""
    answered = 0
    for seed in range(4):
        robot = random_family_arm(family, convention, seed)
        plan = cached_plan(robot, constrain_orientation=True, reference=None)
        assert plan.structure == family
        rng = np.random.default_rng(seed)
        q = rng.uniform(-np.pi, np.pi, (40, 6))
        poses = forward_kinematics(robot, q)
        answered += sum(plan.solve_one(T) is not None for T in poses)
        fast = [solve_ik(robot, T) for T in poses]
        arrays = [solve_ik_arrays(robot, T[None]) for T in poses]
        for generating, result, array in zip(q, fast, arrays):
            joints = np.array([s.joints for s in result.solutions])
            assert np.abs(joint_difference(robot, joints, generating)).max(axis=1).min() <= 1e-7
            assert array.count[0] == len(joints)
            np.testing.assert_array_equal(array.joints[0, :array.count[0]], joints)
        _array_path(monkeypatch, plan)
        slow = [solve_ik(robot, T) for T in poses]
        monkeypatch.undo()
        assert_same_answers(robot, fast, slow, 1e-9)
    assert answered >= 0.9 * 4 * 40


@pytest.mark.parametrize("convention", CONVENTIONS)
def test_random_stanford_type_arms_answer_alike_on_both_paths(convention, monkeypatch):
    """The Stanford type (a slide through axis 2, :class:`SlideThroughAxis2`, and a spherical wrist) on random arms
    with random base and tool frames: poses from the arm's FK, a third of them with the slide within 1e-3 … 1e-12
    of the crossing (where the shoulder's two solutions fold together and only the array path answers), with and
    without the generating vector as reference. The scalar path answers most poses away from the crossing, and
    both paths give the same solutions, labels and residuals, the generating vector among them there."""
    answered = compared = 0
    for seed in range(4):
        robot = random_stanford_type_arm(convention, seed)
        plan = cached_plan(robot, constrain_orientation=True, reference=None)
        assert plan.positioner.slide_through_axis_2 is not None
        foot = plan.positioner.slide_through_axis_2.foot
        rng = np.random.default_rng(seed)
        q = rng.uniform(-np.pi, np.pi, (45, 6))
        q[:, 2] = rng.uniform(0.1, 0.6, 45) * rng.choice([-1, 1], 45)
        q[::3, 2] = foot + rng.choice([1e-3, 1e-6, 1e-9, 1e-12], 15) * rng.choice([-1, 1], 15)
        poses = forward_kinematics(robot, q)
        references = [None if i % 2 else generating for i, generating in enumerate(q)]
        answered += sum(plan.solve_one(T) is not None for T in poses[1::3])
        fast = [solve_ik(robot, T, reference=reference) for T, reference in zip(poses, references)]
        for generating, result in list(zip(q, fast))[1::3]:  # (near the crossing the pose may leave q2 free)
            joints = np.array([s.joints for s in result.solutions])
            assert np.abs(joint_difference(robot, joints, generating)).max(axis=1).min() <= 1e-7
        _array_path(monkeypatch, plan)
        slow = [solve_ik(robot, T, reference=reference) for T, reference in zip(poses, references)]
        monkeypatch.undo()
        assert_same_answers(robot, fast, slow, 1e-9)
        compared += len(poses)
    assert answered >= 0.9 * 4 * 15 and compared == 4 * 45


_CATALOGUE = load_catalogue([Settings().builtin_robots_dir], max_joints=32)


@pytest.mark.parametrize("robot_id", ["puma560_standard", "ur5"])
@pytest.mark.parametrize("joint", ["wrist", "elbow"])
def test_poses_approaching_the_wrist_and_elbow_singularities_answer_alike(robot_id, joint, monkeypatch):
    """θ5 at 1e-3 … 1e-12 and 0 from its singular value 0, θ3 as far from the stretched elbow: whichever path the
    scalar path leaves to the array path, the answers are the same sets with the same labels, and hold the
    generating vector (the joints the singularity couples within the conditioning it allows)."""
    robot = _CATALOGUE.get(robot_id).robot
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    rng = np.random.default_rng(7)
    for trial in range(6):
        q = rng.uniform(-np.pi, np.pi, 6)
        singular = 0.0 if joint == "wrist" else stretched_elbow(plan, q)
        index = 4 if joint == "wrist" else 2
        for epsilon in (1e-3, 1e-6, 1e-9, 1e-12, 0.0):
            q[index] = singular + epsilon * (1 if trial % 2 else -1)
            T = forward_kinematics(robot, q)
            fast = solve_ik(robot, T)
            _array_path(monkeypatch, plan)
            slow = solve_ik(robot, T)
            monkeypatch.undo()
            assert fast.status == "ok"
            # near a singularity the coupled joints are determined to rounding over the distance from it
            assert_same_answers(robot, [fast], [slow], max(1e-9, 1e-15 / max(epsilon, 1e-15) * 1e2))
            joints = np.array([s.joints for s in fast.solutions])
            gap = np.abs(joint_difference(robot, joints, q))
            # a wrist at θ5 = 0 leaves only θ4 + θ6 (PUMA) or θ2 + θ3 + θ4 and θ6 together (UR5) determined
            coupled = ([3, 5] if robot_id.startswith("puma") else [1, 2, 3, 5]) if joint == "wrist" else []
            free = [i for i in range(6) if i not in coupled]
            assert gap[:, free].max(axis=1).min() <= 1e-6  # a fold's root is good to about √(rounding)


def random_scara_arms(seed: int, roll: bool) -> list[Robot]:
    """A random SCARA arm (:class:`ParallelShoulder`: joints 1 and 2 about parallel axes, a slide along them) with a
    roll about the same direction (RRPR) or without (RRP), stated three ways (standard, modified, Khalil DH) with
    a random base and tool and some axes reversed (:func:`stated_three_ways`)."""
    rng = np.random.default_rng(seed)
    rows = RandomDHRows(rng)

    def flat() -> float:
        return float(rng.choice([0.0, np.pi]))

    table = [(rows.length(), flat(), rows.length(), rows.offset()), (rows.length(), flat(), rows.length(),
                                                                      rows.offset())]
    table.append((rows.length(), flat(), rows.length(), rows.offset()) if roll else rows.free())
    if roll:
        table.append(rows.free())
    return stated_three_ways(rng, table, "RRPR" if roll else "RRP")


@pytest.mark.parametrize("roll", [True, False])
def test_random_scara_arms_answer_alike_on_both_paths(roll, monkeypatch):
    """SCARA arms in every convention, pose and position targets from their own FK, some moved out of reach: the
    scalar path answers most of them and finds the generating vector (a position target's roll held at 0); with
    it switched off the array path gives the same solutions, labels, residuals and promises (and the same words
    where a target is out of reach)."""
    answered = asked = 0
    for seed in range(3):
        for robot in random_scara_arms(seed, roll):
            for constrain_orientation in (True, False):
                plan = cached_plan(robot, constrain_orientation=constrain_orientation, reference=None)
                assert plan.structure == ("parallel_shoulder+roll" if roll and constrain_orientation else
                                          "parallel_shoulder")
                q = random_configurations(robot, 30, seed)
                if roll and not constrain_orientation:
                    q[:, 3] = 0.0  # the roll moves an offset tool: a position target holds it at 0
                poses = forward_kinematics(robot, q)
                axis = plan.positioner.geometry.direction(0)
                across = np.cross(axis, [1.0, 0.0, 0.0] if abs(axis[0]) < 0.9 else [0.0, 1.0, 0.0])
                poses[::6, :3, 3] += 5 * robot.characteristic_length * across / np.linalg.norm(across)  # far off axis 1
                fast, count = answers_on_both_paths(robot, plan, poses, [None] * len(poses), constrain_orientation,
                                                    monkeypatch)
                answered, asked = answered + count, asked + len(poses)
                for i, (generating, result) in enumerate(zip(q, fast)):
                    if i % 6 == 0:  # (a position the roll held at 0 misses is searched over every joint)
                        assert result.status == ("not_found" if roll and not constrain_orientation else
                                                 "unreachable")
                    else:
                        assert holds_the_generating_vector(robot, result, generating)
    assert answered >= 0.8 * asked  # all but the poses out of reach


@pytest.mark.parametrize("kinds", ["RPP", "PRP", "PPR"])
def test_random_cylindrical_arms_answer_alike_on_both_paths(kinds, monkeypatch):
    """Arms of one revolute joint and two slides (:class:`OneRevoluteTwoPrismatic`) with random twists, in every
    convention with a random base and tool, pose and position targets from their own FK, with and without the
    generating vector as reference: the scalar path answers most of them and finds the generating vector, and
    both paths give the same solutions, labels, residuals, promises and words."""
    answered = asked = 0
    for seed in range(3):
        rng = np.random.default_rng(seed)
        rows = RandomDHRows(rng)
        for robot in stated_three_ways(rng, [rows.free() for _ in kinds], kinds):
            for constrain_orientation in (True, False):
                plan = cached_plan(robot, constrain_orientation=constrain_orientation, reference=None)
                assert plan.structure == "one_revolute_two_prismatic"
                q = random_configurations(robot, 24, seed)
                poses = forward_kinematics(robot, q)
                references = [None if i % 2 else generating for i, generating in enumerate(q)]
                fast, count = answers_on_both_paths(robot, plan, poses, references, constrain_orientation, monkeypatch)
                answered, asked = answered + count, asked + len(poses)
                assert all(holds_the_generating_vector(robot, result, q_i) for q_i, result in zip(q, fast))
    assert answered >= 0.9 * asked


def test_random_polar_arms_with_an_offset_slide_answer_alike_on_both_paths(monkeypatch):
    """Arms whose first two axes meet and whose third joint slides along a line that misses axis 2 (random
    twists and offsets), in every convention with a random base and tool, pose and position targets from their
    own FK, some moved out of reach: the scalar path answers most and finds the generating vector, and both paths
    give the same solutions, labels, residuals, promises and words."""
    answered = asked = 0
    for seed in range(3):
        rng = np.random.default_rng(seed)
        rows = RandomDHRows(rng)
        table = [(0.0, rows.twist(), rows.length(), rows.offset()), rows.free(), rows.free()]  # axes 1 and 2 meet
        for robot in stated_three_ways(rng, table, "RRP"):
            for constrain_orientation in (True, False):
                plan = cached_plan(robot, constrain_orientation=constrain_orientation, reference=None)
                assert plan.structure == "intersecting_shoulder" and plan.positioner.slide_through_axis_2 is None
                q = random_configurations(robot, 24, seed)
                poses = forward_kinematics(robot, q)
                fast, count = answers_on_both_paths(robot, plan, poses, [None] * len(poses), constrain_orientation,
                                                    monkeypatch)
                answered, asked = answered + count, asked + len(poses)
                assert all(holds_the_generating_vector(robot, result, q_i) for q_i, result in zip(q, fast))
    assert answered >= 0.8 * asked


@pytest.mark.parametrize("robot_id, constrain_orientation, joint, singular, coupled", [
    ("spong_ex3_6_scara_rrpr", True, 1, 0.0, []),  # the elbow stretched: the two assembly modes meet
    ("spong_ex3_6_scara_rrpr", True, 1, np.pi, []),  # folded
    ("assur001_scara_rrp", True, 1, 0.0, []),
    ("spong_ex3_1_planar_rr", False, 1, 0.0, []),  # a position: the planar two-link arm's elbow stretched
    ("spong_ex3_2_cylindrical_rpp", True, 2, 0.0, [0]),  # the radial slide at 0: the point on the revolute axis
    ("ex004_1_prp", True, 2, 0.0, [1]),
])
def test_poses_approaching_the_scara_planar_and_cylindrical_singularities_answer_alike(
        robot_id, constrain_orientation, joint, singular, coupled, monkeypatch):
    """A joint at 1e-3 … 1e-12 and 0 from where two branches meet (the SCARA's and the planar arm's elbow
    stretched or folded) or where the point reaches the revolute axis (the cylindrical arms' radial slide at 0,
    the revolute joint free there): the scalar path answers the poses far enough from it, and whichever it
    leaves to the array path, the answers are the same sets with the same labels, and hold the generating vector
    (within √rounding at a fold; the free joint aside on the axis)."""
    robot = _CATALOGUE.get(robot_id).robot
    plan = cached_plan(robot, constrain_orientation=constrain_orientation, reference=None)
    answered = 0
    for trial in range(4):
        q = random_configurations(robot, 1, seed=trial)[0]
        for epsilon in (1e-3, 1e-6, 1e-9, 1e-12, 0.0):
            q[joint] = singular + epsilon * (1 if trial % 2 else -1)
            T = forward_kinematics(robot, q)
            answered += plan.solve_one(T) is not None
            fast = solve_ik(robot, T, constrain_orientation=constrain_orientation)
            _array_path(monkeypatch, plan)
            slow = solve_ik(robot, T, constrain_orientation=constrain_orientation)
            monkeypatch.undo()
            assert fast.status == "ok"
            assert_same_answers(robot, [fast], [slow], max(1e-9, 1e-15 / max(epsilon, 1e-15) * 1e2))
            gap = np.abs(joint_difference(robot, np.array([s.joints for s in fast.solutions]), q))
            determined = [i for i in range(robot.dof) if i not in coupled or epsilon >= 1e-6]
            assert gap[:, determined].max(axis=1).min() <= 1e-6
    assert 4 <= answered < 20  # (at 1e-3 at least; not at the singular value itself)


_ROUNDED_FAMILY_ARMS = ["spong_ex3_6_scara_rrpr", "assur001_scara_rrp", "spong_ex3_1_planar_rr", "ex004_2_polar_rrp",
                        "ex004_3_spherical_rrpr", "ex004_4_polar_offset_rrp", "spong_ex3_2_cylindrical_rpp",
                        "ex004_1_prp", "spong_ex3_3_spherical_wrist_rrr", "spong_ex3_4_cylindrical_with_wrist"]


@pytest.mark.parametrize("arm", [*_ROUNDED_FAMILY_ARMS, "random SCARA", "random SCARA without roll",
                                 "random cylindrical"])
def test_the_scalar_paths_families_rounded_as_cad_exports_keep_their_promises(arm):
    """The families this scalar path covers beyond the six-joint ones, written as a CAD export writes them
    (:func:`tests.arms.rounded`: angles to 4 decimals, parallel axes 1e-5 rad off, lengths to 0.1 mm, a rounded base
    and tool): on poses from the rounded arm's own FK no answer is unreachable, and every answer that promises
    all solutions (``complete``, no singular condition or free joint) holds the generating vector."""
    if arm in _ROUNDED_FAMILY_ARMS:
        exact = _CATALOGUE.get(arm).robot
    elif arm.startswith("random SCARA"):
        exact = random_scara_arms(4, roll=arm == "random SCARA")[0]
    else:
        rng = np.random.default_rng(4)
        rows = RandomDHRows(rng)
        exact = stated_three_ways(rng, [rows.free() for _ in "RPP"], "RPP")[1]
    promised = 0
    for seed in range(2):
        robot = rounded(exact, seed)
        q = random_configurations(robot, 30, seed)
        for generating, T in zip(q, forward_kinematics(robot, q)):
            result = solve_ik(robot, T)
            assert result.status != "unreachable", (seed, generating.tolist(), result.structure, result.detail)
            if result.complete and not result.singularities and not result.free_joints:
                promised += 1
                assert holds_the_generating_vector(robot, result, generating), (seed, generating.tolist())
    assert promised >= 30
