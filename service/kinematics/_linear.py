"""Stacked linear solves that one singular system does not fail."""

from __future__ import annotations

import numpy as np


def solve_each(matrices: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """``np.linalg.solve`` of a stack of systems, matrices (K, m, m) against right-hand sides (K, m, r): (K, m, r).

    numpy fails the whole stack when one matrix is exactly singular (a damping below the rounding of its entries,
    as an arm of 1e-7 links with a slide metres out gives, or a rank-deficient task). Then each system is solved
    alone: a singular one by least squares (the pseudo-inverse), one whose entries are not finite not at all
    (zeros: no step).
    """
    try:
        return np.linalg.solve(matrices, rhs)
    except np.linalg.LinAlgError:
        pass
    solved = np.zeros(rhs.shape)
    for index, (matrix, right) in enumerate(zip(matrices, rhs)):
        if not (np.isfinite(matrix).all() and np.isfinite(right).all()):
            continue
        try:
            solved[index] = np.linalg.solve(matrix, right)
        except np.linalg.LinAlgError:
            solved[index] = np.linalg.pinv(matrix) @ right
    return solved
