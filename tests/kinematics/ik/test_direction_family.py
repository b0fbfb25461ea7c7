"""The roll family of direction targets on arms of 6 or more joints (issue 22 item 10), in the core.

* the roll read off a rotation (:func:`rolls_of`) is the one :func:`roll_poses` built it with;
* ``complete`` means every solution at each sampled roll: the family's solutions at a roll are exactly the
  closed form's solutions of the full pose at that roll;
* the cost model counts rolls × solutions (and the refined rolls with a reference) before solving, and refuses
  more pose solves per target than the cap.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from service.kinematics import InvalidInputError, forward_kinematics
from service.kinematics.ik import (DEFAULT_ROLL_SAMPLES, DIRECTION, MAX_ROLL_ROWS, AnswerOptions, IKTargets, estimate,
                                   roll_samples, solve_ik)
from service.kinematics.ik._direction import roll_family, roll_poses, rolls_of, solve_roll_family
from service.kinematics.ik._goals import DirectionGoal
from service.robots.catalogue import load_catalogue
from tests.arms import random_family_arm, random_general_arm
from tests.ik_helpers import angle_gap, same_set

ROBOTS = Path(__file__).parents[3] / "robots"


@pytest.fixture(scope="module")
def catalogue():
    return load_catalogue([ROBOTS], max_joints=32)


def test_the_roll_read_off_a_rotation_is_the_one_it_was_built_with():
    rng = np.random.default_rng(0)
    for _ in range(50):
        a = rng.normal(size=3)
        a /= np.linalg.norm(a)
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        for direction in (d, -a, a):  # any, opposite to the axis, along it
            rolls = rng.uniform(-np.pi, np.pi, 5)
            poses = roll_poses(a, np.zeros(3), direction, rolls)
            assert np.allclose(poses[:, :3, :3] @ a, direction, atol=1e-12)
            assert np.allclose(rolls_of(a, direction, poses[:, :3, :3]), rolls, atol=1e-12)


def _direction_target(T: np.ndarray, axis: np.ndarray) -> DirectionGoal:
    return DirectionGoal(T[None, :3, 3], (T[:3, :3] @ axis)[None], axis)


@pytest.mark.parametrize("robot_id", ["puma560_standard", "ur5", "kuka_kr6_r900_2"])
def test_complete_means_every_solution_at_each_sampled_roll(catalogue, robot_id):
    robot = catalogue.get(robot_id).robot
    axis = np.array([0.0, 0.6, 0.8])  # not along the last joint: the roll moves the wrist
    T = forward_kinematics(robot, np.array([[0.4, -0.7, 0.5, 0.9, -0.8, 0.3]]))[0]
    goal = _direction_target(T, axis)
    rolls = roll_samples(12)
    answer = solve_roll_family(robot, roll_family(robot, None), goal, rolls, None)
    assert answer.verified.complete.all()
    table = answer.verified.table
    for roll, pose in zip(rolls, roll_poses(axis, goal.positions[0], goal.directions[0], rolls)):
        at_roll = table.joints[angle_gap(table.roll, roll) < 1e-9]
        closed = solve_ik(robot, pose)
        assert closed.complete
        assert same_set(robot, at_roll, np.array([s.joints for s in closed.solutions]).reshape(-1, robot.dof))


def test_the_cost_model_counts_rolls_times_solutions(catalogue):
    robot = catalogue.get("puma560_standard").robot
    T = forward_kinematics(robot, np.array([[0.4, -0.7, 0.5, 0.9, -0.8, 0.3]]))[0]
    M = np.eye(4)
    M[:3, 3] = T[:3, 3]

    def targets(rolls=None):
        return IKTargets(M[None], np.array([DIRECTION]), np.array([[0.0, 0.0, 1.0]]), T[None, :3, 2], [rolls])

    family = roll_family(robot, None)
    plain = estimate(robot, targets(), AnswerOptions())
    assert plain.solutions_per_target == DEFAULT_ROLL_SAMPLES * family.generic_count
    assert plain.free_values == DEFAULT_ROLL_SAMPLES
    reference = np.array([0.4, -0.7, 0.5, 0.9, -0.8, 0.3])
    nearest = estimate(robot, targets(), AnswerOptions(reference=reference))
    solved = solve_roll_family(robot, family, _direction_target(T, np.array([0.0, 0.0, 1.0])),
                               roll_samples(DEFAULT_ROLL_SAMPLES), reference)
    assert solved.verified.count[0] <= nearest.solutions_per_target
    assert estimate(robot, targets(roll_samples(MAX_ROLL_ROWS)), AnswerOptions()).free_values == MAX_ROLL_ROWS
    with pytest.raises(InvalidInputError, match="pose solves per direction target"):
        estimate(robot, targets(roll_samples(MAX_ROLL_ROWS + 1)), AnswerOptions())


def _random_arms():
    """Random arms of each 6R family, with random base and tool (so the tool axis is not the last joint's)."""
    for seed in range(3):
        yield f"spherical_wrist-{seed}", random_family_arm("intersecting_shoulder+spherical_wrist", "standard", seed)
        yield f"three_parallel-{seed}", random_family_arm("three_parallel", "modified", seed)
        yield f"general_6r-{seed}", random_general_arm(np.random.default_rng(seed), "standard")


@pytest.mark.parametrize("name, robot", list(_random_arms()), ids=lambda value: value if isinstance(value, str)
                         else "")
def test_promise_audit_of_direction_targets_on_random_arms(name, robot):
    """FK-made targets: never unreachable at the default rolls; with the generating roll among the rolls
    solved, the generating configuration among the solutions (complete or not), each within 1e-9."""
    from service.kinematics.ik import answer_ik, unlimited

    rng = np.random.default_rng(101)
    axis = np.array([0.0, 0.0, 1.0])
    q = rng.uniform(-np.pi, np.pi, (4, 6))
    T = forward_kinematics(robot, q)
    M = np.tile(np.eye(4), (len(q), 1, 1))
    M[:, :3, 3] = T[:, :3, 3]
    directions = T[:, :3, :3] @ axis
    own = [np.array([rolls_of(axis, d, R[None])[0], 0.3]) for d, R in zip(directions, T[:, :3, :3])]
    options = AnswerOptions(limits=unlimited(robot), filter_limits=False)
    kinds, axes = np.full(len(q), DIRECTION), np.tile(axis, (len(q), 1))
    at_default = answer_ik(robot, IKTargets(M, kinds, axes, directions), options)
    assert (at_default.status != "unreachable").all(), list(at_default.detail)
    at_own = answer_ik(robot, IKTargets(M, kinds, axes, directions, own), options)
    start, stop = at_own.solutions.bounds(len(q))
    for row in range(len(q)):
        joints = at_own.solutions.joints[start[row]:stop[row]]
        assert len(joints) and angle_gap(joints, q[row]).max(axis=1).min() < 1e-6, name
        reached = forward_kinematics(robot, joints)
        assert np.abs(reached[:, :3, 3] - T[row, :3, 3]).max() <= 1e-9 * max(1.0, robot.characteristic_length)
        assert np.abs(reached[:, :3, :3] @ axis - directions[row]).max() <= 1e-9
