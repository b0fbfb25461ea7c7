"""The one Gauss–Newton loop: its Newton mode never leaves a row worse than it found it."""

from __future__ import annotations

import numpy as np

from service.kinematics import Joint, Robot, forward_kinematics
from service.kinematics.ik._gauss_newton import gauss_newton
from service.kinematics.ik._goals import PoseGoal


def test_newton_steps_along_a_near_singular_direction_never_raise_a_rows_error():
    """The Stanford arm with its DH parameters moved by ~1e-11, its shoulder 1e-9 from the boundary and its wrist
    1e-6 from aligned: the closed form's two candidates (the wrist held free) miss by 8e-7, and three Newton
    steps (μ = 1e-12 against a smallest singular value ~1e-6) threw them 1e-3 off. Each step that would raise a
    row's error is not taken: both rows end where they were, or nearer."""
    rows = [
        ('revolute', 9.446865829548147e-13, -1.5707963268073808, 2.966803890430878e-11, 4.663183956211561e-12),
        ('revolute', -1.7195465855225482e-11, 1.5707963268050356, 0.15400000000712433, 3.9682575357203044e-12),
        ('prismatic', 2.6275205808531668e-12, -4.709456252281336e-12, -1.0998918111116394e-12, -1.946672803641399e-11),
        ('revolute', 1.387857854546278e-11, -1.5707963267739915, 5.801870215506985e-12, 6.9466457536328505e-12),
        ('revolute', -1.2913711684230084e-11, 1.5707963267913707, -1.3465156438916998e-11, -1.2385643305969746e-11),
        ('revolute', 6.135305658124752e-12, 1.4941329345542943e-11, 0.2630000000000492, 2.5590224113796677e-11)]
    robot = Robot([Joint(f"q{i}", *row) for i, row in enumerate(rows)], name="moved stanford",
                  convention="standard")
    q = np.array([1.5707963267958966, 3.141592654589793, 0.25360229428036896, -0.8791115140702122, 1e-06,
                  -1.5707963267948966])
    candidates = np.array([[1.570796328293, 3.141592653586, 0.2536022942819, 0.0, 6.388307536624e-07, -2.449907839368],
                           [1.570796328293, -3.96838e-12, -0.2536022942882, 0.0, -3.141592014759, -2.449907839393]])
    goal = PoseGoal(forward_kinematics(robot, q)[None])
    rows_of = np.zeros(2, dtype=int)
    start = np.abs(goal.error(robot, candidates, rows_of)).max(axis=1)
    reached = gauss_newton(robot, goal, candidates, rows_of, steps=3, tolerance=1e-12)
    assert (start > 1e-7).all() and (start < 1e-5).all(), start  # the narrow misses of the probe
    assert (reached.error <= start).all(), (start, reached.error)
    assert np.allclose(forward_kinematics(robot, reached.joints), goal.world_T_targets[0], atol=1e-5)


def test_the_search_runs_from_each_targets_seeds_with_or_without_common_starts():
    """search() takes each target's own seeds after the common starts, and from the seeds alone when a library
    caller asks for no common start (starts=0): each target reaches the configuration its seed lies next to, a
    seed that is not finite never becomes a candidate, and the rows stay each target's own."""
    from service.kinematics.ik._numeric import NumericOptions, search

    arm = Robot([Joint(f"q{i}", "revolute", a, alpha, d, 0.0) for i, (a, alpha, d) in enumerate(
        [(0.0, np.pi / 2, 0.4), (0.5, 0.0, 0.0), (0.1, np.pi / 2, 0.0), (0.0, -np.pi / 2, 0.45),
         (0.0, np.pi / 2, 0.0), (0.0, 0.0, 0.1)])])
    truth = np.array([[0.3, -0.4, 0.5, 0.2, -0.6, 0.7], [-1.1, 0.2, -0.3, 1.0, 0.9, -2.0]])
    goal = PoseGoal(forward_kinematics(arm, truth))
    seeds = np.full((2, 2, 6), np.nan)
    seeds[:, 0] = truth + 0.02  # beside each target's own configuration; the second seed of each is empty
    for starts in (0, 3):
        found = search(arm, goal, NumericOptions(starts=starts), None, seeds=seeds)
        assert found.candidates.joints.shape == (2, starts + 2, 6)
        for target in range(2):
            valid = found.candidates.valid[target]
            assert valid[starts] and not valid[starts + 1]
            np.testing.assert_allclose(found.candidates.joints[target, starts], truth[target], atol=1e-9)
