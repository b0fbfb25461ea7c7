"""Position + tool direction targets of 5-joint arms (issue 14): recall over poses from the arm's own FK.

The arms are inline DH tables of the desktop class (tests/data/redundant_and_deficient_arms.json). For each random
joint vector the target is the tool position and the direction of a tool axis; the generating vector must be among
the solutions (with the roll joint at 0 when the axis is the gripper's roll axis, which the target leaves free),
and every solution is checked here by FK.
"""

from __future__ import annotations

import numpy as np
import pytest

from service.kinematics import Joint, Robot, forward_kinematics
from service.kinematics.ik import (DIRECTION, AnswerOptions, IKTargets, answer_ik, solve_direction, target_kinds,
                                   unlimited)
from service.kinematics.ik._direction import rotations_to
from tests.ik_helpers import find
from tests.arms import published_arm

AXES = {"roll axis z": [0.0, 0.0, 1.0], "jaw axis y": [0.0, 1.0, 0.0], "side axis x": [1.0, 0.0, 0.0],
        "oblique": [0.3, -0.5, 0.8]}


@pytest.mark.parametrize("name", ["widowx250_like", "so101_like"])
@pytest.mark.parametrize("axis_name", list(AXES))
def test_recall_of_direction_targets_is_complete(name, axis_name):
    robot = published_arm(name)
    axis = np.array(AXES[axis_name]) / np.linalg.norm(AXES[axis_name])
    rng = np.random.default_rng(51)
    q = rng.uniform(-np.pi, np.pi, (150, 5))
    T = forward_kinematics(robot, q)
    positions, directions = T[:, :3, 3], T[:, :3, :3] @ axis
    answer = solve_direction(robot, positions, directions, axis, None)
    assert answer is not None
    roll_free = answer.free_joints == [4]
    assert roll_free == (axis_name == "roll axis z")
    recalled = 0
    for row in range(len(q)):
        solutions = answer.joints[row, :answer.count[row]]
        expected = q[row].copy()
        if roll_free:
            expected[4] = 0.0
            assert np.all(solutions[:, 4] == 0.0)
        recalled += find(robot, solutions, expected) is not None
        reached = forward_kinematics(robot, solutions)
        assert np.abs(reached[:, :3, 3] - positions[row]).max() <= 1e-9 * robot.characteristic_length
        assert np.abs(reached[:, :3, :3] @ axis - directions[row]).max() <= 1e-8
    assert recalled == len(q)


def test_an_unreachable_direction_gives_no_solution():
    robot = published_arm("widowx250_like")
    T = forward_kinematics(robot, np.array([0.3, 0.2, -0.4, 0.5, 0.6]))
    # the gripper axis of this arm stays in the vertical plane through the base axis: a sideways one is out
    sideways = np.cross([0.0, 0.0, 1.0], T[:3, 3])
    answer = solve_direction(robot, T[None, :3, 3], sideways[None], np.array([0.0, 0.0, 1.0]), None)
    assert answer.count[0] == 0


def test_rotations_to_take_the_axis_onto_the_direction_also_when_opposite():
    a = np.array([0.0, 0.0, 1.0])
    d = np.array([[0.0, 0.0, -1.0], [0.0, 0.0, 1.0], [1.0, 2.0, -0.5]])
    R = rotations_to(a, d)
    assert np.allclose(R @ a, d / np.linalg.norm(d, axis=1, keepdims=True))
    assert np.allclose(R @ np.swapaxes(R, 1, 2), np.eye(3)) and np.allclose(np.linalg.det(R), 1.0)


def test_target_kinds_name_the_direction_kind_for_arms_of_five_joints_or_more():
    assert target_kinds(published_arm("so101_like")) == ["pose", "position", "position_direction"]
    assert target_kinds(published_arm("iiwa14")) == ["pose", "position", "position_direction"]


def _assert_own_direction_target_is_never_unreachable(robot: Robot, q: np.ndarray) -> None:
    """The position and tool z axis of FK(q) as a direction target: never `unreachable`, and found unless the
    answer says it is not complete."""
    T = forward_kinematics(robot, q)
    matrices = np.eye(4)[None].copy()
    matrices[0, :3, 3] = T[:3, 3]
    targets = IKTargets(matrices, np.array([DIRECTION]), np.array([[0, 0, 1.0]]), T[None, :3, 2].copy())
    answer = answer_ik(robot, targets, AnswerOptions(limits=unlimited(robot), filter_limits=False))
    report = answer.solvers[answer.solver[0]]
    assert answer.status[0] != "unreachable", answer.detail_list()[0]
    assert answer.status[0] == "ok" or not report.complete  # found, or not promised


def test_an_incomplete_closed_form_does_not_promise_unreachable():
    """A random R-P-R-R-R arm whose last joint rolls about the tool axis: its direction targets go to the general
    5R1P solver with a virtual joint, which cannot promise every solution for this one. The answer once dropped
    that flag and said `unreachable, complete` of a pose from the arm's own FK."""
    h = np.pi / 2
    rows = [("revolute", 0.0, -h, 0.0, 0.0), ("prismatic", 0.0, h, 0.2, 0.0), ("revolute", 0.0, -h, 0.0, h),
            ("revolute", 0.6059950341551361, h, 0.0, h),
            ("revolute", 0.5248144502421734, np.pi, 0.2, -0.710926735853691)]
    robot = Robot([Joint(f"q{i}", *row) for i, row in enumerate(rows)], name="probe", convention="modified")
    _assert_own_direction_target_is_never_unreachable(
        robot, np.array([-0.729844197, -0.15513631, 0.228209683, -1.552625249, -0.553408862]))


def test_a_gimbal_whose_axes_all_meet_is_not_promised_unreachable():
    """Five revolute axes through one point, the tool there too (a gimbal): the virtual roll's 6-joint arm places
    its point at the shoulder's centre, where subproblems 2 and 3 judged 1e-16 of rounding against itself and
    gave no candidate, and the answer said `unreachable, complete` of the arm's own FK pose."""
    h = np.pi / 2
    rows = [(0.0, 2.9552007457290577, -0.6229685060125036), (0.0, -2.1102717999823857, 0.0), (0.0, -h, 0.0),
            (0.0, h, 0.0), (0.0, 3.0087290532683735, 0.0)]
    robot = Robot([Joint(f"q{i}", "revolute", a, alpha, d, 0.0) for i, (a, alpha, d) in enumerate(rows)],
                  name="gimbal", convention="standard")
    _assert_own_direction_target_is_never_unreachable(
        robot, np.array([-1.380173228, -2.680064972, -0.598100873, 1.450488122, -0.587071736]))
