"""Stacked linear solves: one singular system does not fail the others."""

from __future__ import annotations

import numpy as np

from service.kinematics._linear import solve_each


def test_each_system_is_solved_as_well_as_it_can_be():
    rng = np.random.default_rng(3)
    regular = rng.normal(size=(2, 3, 3)) + 3 * np.eye(3)
    singular = np.array([[1.0, 2.0, 0.0], [2.0, 4.0, 0.0], [0.0, 0.0, 1.0]])  # rank 2: exactly singular in LU
    broken = np.full((3, 3), np.nan)
    matrices = np.stack([regular[0], singular, broken, regular[1]])
    rhs = rng.normal(size=(4, 3, 1))
    solved = solve_each(matrices, rhs)
    np.testing.assert_allclose(solved[[0, 3]], np.linalg.solve(regular, rhs[[0, 3]]), rtol=1e-13)
    # the singular one by least squares: the minimum-norm x with the smallest residual
    np.testing.assert_allclose(solved[1], np.linalg.lstsq(singular, rhs[1], rcond=None)[0], atol=1e-13)
    assert solved[2].tolist() == [[0.0]] * 3  # no finite system: no step
    # a stack numpy solves whole is solved as numpy solves it
    assert solve_each(regular, rhs[:2]).tobytes() == np.linalg.solve(regular, rhs[:2]).tobytes()
