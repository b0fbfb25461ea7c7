"""Redundant arms: the self-motion family solved as locked 6-DOF problems (issue 14).

The arms are inline DH tables from published parameters (tests/data/redundant_and_deficient_arms.json). Poses come
from the arm's own FK at random joint vectors; the generating vector's free value is among the values asked for,
so the generating vector must come back. Every solution is checked here by an independent FK call.
"""

from __future__ import annotations


import numpy as np
import pytest

from service.kinematics import Budget, BudgetExhausted, InvalidInputError, Joint, Robot, forward_kinematics
from service.kinematics.ik import (FreeJoint, beyond_reach, distance_to_reference, free_joints_for,
                                   solve_free_joint_family, solve_ik)
from service.kinematics.ik._redundant import default_free_joints, family_for, sample_values
from tests.arms import SKEW_7R, published_arm
from tests.ik_helpers import angle_gap, find

def solutions_of(answer, row: int = 0) -> np.ndarray:
    table = answer.verified.table
    return table.joints[table.target == row]


def assert_fk_verified(robot, solutions: np.ndarray, target: np.ndarray) -> None:
    reached = forward_kinematics(robot, solutions)
    scale = robot.characteristic_length
    assert np.abs(reached[:, :3, 3] - target[:3, 3]).max() <= 1e-9 * scale
    assert np.abs(reached[:, :3, :3] - target[:3, :3]).max() <= 1e-8




def test_default_free_joint_is_an_end_joint_whose_locking_leaves_a_family():
    # iiwa and Panda with q7 locked: the shoulder (axes 1-3 through one point) is a spherical wrist at the base.
    # The Gen3's shoulder axes do not meet (d2 = -0.0118 m), so its q7 leaves no family; q1 leaves the
    # intersecting shoulder + spherical wrist.
    assert default_free_joints(published_arm("iiwa14")) == (6,)
    assert default_free_joints(published_arm("panda")) == (6,)
    assert default_free_joints(published_arm("gen3")) == (0,)
    assert family_for(published_arm("iiwa14"), (0,)).ends_only
    assert not family_for(published_arm("iiwa14"), (2,)).ends_only


@pytest.mark.parametrize("track_limits, free", [(None, (2,)), ((-1.5, 1.5), (0,))])
def test_a_track_without_limits_is_not_the_default_free_joint(track_limits, free):
    """A PUMA on a linear track: locking the track leaves the PUMA's family, but a slide without limits has no
    range to sample, and the default answer was a 4xx asking for its values. Another joint is freed instead."""
    h = np.pi / 2
    puma = [(0, h, 0), (0.4318, 0, 0), (0.0203, -h, 0.15005), (0, h, 0.4318), (0, -h, 0), (0, 0, 0)]
    track = Joint("track", "prismatic", 0.0, -h, 0.3, 0.0, *(track_limits or ()))
    robot = Robot([track] + [Joint(f"q{i + 1}", "revolute", a, alpha, d, 0.0) for i, (a, alpha, d) in enumerate(puma)],
                  name="PUMA on a track", convention="standard")
    assert default_free_joints(robot) == free
    q = np.array([0.7, 0.3, -0.5, 0.4, 1.0, -0.6, 0.2])
    target = forward_kinematics(robot, q)
    result = solve_ik(robot, target)
    assert result.status == "ok" and result.free_joints == list(free)
    for solution in result.solutions:
        assert np.allclose(forward_kinematics(robot, solution.joints), target, atol=1e-8)


def test_a_locked_class_that_is_degenerate_is_not_chosen():
    # iiwa with q4 locked: the shoulder-to-wrist distance is fixed, so generic poses are out of reach
    assert not family_for(published_arm("iiwa14"), (3,)).available


@pytest.mark.parametrize("name, joint", [("iiwa14", 2), ("iiwa14", 0), ("gen3", 2), ("gen3", 0),
                                         ("panda", 6)])
