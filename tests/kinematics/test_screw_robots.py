"""Robots built from joint screws (Robot.from_screws) against the same arms as DH tables, in the core."""

from __future__ import annotations

import numpy as np
import pytest

from service.kinematics import (
    InvalidInputError,
    Joint,
    Robot,
    ScrewJoint,
    forward_kinematics,
    geometric_jacobian,
    joint_screws,
    link_frames,
    screw_model,
)
from tests.arms import screw_exponential


def _random_dh_arm(rng, convention: str) -> Robot:
    joints = [Joint(f"q{i + 1}", "prismatic" if rng.random() < 0.25 else "revolute",
                    *rng.uniform(-0.5, 0.5, 1), *rng.uniform(-np.pi, np.pi, 1), *rng.uniform(-0.5, 0.5, 1),
                    *rng.uniform(-np.pi, np.pi, 1)) for i in range(int(rng.integers(1, 8)))]
    T = np.eye(4)
    T[:3, 3] = rng.uniform(-1, 1, 3)
    tool = np.eye(4)
    tool[:3, :3] = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    tool[:3, 3] = rng.uniform(-0.2, 0.2, 3)
    return Robot(joints, convention=convention, world_T_base=T, flange_T_tool=tool)


def _as_screws(robot: Robot) -> Robot:
    bare = robot.with_frames(np.eye(4), np.eye(4))
    model = screw_model(bare)
    joints = [ScrewJoint(name, "revolute" if revolute else "prismatic", tuple(d), tuple(p), lo, hi)
              for name, revolute, d, p, lo, hi in zip(robot.joint_names, model.is_revolute, model.directions,
                                                      model.points, robot.lower, robot.upper)]
    return Robot.from_screws(joints, model.home, world_T_base=robot.world_T_base, flange_T_tool=robot.flange_T_tool)


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_screw_robots_reproduce_random_dh_arms(convention):
    rng = np.random.default_rng(5)
    for _ in range(40):
        dh = _random_dh_arm(rng, convention)
        screws = _as_screws(dh)
        q = rng.uniform(-3, 3, (20, dh.dof))
        np.testing.assert_allclose(forward_kinematics(screws, q), forward_kinematics(dh, q), atol=1e-13)
        for row in q[:3]:  # the scalar single-pose path
            np.testing.assert_allclose(forward_kinematics(screws, row), forward_kinematics(dh, row), atol=1e-13)
        np.testing.assert_allclose(geometric_jacobian(screws, q), geometric_jacobian(dh, q), atol=1e-12)
        a, b = joint_screws(screws, q), joint_screws(dh, q)
        np.testing.assert_allclose(a.directions, b.directions, atol=1e-13)
        # points differ along the axis only: the offset is parallel to the direction
        offset = a.points - b.points
        np.testing.assert_allclose(np.cross(offset, b.directions), 0.0, atol=1e-12)
        assert link_frames(screws, q).shape == link_frames(dh, q).shape
        np.testing.assert_allclose(link_frames(screws, q)[..., -1, :, :], link_frames(dh, q)[..., -1, :, :],
                                   atol=1e-13)


def test_with_frames_replaces_base_and_tool_only():
    rng = np.random.default_rng(2)
    dh = _random_dh_arm(rng, "standard")
    tool = np.eye(4)
    tool[:3, 3] = [0.0, 0.1, 0.2]
    q = rng.uniform(-1, 1, dh.dof)
    for robot in (dh, _as_screws(dh)):
        framed = robot.with_frames(flange_T_tool=tool)
        flange = forward_kinematics(robot.with_frames(flange_T_tool=np.eye(4)), q)
        np.testing.assert_allclose(forward_kinematics(framed, q), flange @ tool, atol=1e-14)
        assert not np.allclose(forward_kinematics(framed, q), forward_kinematics(robot, q))  # replaced, not added
        assert np.array_equal(framed.world_T_base, robot.world_T_base) and framed.joints == robot.joints
    with pytest.raises(InvalidInputError) as error:
        dh.with_frames(flange_T_tool=np.diag([1.0, 1.0, -1.0, 1.0]))
    assert error.value.location[:1] == ("tool",)


@pytest.mark.parametrize(("axis", "point", "match", "where"), [
    ((0, 0, 0), (0, 0, 0), "zero vector", "axis"),
    ((0, 0, 2), (0, 0, 0), "unit vector", "axis"),
    ((0, 0, np.nan), (0, 0, 0), "finite", "axis"),
    ((0, 0, 1), (0, np.inf, 0), "finite", "point"),
])
def test_bad_screws_are_refused_with_their_location(axis, point, match, where):
    joints = [ScrewJoint("q1", "revolute", (0, 0, 1), (0, 0, 0)), ScrewJoint("q2", "revolute", axis, point)]
    with pytest.raises(InvalidInputError, match=match) as error:
        Robot.from_screws(joints, np.eye(4))
    assert error.value.location == ("joints", 1, where)
    with pytest.raises(InvalidInputError) as error:
        Robot.from_screws(joints[:1], np.diag([1.0, 2.0, 1.0, 1.0]))
    assert error.value.location[:1] == ("home",)


def test_every_link_frame_of_a_screw_robot_moves_by_the_exponentials_before_it():
    """Link frame i of a screws robot at q is world_T_base · exp([S_1] q_1) ⋯ exp([S_i] q_i) · (frame i at q = 0)
    (the product of exponentials written out here, Rodrigues' formula), and at q = 0 frame i carries the axis of
    joint i + 1 as its z axis through its point; the last frame is the flange."""
    rng = np.random.default_rng(11)
    for _ in range(10):
        screws = _as_screws(_random_dh_arm(rng, "standard"))
        model = screw_model(screws.with_frames(np.eye(4), np.eye(4)))
        at_zero = link_frames(screws.with_frames(np.eye(4), np.eye(4)), np.zeros(screws.dof))
        for i in range(screws.dof - 1):
            np.testing.assert_allclose(at_zero[i + 1][:3, 2], model.directions[i + 1], atol=1e-13)
            np.testing.assert_allclose(np.cross(at_zero[i + 1][:3, 3] - model.points[i + 1], model.directions[i + 1]),
                                       0.0, atol=1e-13)
        np.testing.assert_allclose(at_zero[-1], model.home, atol=1e-13)
        q = rng.uniform(-3, 3, (4, screws.dof))
        frames = link_frames(screws, q)
        for row, values in enumerate(q):
            moved = screws.world_T_base.copy()
            np.testing.assert_allclose(frames[row][0], moved, atol=1e-15)
            for i in range(screws.dof):
                moved = moved @ screw_exponential(model.directions[i], model.points[i], model.is_revolute[i], values[i])
                np.testing.assert_allclose(frames[row][i + 1], moved @ at_zero[i + 1], atol=1e-12)

