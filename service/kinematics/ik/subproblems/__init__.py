"""Geometric subproblems of analytic inverse kinematics, vectorised over a batch.

The solvers for each kinematic family reduce a pose to a few of these
subproblems (Paden-Kahan 1-3, IK-Geo 4, 5 and 6, and their prismatic analogues). Each
one returns every candidate, and each candidate carries its own flags. No
solver here decides acceptance, so a solver can still use a least-squares
candidate when the target is just outside the workspace.

Conventions
-----------
* ``R(k, theta) p`` rotates ``p`` by ``theta`` radians about the unit axis
  ``k`` through the origin, right-handed (Rodrigues)::

      R(k, theta) p = (k.p) k + cos(theta) (p - (k.p) k) + sin(theta) (k x p)

  Callers translate points first so that the axis passes through the origin.
  ``p_perp = p - (k.p) k`` is the part of ``p`` that the rotation moves.
* Axes and fixed directions (``k``, ``k1``, ``k2``, ``h``, ``v``) are constant
  unit vectors of shape (3,). They are validated (shape, unit norm to
  ``ORTHONORMAL_TOLERANCE``) and renormalised.
* Data (points of shape (..., 3), distances and heights of shape (...)) broadcast
  against each other. Their broadcast shape, the *batch shape*, leads every
  result. Data are not checked for finiteness: these functions run inside the
  solvers, after the API boundary. A non-finite row gives NaN candidates with
  false flags.
* Returned angles are wrapped to ``(-pi, pi]``. A candidate slot that does not
  exist (``valid`` false) holds NaN.
* Tolerances come from :mod:`service.kinematics._tolerances` and scale with each
  problem. Every docstring names the scale it uses.

  - ``GEOMETRY_TOLERANCE`` decides whether a least-squares miss or a
    rotation radius is zero. It is relative to the scale.
  - ``DUPLICATE_TOLERANCE`` decides when two roots are one root. Two roots
    are reported once, as the tangent root midway between them with ``merged``
    set, when that midpoint satisfies the equation to
    ``DUPLICATE_TOLERANCE**2`` of the scale. Near a double root the residual
    grows with the square of the distance from it. So this merges roots
    closer than about ``DUPLICATE_TOLERANCE`` (radians, or a fraction of the
    scale for prismatic joints), the project's test for "the same solution".
    It also merges a double root that rounding has split. Subproblem 2 bounds the
    two angles themselves (both within ``DUPLICATE_TOLERANCE``) or, on small
    circles, the crossing gap's rounding error: its midpoint residual alone
    would merge roots ``1e-6 / sqrt(radius)`` apart.

Results
-------
Every function returns a record with the same flags. ``m`` is the number of
candidate slots, which is fixed for each function (1 or 2; 4 for subproblems 5 and 6):

* ``valid`` (..., m) bool: the candidate exists. The first slot is always
  valid, because every problem has an exact, least-squares or representative
  answer (subproblem 5 excepted: it has four slots and no least-squares
  candidate, so a row with no real root has none).
* ``exact`` (..., m) bool: the candidate satisfies the equation within
  tolerance. False means it is the least-squares answer.
* ``degenerate`` (...,) bool: infinitely many candidates are equally good,
  because the equation or its least-squares residual does not depend on a
  joint. The candidate given is a representative, with the free value 0.
* ``merged`` (...,) bool: the two roots coincide. This is the tangent or
  workspace-boundary case, and a singular configuration for the solver. Only
  the first slot is valid. Functions with one slot always report False.

The records are :class:`AngleSolutions` (``theta``), :class:`AnglePairSolutions`
(``theta1``, ``theta2``), :class:`AngleTripleSolutions` (``theta1``, ``theta2``,
``theta3``: subproblem 5, four slots), :class:`AngleQuadSolutions` (``theta1``, ``theta2``:
subproblem 6, four slots) and :class:`DisplacementSolutions` (``s``).

Modules
-------
* ``_records``: the solution records and the constants that merge two roots into one.
* ``_vectors``: input checks, axis frames (bounded caches) and the small vector algebra.
* ``_roots``: the harmonic equation, the quadratic and the trigonometric quartic.
* ``_paden_kahan``: subproblems 1-4 and the planar two-link elbow.
* ``_sp5``, ``_sp6``: IK-Geo subproblems 5 and 6.
* ``_prismatic``: the slide to a distance or a plane, and subproblem 5 with a slide.
"""

from ._paden_kahan import (
    planar_two_link_elbow,
    subproblem_1,
    subproblem_2,
    subproblem_2_chain,
    subproblem_3,
    subproblem_4,
)
from ._prismatic import prismatic_to_distance, prismatic_to_plane, subproblem_5_prismatic
from ._records import (
    AnglePairSolutions,
    AngleQuadSolutions,
    AngleSolutions,
    AngleTripleSolutions,
    DisplacementSolutions,
    TurnSlideSolutions,
)
from ._roots import quadratic_roots
from ._sp5 import subproblem_5
from ._sp6 import subproblem_6

__all__ = [
    "AnglePairSolutions",
    "AngleQuadSolutions",
    "AngleTripleSolutions",
    "AngleSolutions",
    "DisplacementSolutions",
    "planar_two_link_elbow",
    "prismatic_to_distance",
    "prismatic_to_plane",
    "quadratic_roots",
    "subproblem_1",
    "subproblem_2",
    "subproblem_2_chain",
    "subproblem_3",
    "subproblem_4",
    "subproblem_5",
    "subproblem_5_prismatic",
    "subproblem_6",
    "TurnSlideSolutions",
]