def test_generating_vector_comes_back_and_every_solution_is_verified(name, joint):
    robot = published_arm(name)
    rng = np.random.default_rng(14)
    grid = sample_values(robot, joint, 16)
    recovered = 0
    for trial in range(25):
        q = rng.uniform(-np.pi, np.pi, robot.dof)
        q = np.clip(q, robot.lower, robot.upper)
        q[joint] = grid[rng.integers(len(grid))]
        target = forward_kinematics(robot, q)
        answer = solve_free_joint_family(robot, target[None], [FreeJoint(joint, grid)], None)
        solutions = solutions_of(answer)
        assert_fk_verified(robot, solutions, target)
        gap = angle_gap(solutions[:, joint, None], grid[None, :]).min(axis=1)
        assert gap.max() <= 1e-9  # every solution sits at one of the values asked for (mod 2π)
        recovered += find(robot, solutions, q) is not None
    assert recovered == 25


def test_each_value_is_solved_completely():
    """At one free value the answer equals the locked 6-DOF family's complete set (8 for this SRS pose)."""
    robot = published_arm("iiwa14")
    q = np.array([0.4, 0.7, -0.3, 1.2, 0.5, -0.8, 0.2])
    target = forward_kinematics(robot, q)
    answer = solve_free_joint_family(robot, target[None], [FreeJoint(2, np.array([-0.3]))], None)
    solutions = solutions_of(answer)
    assert len(solutions) == 8
    assert_fk_verified(robot, solutions, target)
    assert len({tuple(np.round(s, 6)) for s in solutions}) == 8


@pytest.mark.parametrize("name, joint", [("iiwa14", 0), ("iiwa14", 2), ("gen3", 0),
                                         ("panda", 6)])
def test_nearest_to_reference_is_at_least_as_near_as_a_dense_grid(name, joint):
    robot = published_arm(name)
    rng = np.random.default_rng(3)
    dense = sample_values(robot, joint, 1440)
    for trial in range(6):
        q = np.clip(rng.uniform(-2.5, 2.5, robot.dof), robot.lower, robot.upper)
        target = forward_kinematics(robot, q)
        reference = q + rng.uniform(-0.4, 0.4, robot.dof)
        reference[joint] = q[joint] + 0.3
        free = [FreeJoint(joint, sample_values(robot, joint, 32))]
        answer = solve_free_joint_family(robot, target[None], free, reference)
        best = solutions_of(answer)[0]
        assert_fk_verified(robot, solutions_of(answer), target)
        grid = np.concatenate([solutions_of(solve_free_joint_family(robot, target[None], [FreeJoint(joint, part)],
                                                                    None))
                               for part in np.array_split(dense, 6)])  # ≤ 256 values per request
        for norm in ("linf",):
            ours = distance_to_reference(robot, best[None], reference, norm=norm)[0]
            theirs = distance_to_reference(robot, grid, reference, norm=norm).min()
            assert ours <= theirs + 1e-9, (trial, ours, theirs)
        # and the search went between the samples: the answer is nearer than the 32-sample grid alone
        coarse = solutions_of(solve_free_joint_family(robot, target[None], free, None))
        assert distance_to_reference(robot, best[None], reference)[0] <= \
            distance_to_reference(robot, coarse, reference).min() + 1e-12


def test_free_joints_for_checks_the_request():
    robot = published_arm("iiwa14")
    with pytest.raises(ValueError, match="1 free joint"):
        free_joints_for(robot, [(1, [0.0], None), (2, [0.0], None)])
    with pytest.raises(ValueError, match="0…6"):
        free_joints_for(robot, [(9, [0.0], None)])
    default = free_joints_for(robot, None)
    assert [f.joint for f in default] == [6] and len(default[0].values) == 32
    # the iiwa's q7 spans ±175°: 32 samples over the limits, ends included
    assert np.isclose(default[0].values[0], np.radians(-175)) and np.isclose(default[0].values[-1], np.radians(175))


def test_reach_sphere_is_a_proof():
    robot = published_arm("iiwa14")
    rng = np.random.default_rng(0)
    reachable = forward_kinematics(robot, rng.uniform(-np.pi, np.pi, (2000, 7)))[:, :3, 3]
    assert not beyond_reach(robot, reachable).any()
    assert beyond_reach(robot, np.array([1.5, 0.0, 0.36]))  # the arm reaches 0.36 + 0.42 + 0.40 + 0.126 m


