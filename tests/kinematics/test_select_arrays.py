"""select_arrays gives, target by target, exactly what select() gives for the same IK answer.

The API's two batch forms both use select_arrays, so this is the check that ties them to the per-result rules.
"""

from __future__ import annotations

import numpy as np
import pytest

from service.robots.catalogue import load_catalogue
from service.config import Settings
from service.kinematics import Limits, forward_kinematics
from service.kinematics.ik import Ordering, select, select_arrays
from service.kinematics.ik._arrays import solve_ik_arrays
from service.kinematics.ik._solve import results_from_arrays

CATALOGUE = load_catalogue([Settings().builtin_robots_dir], max_joints=32)
INF = np.inf

CASES = {
    "no limits": ("puma560_standard", lambda r: Limits(np.full(6, -INF), np.full(6, INF)), {}),
    "no limits, reference": ("puma560_standard", lambda r: Limits(np.full(6, -INF), np.full(6, INF)),
                             {"reference": np.array([0.1, -0.4, 0.2, 0.0, 0.3, 0.0])}),
    "no limits, weights, per-joint move, max_solutions": (
        "ur5", lambda r: Limits(np.full(6, -INF), np.full(6, INF)),
        {"reference": np.zeros(6), "ordering": Ordering("linf", np.array([2, 1, 1, 0.5, 1, 1.0]), 4,
                                                        np.array([2.5, 2.5, INF, 3, 3, 3]))}),
    "one-sided and narrow limits, a cap": (
        "puma560_standard", lambda r: Limits(np.array([-3.2, -INF, -1.0, -INF, -INF, -INF]),
                                             np.array([3.2, INF, INF, INF, 2.0, INF])),
        {"reference": np.zeros(6), "max_equivalents": 3}),
    "the robot's limits (2π-equivalents: select() itself)": ("puma560_standard", Limits.of, {}),
    "the robot's limits, not filtered, l2": (
        "ur5", Limits.of, {"filter_limits": False, "reference": np.zeros(6), "ordering": Ordering("l2")}),
    "stanford slide limits": ("spong_ex3_5_stanford", Limits.of, {"reference": np.zeros(6)}),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_select_arrays_matches_select(case):
    robot_id, make_limits, options = CASES[case]
    robot = CATALOGUE.get(robot_id).robot
    q = np.random.default_rng(sorted(CASES).index(case)).uniform(-np.pi, np.pi, (60, robot.dof))
    q[:, ~robot.is_revolute] = 0.5
    targets = forward_kinematics(robot, q)
    targets[-1, 0, 3] = 50.0  # unreachable
    arrays = solve_ik_arrays(robot, targets, reference=options.get("reference"))
    limits = make_limits(robot)
    chosen = select_arrays(robot, arrays, limits, **options)
    results = results_from_arrays(robot, arrays, targets, True, options.get("reference"))
    for row, result in enumerate(results):
        expected = select(robot, result, limits, **options)
        assert chosen.status[row] == expected.status
        assert (chosen.truncated[row], chosen.trimmed[row], chosen.available[row]) == (
            expected.expansion_truncated, expected.trimmed, expected.available)
        assert chosen.notes.get(row, []) == expected.notes
        for table, entries in ((chosen.solutions, expected.solutions), (chosen.rejected, expected.rejected)):
            mine = np.flatnonzero(table.target == row)
            assert len(mine) == len(entries)
            for k, entry in zip(mine, entries):
                np.testing.assert_array_equal(table.joints[k], entry.solution.joints)
                assert table.within_limits[k] == entry.within_limits
                assert {name: values[codes[k]] for name, (values, codes) in table.labels.items() if codes[k] >= 0} == \
                    entry.solution.branch
