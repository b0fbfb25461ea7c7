"""The solution records of the subproblems, and the constants that decide when two roots are one.

Every subproblem returns one of these named tuples. Each candidate slot carries its own flags (``valid``,
``exact``) and each row its own ``degenerate`` and ``merged``: :mod:`service.kinematics.ik.subproblems` documents
what they mean. The merge constants turn ``DUPLICATE_TOLERANCE`` into the tests each equation uses.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ..._tolerances import DUPLICATE_TOLERANCE, FOLD_TOLERANCE


class AngleSolutions(NamedTuple):
    """Candidates for one joint angle. See the package docstring (:mod:`service.kinematics.ik.subproblems`) for
    the flags."""

    theta: np.ndarray  #: (..., m) float, radians in (-pi, pi]; NaN where not valid
    valid: np.ndarray  #: (..., m) bool
    exact: np.ndarray  #: (..., m) bool
    degenerate: np.ndarray  #: (...,) bool
    merged: np.ndarray  #: (...,) bool


class AnglePairSolutions(NamedTuple):
    """Candidates for two joint angles. Slot ``j`` of ``theta1`` and ``theta2`` is one candidate."""

    theta1: np.ndarray  #: (..., 2) float, radians in (-pi, pi]; NaN where not valid
    theta2: np.ndarray  #: (..., 2) float, radians in (-pi, pi]; NaN where not valid
    valid: np.ndarray  #: (..., 2) bool
    exact: np.ndarray  #: (..., 2) bool
    degenerate: np.ndarray  #: (...,) bool
    merged: np.ndarray  #: (...,) bool


class AngleTripleSolutions(NamedTuple):
    """Candidates for three joint angles (subproblem 5). Slot ``j`` of the three arrays is one candidate."""

    theta1: np.ndarray  #: (..., 4) float, radians in (-pi, pi]; NaN where not valid
    theta2: np.ndarray  #: (..., 4) float, radians in (-pi, pi]; NaN where not valid
    theta3: np.ndarray  #: (..., 4) float, radians in (-pi, pi]; NaN where not valid
    valid: np.ndarray  #: (..., 4) bool
    exact: np.ndarray  #: (..., 4) bool
    degenerate: np.ndarray  #: (...,) bool
    merged: np.ndarray  #: (...,) bool


class DisplacementSolutions(NamedTuple):
    """Candidates for one prismatic displacement. See the package docstring
    (:mod:`service.kinematics.ik.subproblems`) for the flags."""

    s: np.ndarray  #: (..., m) float, length unit of the inputs; NaN where not valid
    valid: np.ndarray  #: (..., m) bool
    exact: np.ndarray  #: (..., m) bool
    degenerate: np.ndarray  #: (...,) bool
    merged: np.ndarray  #: (...,) bool


class AngleQuadSolutions(NamedTuple):
    """Candidates for two joint angles with up to four slots. Slot ``j`` of ``theta1`` and ``theta2`` is one
    candidate. See the package docstring (:mod:`service.kinematics.ik.subproblems`) for the flags; ``merged``
    marks a double root."""

    theta1: np.ndarray  #: (..., 4) float, radians in (-pi, pi]; NaN where not valid
    theta2: np.ndarray  #: (..., 4) float, radians in (-pi, pi]; NaN where not valid
    valid: np.ndarray  #: (..., 4) bool
    exact: np.ndarray  #: (..., 4) bool
    degenerate: np.ndarray  #: (...,) bool
    merged: np.ndarray  #: (...,) bool


class TurnSlideSolutions(NamedTuple):
    """Candidates for two joint angles and a displacement (:func:`subproblem_5_prismatic`, four slots).

    ``phi_free`` (..., 4): the slot's ``phi`` is undetermined (the vector it turns lies on ``k2``); it is 0.
    """

    phi: np.ndarray  #: (..., 4) float, radians in (-pi, pi]; NaN where not valid
    theta: np.ndarray  #: (..., 4) float, radians in (-pi, pi]; NaN where not valid
    s: np.ndarray  #: (..., 4) float, length unit of the inputs; NaN where not valid
    valid: np.ndarray  #: (..., 4) bool
    exact: np.ndarray  #: (..., 4) bool
    degenerate: np.ndarray  #: (...,) bool
    merged: np.ndarray  #: (...,) bool
    phi_free: np.ndarray  #: (..., 4) bool


# Largest relative residual of the midpoint for which two roots count as one.
_MERGE_RESIDUAL = DUPLICATE_TOLERANCE**2
# Two roots phi ± half of rho cos(theta - phi) = c are one when half < DUPLICATE_TOLERANCE / 2, that is when
# rho - |c| < rho (1 - cos(DUPLICATE_TOLERANCE / 2)): an angle criterion, independent of the problem's scale.
_MERGE_COS_GAP = 1.0 - math.cos(DUPLICATE_TOLERANCE / 2.0)
# The same angle criterion for two crossings of circles of radius rho, half an angle asin(sqrt(g) / rho) apart:
# g < rho**2 sin(DUPLICATE_TOLERANCE / 2)**2.
_MERGE_SIN_SQUARED = math.sin(DUPLICATE_TOLERANCE / 2.0) ** 2
# Rounding error of that g relative to rho: exact tangencies give |g| up to 86 ulps of rho (tests/kinematics/ik/
# subproblems/test_subproblems.py's tangent cones); this bound keeps a factor 3 above it.
_GAP_ROUNDING = 256 * np.finfo(float).eps
# How much that g (relative to rho) moves per unit of error in the directions of p and q (radians): a tangency
# seen through inputs that carry an error (the arm's own deviation from its family) has |g| up to about
# (2 + 4 / sin) rho times that error, sin the sine between the axes; this keeps a margin above it.
_GAP_PER_ERROR = 16.0
# Two cones (subproblem 2) that miss by at most this gap on the unit sphere are a tangency that an error of the
# inputs split: an angle found upstream at a double root (subproblem 3 at its fold: a stretched elbow) is known
# only to the square root of its inputs' error (FOLD_TOLERANCE), and moves the point by that much. Their
# closest directions are then the touching root, reported ``merged`` (not ``exact``) for the caller to refine.
_NEAR_TANGENT_GAP = FOLD_TOLERANCE