def test_trajectory_of_a_redundant_arm_keeps_the_free_joint_continuous():
    from service.kinematics import TrajectoryOptions, follow_trajectory

    robot = published_arm("iiwa14")
    t = np.linspace(0.0, 1.0, 41)
    start, end = np.array([0.2, 0.6, -0.4, 1.3, 0.3, -0.7, 0.1]), np.array([0.9, 0.2, 0.5, 0.7, -0.4, 0.5, 1.2])
    path = start + (end - start) * t[:, None] ** 2 * (3 - 2 * t[:, None])
    targets = forward_kinematics(robot, path)
    result = follow_trajectory(robot, t, targets, options=TrajectoryOptions(reference=start))
    joints = np.array([s.joints for s in result.samples])
    assert all(s.reached for s in result.samples)
    assert_fk_verified_each(robot, joints, targets)
    assert np.allclose(joints[0], start, atol=1e-9)  # the reference is itself a solution: nearest first
    steps = np.abs(np.diff(joints, axis=0)).max(axis=1)
    # no jump between branches (a flip moves a wrist joint by ~π) or along the self-motion: the largest step, where
    # this path passes near the wrist singularity q6 = 0, stays a few times the generating path's 0.045 rad
    assert steps.max() < 0.25
    free_steps = np.abs(np.diff(joints[:, 0]))
    assert free_steps.max() < 0.25 and np.ptp(joints[:, 0]) > 0.5  # q1 moves continuously, as the path needs
    # the answer is the greedy nearest one: each step no larger than to the generating path's next sample
    for k in range(1, len(t)):
        to_generating = angle_gap(path[k], joints[k - 1]).max()
        assert steps[k - 1] <= to_generating + 1e-9


def assert_fk_verified_each(robot, joints: np.ndarray, targets: np.ndarray) -> None:
    for q, target in zip(joints, targets):
        assert_fk_verified(robot, q[None], target)


def test_values_whose_locked_arm_has_no_plan_are_counted(monkeypatch):
    from service.kinematics.ik._redundant import FreeJointFamily

    robot = published_arm("iiwa14")
    original = FreeJointFamily.locked_plan
    monkeypatch.setattr(FreeJointFamily, "locked_plan",
                        lambda self, values: None if values[0] > 1.0 else original(self, values))
    q = np.array([0.4, 0.7, -0.3, 1.2, 0.5, -0.8, 0.2])
    values = np.array([-0.3, 0.5, 1.5, 2.0])
    answer = solve_free_joint_family(robot, forward_kinematics(robot, q)[None], [FreeJoint(2, values)], None)
    assert answer.missing.tolist() == [2]
    assert find(robot, solutions_of(answer), q) is not None


def test_free_joint_errors_are_located_in_the_request_and_worded_in_the_core_terms():
    """Locations are relative to the entries given (the boundary prefixes the request's path); the words name
    free joints, not a wire field."""
    from service.config import Settings
    from service.kinematics.ik import AnswerOptions, IKTargets, NotRedundantError, answer_ik
    from service.robots.catalogue import load_catalogue

    robot = published_arm("iiwa14")
    with pytest.raises(InvalidInputError) as caught:
        free_joints_for(robot, [(9, [0.0], None)])
    assert caught.value.location == (0, "joint")
    with pytest.raises(InvalidInputError) as caught:
        free_joints_for(robot, [(2, [0.0, np.nan], None)])
    assert caught.value.location == (0, "values")
    with pytest.raises(NotRedundantError) as caught:
        ur5 = load_catalogue([Settings().builtin_robots_dir], max_joints=32).get("ur5").robot
        free_joints_for(ur5, [(2, [0.0], None)])
    assert caught.value.location == () and caught.value.dof == 6 and "free_joints" not in caught.value.message
    target = IKTargets.poses(forward_kinematics(robot, np.zeros((1, 7))))
    with pytest.raises(InvalidInputError) as caught:  # answer_ik puts them at its option
        answer_ik(robot, target, AnswerOptions(free_joints=[(9, [0.0], None)]))
    assert caught.value.location == ("free_joints", 0, "joint")


@pytest.mark.parametrize("robot_id, q", [
    ("kinova_gen3", [2.646482, 1.330195, 0.504285, 0.001, 1.997572, -1.487952, 0.836111]),
    ("kuka_iiwa14", [0.605373, -0.781728, 1.685082, 0.001, 0.558733, 0.550195, -2.776092]),
    ("kuka_iiwa14", [-0.406115, -1.118501, 0.767787, 0.024351, 0.436138, -1.823231, 1.213270]),
])
def test_an_empty_family_near_a_stretched_elbow_is_not_said_unreachable(robot_id, q):
    """A redundant arm's family is solved completely at each sampled value of its free joint, which proves
    nothing for the values between: a pose from the arm's own FK that no sampled value reaches (an elbow a
    thousandth of a radian from straight, where each locked arm's two elbow roots nearly meet) is `not_found`,
    not `unreachable` (a hostile probe found it said unreachable, with complete true). A pose beyond the reach
    sphere stays a proof."""
    from service.config import Settings
    from service.kinematics.ik import AnswerOptions, IKTargets, answer_ik
    from service.robots.catalogue import load_catalogue

    robot = load_catalogue([Settings().builtin_robots_dir], max_joints=32).get(robot_id).robot
    q = np.array(q)
    target = forward_kinematics(robot, q)
    far = target.copy()
    far[:3, 3] *= 100.0
    for reference in (None, q):
        answer = answer_ik(robot, IKTargets.poses(np.stack([target, far])), AnswerOptions(reference=reference))
        assert answer.status[0] != "unreachable", answer.detail_list()[0]
        if answer.status[0] == "ok":
            assert_fk_verified(robot, answer.solutions.joints[answer.solutions.target == 0], target)
        assert answer.status[1] == "unreachable" and "outside the workspace" in answer.detail_list()[1]


@pytest.mark.parametrize("robot_id, q", [
    ("kuka_iiwa14", [-1.403817, 1.960958, 2.9, 0.1, 1.639384, -2.0, 1.556454]),
    ("kuka_iiwa14", [0.605373, -0.781728, 1.685082, 0.001, 0.558733, 0.550195, -2.776092]),
    ("kinova_gen3", [2.646482, 1.330195, 0.504285, 0.001, 1.997572, -1.487952, 0.836111]),
])
def test_a_reference_that_solves_the_pose_comes_first_even_between_grid_values(robot_id, q):
    """With a reference the family is searched near it (the nearest first over the whole family). Near a
    stretched elbow a branch reaches the pose only between two grid values of the free joint, so neither the
    grid nor the refinement of its minima has a sample on it: the reference's own free value is solved then,
    and a reference that is itself a solution comes first (a probe found it 3.09 rad away, or not at all)."""
    from service.config import Settings
    from service.kinematics.ik import AnswerOptions, IKTargets, answer_ik
    from service.robots.catalogue import load_catalogue

    robot = load_catalogue([Settings().builtin_robots_dir], max_joints=32).get(robot_id).robot
    q = np.array(q)
    answer = answer_ik(robot, IKTargets.poses(forward_kinematics(robot, q)[None]),
                       AnswerOptions(reference=q, filter_limits=False))
    assert answer.status[0] == "ok"
    assert distance_to_reference(robot, answer.solutions.joints[0], q) <= 1e-6


def test_a_free_joint_grid_checks_the_budget_at_every_locked_arm():
    """A skew 7R locked at each of 16 free values is 16 arms, each solved (and its plan built, the first time) on
    its own: the request's budget is checked before each, so a grid of many samples stops at its deadline rather
    than seconds later (256 samples ran 5.4 s past the first check under a 3 s deadline before)."""
    robot = Robot([Joint(f"q{i + 1}", joint["type"], joint["a"], joint["alpha"], joint["d"], 0.0)
                   for i, joint in enumerate(SKEW_7R["joints"])], name="skew 7R")  # the live test's slow arm
    target = forward_kinematics(robot, np.array([[0.3, -0.4, 0.5, 0.2, -0.6, 0.7, 0.1]]))
    checks = []
    budget = Budget(between_chunks=lambda: checks.append(1))
    solve_free_joint_family(robot, target, [FreeJoint(3, np.linspace(-3.0, 3.0, 16))], None, budget=budget)
    assert len(checks) >= 16
    stopped_at = []

    def cancel_after_three() -> None:
        stopped_at.append(1)
        if len(stopped_at) == 3:
            cancelling.cancel()

    cancelling = Budget(between_chunks=cancel_after_three)
    with pytest.raises(BudgetExhausted):
        solve_free_joint_family(robot, target, [FreeJoint(3, np.linspace(-3.0, 3.0, 16))], None, budget=cancelling)
    assert len(stopped_at) == 3
