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
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from .._errors import InvalidInputError
from .._rotations import wrap_angle
from .._tolerances import DUPLICATE_TOLERANCE, GEOMETRY_TOLERANCE, ORTHONORMAL_TOLERANCE

__all__ = [
    "AnglePairSolutions",
    "AngleQuadSolutions",
    "AngleTripleSolutions",
    "AngleSolutions",
    "DisplacementSolutions",
    "planar_two_link_elbow",
    "prismatic_to_distance",
    "prismatic_to_plane",
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


class AngleSolutions(NamedTuple):
    """Candidates for one joint angle. See the module docstring for the flags."""

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
    """Candidates for one prismatic displacement. See the module docstring for the flags."""

    s: np.ndarray  #: (..., m) float, length unit of the inputs; NaN where not valid
    valid: np.ndarray  #: (..., m) bool
    exact: np.ndarray  #: (..., m) bool
    degenerate: np.ndarray  #: (...,) bool
    merged: np.ndarray  #: (...,) bool


# Largest relative residual of the midpoint for which two roots count as one.
_MERGE_RESIDUAL = DUPLICATE_TOLERANCE**2
# Two roots phi ± half of rho cos(theta - phi) = c are one when half < DUPLICATE_TOLERANCE / 2, that is when
# rho - |c| < rho (1 - cos(DUPLICATE_TOLERANCE / 2)): an angle criterion, independent of the problem's scale.
_MERGE_COS_GAP = 1.0 - math.cos(DUPLICATE_TOLERANCE / 2.0)
# The same angle criterion for two crossings of circles of radius rho, half an angle asin(sqrt(g) / rho) apart:
# g < rho**2 sin(DUPLICATE_TOLERANCE / 2)**2.
_MERGE_SIN_SQUARED = math.sin(DUPLICATE_TOLERANCE / 2.0) ** 2
# Rounding error of that g relative to rho: exact tangencies give |g| up to 86 ulps of rho (tests/kinematics/
# test_subproblems.py's tangent cones); this bound keeps a factor 3 above it.
_GAP_ROUNDING = 256 * np.finfo(float).eps


# ---------------------------------------------------------------------------
# Private helpers
# ---------------------------------------------------------------------------


def _unit(k: ArrayLike, name: str) -> np.ndarray:
    """Return the constant unit vector ``k`` (shape (3,)) renormalised, or raise.

    The solvers pass the same few joint axes on every call, so a vector that passed is remembered by value
    (read-only) and the next call with it skips the checks.
    """
    try:
        key = tuple(k.tolist()) if isinstance(k, np.ndarray) else tuple(k)
        known = _UNITS.get(key)
    except TypeError:  # not a flat sequence of numbers: let the checks below say what is wrong
        key, known = None, None
    if known is not None:
        return known
    unit = _checked_unit(k, name)
    if key is not None and len(_UNITS) < _UNITS_KEPT:
        unit.setflags(write=False)
        _UNITS[key] = unit
    return unit


_UNITS: dict[tuple, np.ndarray] = {}
_UNITS_KEPT = 4096  # bounded: a caller sweeping over many axes keeps no more than this


def _checked_unit(k: ArrayLike, name: str) -> np.ndarray:
    k = np.asarray(k, dtype=float)
    if k.shape != (3,):
        raise InvalidInputError(f"{name} must be a unit vector of shape (3,), got shape {k.shape}", location=(name,))
    norm = math.sqrt(float(k @ k))
    if not abs(norm - 1.0) <= ORTHONORMAL_TOLERANCE:  # also rejects NaN
        raise InvalidInputError(f"{name} must be a unit vector, its norm is {norm:.9g}", location=(name,))
    return k / norm


def _points(p: ArrayLike, name: str) -> np.ndarray:
    p = np.asarray(p, dtype=float)
    if p.ndim == 0 or p.shape[-1] != 3:
        raise InvalidInputError(f"{name} must have shape (..., 3), got shape {p.shape}", location=(name,))
    return p


def _distances(d: ArrayLike, name: str) -> np.ndarray:
    d = np.asarray(d, dtype=float)
    if (d < 0.0).any():
        raise InvalidInputError(f"{name} is a distance and must not be negative", location=(name,))
    return d


def axis_frame(k: np.ndarray) -> np.ndarray:
    """Right-handed orthonormal frame ``[e1, e2, k]`` (as columns) around the unit axis ``k``, remembered by value
    (read-only) as :func:`_unit` remembers the axes."""
    key = tuple(k.tolist())
    frame = _FRAMES.get(key)
    if frame is None:
        frame = _build_frame(k)
        if len(_FRAMES) < _UNITS_KEPT:
            frame.setflags(write=False)
            _FRAMES[key] = frame
    return frame


_FRAMES: dict[tuple, np.ndarray] = {}


def _build_frame(k: np.ndarray) -> np.ndarray:
    """Right-handed orthonormal frame ``[e1, e2, k]`` (as columns) around the unit axis ``k``.

    ``p @ axis_frame(k)`` gives the coordinates ``(x, y, z)`` of ``p``, where ``z = k.p``
    is the height along the axis. A rotation about ``k`` turns ``(x, y)`` like a
    plane rotation: ``R(k, theta) p`` has ``(x cos - y sin, x sin + y cos, z)``.
    """
    kx, ky, kz = k.tolist()
    # e1 = k x (the coordinate axis least aligned with k), normalised.
    if abs(kx) <= abs(ky) and abs(kx) <= abs(kz):
        e1 = (0.0, kz, -ky)
    elif abs(ky) <= abs(kz):
        e1 = (-kz, 0.0, kx)
    else:
        e1 = (ky, -kx, 0.0)
    n = math.sqrt(e1[0] ** 2 + e1[1] ** 2 + e1[2] ** 2)
    ax, ay, az = e1[0] / n, e1[1] / n, e1[2] / n
    e2 = (ky * az - kz * ay, kz * ax - kx * az, kx * ay - ky * ax)  # k x e1
    return np.array([[ax, e2[0], kx], [ay, e2[1], ky], [az, e2[2], kz]])


def _coords(p: np.ndarray, frame: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    c = p @ frame
    return c[..., 0], c[..., 1], c[..., 2]


def _cross3(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product of two vectors of shape (3,) (cheaper than ``np.cross`` for one pair)."""
    (ax, ay, az), (bx, by, bz) = a.tolist(), b.tolist()
    return np.array([ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx])


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise dot product over the last axis, broadcasting the batch axes."""
    if a.ndim == 1 and b.ndim == 1:  # single row: ``@`` has less overhead than einsum
        return a @ b
    return np.einsum("...i,...i->...", a, b)


def _hypot(x: ArrayLike, y: ArrayLike) -> np.ndarray:
    """``sqrt(x**2 + y**2)``, several times faster than ``np.hypot``.

    Accurate for any length far from float overflow or underflow (1e+-154).
    """
    return np.sqrt(x * x + y * y)


def _norm(a: np.ndarray) -> np.ndarray:
    return np.sqrt(_dot(a, a))


def _pair(shape: tuple[int, ...], first: ArrayLike, second: ArrayLike, dtype: type) -> np.ndarray:
    """Candidates of shape ``shape + (2,)`` from the two slots (cheaper than ``np.stack`` for one row)."""
    out = np.empty(shape + (2,), dtype=dtype)
    out[..., 0] = first
    out[..., 1] = second
    return out


def _rotate_onto(
    frame: np.ndarray, p: np.ndarray, q: np.ndarray, scale: np.ndarray | None = None,
    free_below: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Subproblem 1 core: ``(theta, exact, degenerate)`` for ``R(k, theta) p = q``.

    ``frame`` is ``axis_frame(k)``. ``scale`` defaults to ``max(||p||, ||q||)``. ``free_below``, the radius
    at or below which ``p`` or ``q`` counts as on the axis, defaults to ``GEOMETRY_TOLERANCE * scale``.
    """
    px, py, pz = _coords(p, frame)
    qx, qy, qz = _coords(q, frame)
    # q.R p = pz qz + cos(theta) (px qx + py qy) + sin(theta) (px qy - py qx), largest at:
    theta = np.arctan2(px * qy - py * qx, px * qx + py * qy)
    radius_p = _hypot(px, py)
    radius_q = _hypot(qx, qy)
    if scale is None:
        scale = np.maximum(_hypot(radius_p, pz), _hypot(radius_q, qz))
    tol = GEOMETRY_TOLERANCE * scale
    exact = (np.abs(radius_p - radius_q) <= tol) & (np.abs(pz - qz) <= tol)
    free_below = tol if free_below is None else free_below
    degenerate = (radius_p <= free_below) | (radius_q <= free_below)
    return np.where(degenerate, 0.0, wrap_angle(theta)), exact, degenerate


def _harmonic(a: ArrayLike, b: ArrayLike, c: ArrayLike, scale: ArrayLike) -> AngleSolutions:
    """Solve ``a cos(theta) + b sin(theta) = c`` elementwise.

    Subproblems 3 and 4 and the two-link elbow all reduce to this equation.
    ``scale`` (same unit as ``a``, ``b``, ``c``) sets the tolerance. With
    ``rho = hypot(a, b)`` and ``phi = atan2(b, a)`` the equation reads
    ``rho cos(theta - phi) = c``. The roots are ``phi + half`` and
    ``phi - half``, in that order, where ``half = atan2(sqrt(rho**2 - c**2), c)``.
    When ``|c| > rho``, ``theta = phi`` (``c > 0``) or ``phi + pi`` (``c < 0``)
    minimises ``|a cos + b sin - c|``. When ``rho`` is about 0 the equation is
    degenerate. The two roots are one (``merged``) when they are closer than
    ``DUPLICATE_TOLERANCE`` in angle, i.e. ``rho - |c| < rho (1 - cos(tol / 2))``.
    """
    tol = GEOMETRY_TOLERANCE * scale
    rho = _hypot(a, b)
    abs_c = np.abs(c)
    excess = abs_c - rho  # > 0: c is outside the range [-rho, rho] of the left side
    exact = np.asarray(excess <= tol)
    shape = exact.shape  # the broadcast batch shape
    degenerate = rho <= tol
    if np.shape(degenerate) != shape:
        degenerate = np.broadcast_to(degenerate, shape)
    regular = exact & ~degenerate
    merged = regular & (-excess <= rho * _MERGE_COS_GAP)
    two = regular & ~merged
    root = np.sqrt(np.maximum(-excess, 0.0) * (rho + abs_c))  # sqrt(rho**2 - c**2) without cancellation
    half = np.arctan2(root * two, c)  # 0 or pi unless there are two roots
    phi = np.arctan2(b, a)
    first = np.where(degenerate, 0.0, wrap_angle(phi + half))
    second = np.where(two, wrap_angle(phi - half), np.nan)
    exact_first = regular | (degenerate & (np.abs(a - c) <= tol))
    return AngleSolutions(
        theta=_pair(shape, first, second, float),
        valid=_pair(shape, True, two, bool),
        exact=_pair(shape, exact_first, two, bool),
        degenerate=np.array(degenerate),
        merged=np.asarray(merged),
    )


# ---------------------------------------------------------------------------
# Revolute subproblems
# ---------------------------------------------------------------------------


def subproblem_1(k: ArrayLike, p: ArrayLike, q: ArrayLike, free_below: ArrayLike | None = None) -> AngleSolutions:
    """Paden-Kahan 1: solve ``R(k, theta) p = q``; else minimise ``||R(k, theta) p - q||``.

    An exact solution needs ``||p_perp|| = ||q_perp||`` and ``k.p = k.q``. The
    solution and the least-squares minimiser are the same formula:
    ``theta = atan2(k.(p x q), p_perp.q_perp)``, which turns ``p_perp`` onto
    the direction of ``q_perp``.

    Parameters
    ----------
    k : array_like, shape (3,)
        Unit rotation axis through the origin.
    p, q : array_like, shape (..., 3)
        Points before and after the rotation.
    free_below : array_like, shape (...), optional
        The radius from the axis at or below which a point counts as on it (``degenerate``); by default
        ``GEOMETRY_TOLERANCE * L``. A caller that knows the target's rounding passes it: a point further
        out still fixes the angle, to rounding / radius.

    Returns
    -------
    AngleSolutions
        ``theta`` has shape (..., 1). ``merged`` is always False.

    Notes
    -----
    Scale: ``L = max(||p||, ||q||)``. The solution is exact when
    ``| ||p_perp|| - ||q_perp|| |`` and ``|k.p - k.q|`` are both at most
    ``GEOMETRY_TOLERANCE * L``. It is degenerate, with representative
    ``theta = 0``, when ``p`` lies on the axis (``||p_perp|| <= tol``): every
    angle solves it. It is also degenerate when only ``q`` lies on the axis,
    because every angle is then an equally good least-squares answer.

    Examples
    --------
    >>> sol = subproblem_1([0, 0, 1], [1, 0, 0.5], [0, 1, 0.5])
    >>> np.degrees(sol.theta).round(9).tolist(), sol.exact.tolist()
    ([90.0], [True])
    """
    k = _unit(k, "k")
    p = _points(p, "p")
    q = _points(q, "q")
    free_below = None if free_below is None else np.asarray(free_below, dtype=float)
    theta, exact, degenerate = _rotate_onto(axis_frame(k), p, q, free_below=free_below)  # all of the batch shape
    return AngleSolutions(
        theta=theta[..., None],
        valid=np.ones(theta.shape + (1,), dtype=bool),
        exact=exact[..., None],
        degenerate=np.asarray(degenerate),
        merged=np.zeros(theta.shape, dtype=bool),
    )


def subproblem_2(k1: ArrayLike, k2: ArrayLike, p: ArrayLike, q: ArrayLike) -> AnglePairSolutions:
    """Paden-Kahan 2, IK-Geo form: solve ``R(k1, theta1) p = R(k2, theta2) q``; else least squares.

    The common point ``x`` lies on the circle that ``p`` sweeps about ``k1`` and
    on the circle that ``q`` sweeps about ``k2``. On the unit sphere, write
    ``x = alpha k1 + beta k2 + gamma (k1 x k2)``. The conditions
    ``k1.x = k1.p/||p||`` and ``k2.x = k2.q/||q||`` fix ``alpha`` and ``beta``.
    The condition ``||x|| = 1`` gives ``gamma = +/- sqrt(g) / ||k1 x k2||`` with
    ``g = 1 - ||alpha k1 + beta k2||**2``. Each ``x`` gives both angles through
    subproblem 1. The code evaluates it in the coordinates of ``p`` and ``q``
    along ``k1``, ``k2`` and ``k1 x k2``, so it forms no batch of 3-vectors.
    When ``g < 0`` the two cones do not meet. With ``gamma = 0``, the angles
    then turn ``p`` and ``q`` to the closest pair of directions on the two
    cones. Because ``||R1 p - R2 q||**2 = ||p||**2 + ||q||**2 - 2 R1 p . R2 q``,
    this pair also minimises ``||R(k1, theta1) p - R(k2, theta2) q||``, and it
    does so whatever ``||p||`` and ``||q||`` are.

    Paden-Kahan's own form ``R(k1, a) R(k2, b) p = q`` is the same problem as
    ``R(k1, -a) q = R(k2, b) p``. Call ``subproblem_2(k1, k2, q, p)`` and take
    ``a = -theta1``, ``b = theta2``, or call :func:`subproblem_2_chain`.

    Parameters
    ----------
    k1, k2 : array_like, shape (3,)
        Unit axes through the origin, not parallel.
    p, q : array_like, shape (..., 3)
        ``p`` is rotated about ``k1``, ``q`` about ``k2``.

    Returns
    -------
    AnglePairSolutions
        Two slots. There are 2 valid candidates when the cones cross, and 1
        when they touch (``merged``), miss (least squares) or when a joint is
        free (``degenerate``). The candidate with ``+gamma`` comes first.
        Candidates are not exact when ``||p|| != ||q||``. They are still the
        least-squares minimisers.

    Raises
    ------
    InvalidInputError
        When ``k1`` and ``k2`` are parallel (``||k1 x k2|| <= GEOMETRY_TOLERANCE``).

    Notes
    -----
    Scale: ``L = max(||p||, ||q||)``. Exactness needs
    ``| ||p|| - ||q|| | <= tol L``. When the cones miss, it also needs the gap
    between the closest directions to be at most ``GEOMETRY_TOLERANCE`` (on the
    unit sphere). A gap that small means the cones touch, and the candidate is
    then ``merged``. ``theta1`` is free (degenerate, representative 0) when
    ``p`` lies on ``k1``, or ``p = 0``. ``theta2`` is then the subproblem 1
    answer for ``R(k2, theta2) q = p``. The case ``q`` on ``k2`` is the mirror
    image.

    Examples
    --------
    Two crossings, at ``(0, 1, 0)`` and ``(0, -1, 0)``:

    >>> sol = subproblem_2([0, 0, 1], [1, 0, 0], [1, 0, 0], [0, 1, 0])
    >>> np.degrees(sol.theta1).round(9).tolist(), np.degrees(sol.theta2).round(9).tolist()
    ([90.0, -90.0], [0.0, 180.0])

    Two cones of half-angle 45 degrees about perpendicular axes touch at ``(1, 0, 1)``:

    >>> sol = subproblem_2([0, 0, 1], [1, 0, 0], [1, 0, 1], [1, 1, 0])
    >>> np.degrees(sol.theta1).round(9).tolist(), np.degrees(sol.theta2).round(9).tolist()
    ([0.0, nan], [90.0, nan])
    >>> sol.merged.tolist(), sol.exact.tolist()
    (True, [True, False])
    """
    k1 = _unit(k1, "k1")
    k2 = _unit(k2, "k2")
    normal = _cross3(k1, k2)
    sin2 = float(normal @ normal)
    if sin2 <= GEOMETRY_TOLERANCE**2:
        raise InvalidInputError(
            "k1 and k2 are parallel; subproblem 2 needs two intersecting, non-parallel axes", location=("k2",)
        )
    cos = float(k1 @ k2)
    sin = math.sqrt(sin2)
    p = _points(p, "p")
    q = _points(q, "q")

    # Everything follows from the coordinates of p and q along k1, k2 and n = k1 x k2.
    basis = np.array([k1, k2, normal]).T
    pk = p @ basis
    qk = q @ basis
    p1, p2, pn = pk[..., 0], pk[..., 1], pk[..., 2]
    q1, q2, qn = qk[..., 0], qk[..., 1], qk[..., 2]
    d1 = p2 - cos * p1  # p.(k2 - cos k1): with pn, the part of p that k1 moves
    e2 = q1 - cos * q2  # q.(k1 - cos k2): with qn, the part of q that k2 moves
    radius_p = _hypot(pn, d1) / sin  # ||k1 x p||
    radius_q = _hypot(qn, e2) / sin  # ||k2 x q||
    norm_p = _hypot(p1, radius_p)
    norm_q = _hypot(q2, radius_q)
    scale = np.maximum(norm_p, norm_q)
    tol = GEOMETRY_TOLERANCE * scale
    free1 = radius_p <= tol  # p on k1 (or p = 0): theta1 free
    free2 = radius_q <= tol  # q on k2 (or q = 0): theta2 free
    degenerate = free1 | free2
    norms_match = np.abs(norm_p - norm_q) <= tol

    # Directions on the unit sphere (zero vectors are degenerate rows).
    inv_p = 1.0 / np.where(norm_p > 0.0, norm_p, 1.0)
    inv_q = 1.0 / np.where(norm_q > 0.0, norm_q, 1.0)
    h1 = p1 * inv_p
    h2 = q2 * inv_q
    rho1 = radius_p * inv_p
    rho2 = radius_q * inv_q
    alpha = (h1 - cos * h2) / sin2
    beta = (h2 - cos * h1) / sin2
    g = _crossing_gap(rho1, rho2, alpha * sin, beta * sin)
    meet = g >= 0.0
    # The crossings x0 +/- gamma n lie on the circles of radius rho1 and rho2, half an angle asin(sqrt(g) / rho)
    # apart about each axis: they are one root when both angles are within DUPLICATE_TOLERANCE (the smaller
    # radius turns the more), or when g is within its rounding error (about a hundred ulps of rho: a tangency
    # that rounding split). A test on the midpoint's residual, g (1/rho1 + 1/rho2) <= 1e-12, merged roots
    # 1e-6 / sqrt(rho) apart instead: the Stanford shoulder at theta2 = 6e-7 came back 1.5e-6 off.
    rho = np.minimum(rho1, rho2)
    close = g <= np.maximum(_MERGE_SIN_SQUARED * rho, _GAP_ROUNDING) * rho
    two = meet & ~close & ~degenerate
    gamma = np.sqrt(np.maximum(g, 0.0)) * two / sin

    # Subproblem 1 towards x = x0 + sign gamma n, written in the coordinates:
    #   (k1 x p).x = -beta pn + sign gamma d1,   (k1 x p).(k1 x x) = beta d1 + sign gamma pn,
    #   (k2 x q).x = alpha qn - sign gamma e2,   (k2 x q).(k2 x x) = alpha e2 + sign gamma qn.
    s1, c1, t1, u1 = -beta * pn, beta * d1, gamma * d1, gamma * pn
    s2, c2, t2, u2 = alpha * qn, alpha * e2, gamma * e2, gamma * qn
    first1 = wrap_angle(np.arctan2(s1 + t1, c1 + u1))
    first2 = wrap_angle(np.arctan2(s2 - t2, c2 + u2))
    second1 = np.where(two, wrap_angle(np.arctan2(s1 - t1, c1 - u1)), np.nan)
    second2 = np.where(two, wrap_angle(np.arctan2(s2 + t2, c2 - u2)), np.nan)

    touch = meet & close
    if not meet.all():
        # The cones miss. In the orthonormal frame (k1, (k2 - cos k1) / sin) of
        # their common plane, the closest directions are u = (h1, +/-rho1) on
        # the side of beta and v = h2 (cos, sin) +/- rho2 (sin, -cos) on the
        # side of alpha. They touch if u and v meet within tolerance.
        side1 = np.sign(beta) * rho1
        side2 = np.sign(alpha) * rho2
        gap = _hypot(h1 - cos * h2 - sin * side2, side1 - sin * h2 + cos * side2)
        touch = touch | (~meet & (gap <= GEOMETRY_TOLERANCE))
    merged = touch & ~degenerate
    exact_first = norms_match & (meet | touch)

    if degenerate.any():
        scale_b = np.broadcast_to(scale, degenerate.shape)
        # theta1 free: R(k2, theta2) q = p.  theta2 free: R(k1, theta1) p = q.
        free_t2, exact2, _ = _rotate_onto(axis_frame(k2), q, p, scale_b)
        free_t1, exact1, _ = _rotate_onto(axis_frame(k1), p, q, scale_b)
        first1 = np.where(free1, 0.0, np.where(free2, free_t1, first1))
        first2 = np.where(free1, free_t2, np.where(free2, 0.0, first2))
        exact_first = np.where(free1, exact2, np.where(free2, exact1, exact_first))

    shape = two.shape
    return AnglePairSolutions(
        theta1=_pair(shape, first1, second1, float),
        theta2=_pair(shape, first2, second2, float),
        valid=_pair(shape, True, two, bool),
        exact=_pair(shape, exact_first, two & norms_match, bool),
        degenerate=np.asarray(degenerate),
        merged=np.asarray(merged),
    )


def _crossing_gap(rho1, rho2, alpha_sin, beta_sin):
    """``g = 1 - ||x0||**2`` for ``x0 = alpha k1 + beta k2`` (so ``gamma = sqrt(g) / sin``), without cancellation.

    In the orthonormal frame (k1, (k2 - cos k1) / sin) of the axes' plane, ``x0 = (h1, beta sin)``, so
    ``g = rho1**2 - (beta sin)**2``, and symmetrically ``g = rho2**2 - (alpha sin)**2``. The form of the
    smaller radius is used, as a product of a difference and a sum. Computed as ``1 - alpha h1 - beta h2``, ``g``
    carries an absolute error of about 1e-16: near a wrist singularity (a radius ``eps``, ``g ~ eps**2``) that
    moved the roots by ``1e-16 / eps`` and, below ``eps ~ 1e-8``, merged the two roots into one wrong one.
    """
    first = (rho1 - np.abs(beta_sin)) * (rho1 + np.abs(beta_sin))
    second = (rho2 - np.abs(alpha_sin)) * (rho2 + np.abs(alpha_sin))
    return np.where(rho1 <= rho2, first, second)


def subproblem_2_chain(k1: ArrayLike, k2: ArrayLike, p: ArrayLike, q: ArrayLike) -> AnglePairSolutions:
    """Paden-Kahan 2, chain form: solve ``R(k1, theta1) R(k2, theta2) p = q``; else least squares.

    This is :func:`subproblem_2` applied to ``R(k1, -theta1) q = R(k2, theta2) p``.
    It minimises the same residual, because rotations preserve length. Flags,
    slots and tolerances are as in :func:`subproblem_2`. In this form
    ``theta2`` is free when ``p`` lies on ``k2``, and ``theta1`` is free when
    ``q`` lies on ``k1``.

    Parameters
    ----------
    k1, k2 : array_like, shape (3,)
        Unit axes through the origin, not parallel. ``k2`` acts first.
    p, q : array_like, shape (..., 3)
        Point before and after both rotations.

    Examples
    --------
    Turn ``z`` onto ``y``: first about ``y`` to ``+x`` or ``-x``, then about ``z``:

    >>> sol = subproblem_2_chain([0, 0, 1], [0, 1, 0], [0, 0, 1], [0, 1, 0])
    >>> np.degrees(sol.theta1).round(9).tolist(), np.degrees(sol.theta2).round(9).tolist()
    ([-90.0, 90.0], [-90.0, 90.0])
    """
    sol = subproblem_2(k1, k2, q, p)
    return sol._replace(theta1=wrap_angle(-sol.theta1))


def subproblem_3(k: ArrayLike, p: ArrayLike, q: ArrayLike, delta: ArrayLike) -> AngleSolutions:
    """Paden-Kahan 3: solve ``||R(k, theta) p - q|| = delta``; else minimise ``| ||R(k, theta) p - q|| - delta |``.

    Expanding the square gives ``a cos(theta) + b sin(theta) = c``, where
    ``a = p_perp.q_perp``, ``b = k.(p x q)`` and
    ``c = (||p_perp||**2 + ||q_perp||**2 + (k.p - k.q)**2 - delta**2) / 2``.
    The distance varies between the two ends of a range. When ``delta`` is
    outside that range, the least-squares answer is the end nearer
    ``delta``.

    Parameters
    ----------
    k : array_like, shape (3,)
        Unit rotation axis through the origin.
    p, q : array_like, shape (..., 3)
        Rotated point and fixed point.
    delta : array_like, shape (...)
        Wanted distance, ``>= 0``.

    Returns
    -------
    AngleSolutions
        ``theta`` has shape (..., 2). The roots are ``phi + half`` and then
        ``phi - half``, where ``phi = atan2(b, a)``.

    Raises
    ------
    InvalidInputError
        When a ``delta`` is negative.

    Notes
    -----
    Scale: ``S = ||p||**2 + ||q||**2 + delta**2``. The answer is exact when
    ``(d**2 - delta**2) / 2`` is at most ``GEOMETRY_TOLERANCE * S``, with ``d``
    the distance reached. The problem is degenerate (representative
    ``theta = 0``) when ``||p_perp|| ||q_perp|| <= tol S``, that is when ``p``
    or ``q`` lies on the axis. The distance then does not depend on ``theta``,
    and the answer is exact only if that distance is ``delta``. At either end
    of the range the two roots merge.

    Examples
    --------
    >>> sol = subproblem_3([0, 0, 1], [1, 0, 0], [0, 0, 0], 1.0)  # p on a circle about q
    >>> sol.degenerate.tolist(), sol.exact.tolist()
    (True, [True, False])
    >>> sol = subproblem_3([0, 0, 1], [1, 0, 0], [1, 0, 0], np.sqrt(2))
    >>> np.degrees(sol.theta).round(9).tolist()
    [90.0, -90.0]
    """
    k = _unit(k, "k")
    p = _points(p, "p")
    q = _points(q, "q")
    delta = _distances(delta, "delta")
    frame = axis_frame(k)
    px, py, pz = _coords(p, frame)
    qx, qy, qz = _coords(q, frame)
    rp2 = px * px + py * py
    rq2 = qx * qx + qy * qy
    delta2 = delta * delta
    c = 0.5 * (rp2 + rq2 + (pz - qz) ** 2 - delta2)
    scale = rp2 + rq2 + pz * pz + qz * qz + delta2
    return _harmonic(px * qx + py * qy, px * qy - py * qx, c, scale)


def subproblem_4(h: ArrayLike, k: ArrayLike, p: ArrayLike, delta: ArrayLike) -> AngleSolutions:
    """IK-Geo 4: solve ``h.R(k, theta) p = delta``; else minimise ``|h.R(k, theta) p - delta|``.

    With ``h_perp = h - (h.k) k`` the equation is
    ``a cos(theta) + b sin(theta) = c``, where ``a = h_perp.p``,
    ``b = (h x k).p`` and ``c = delta - (h.k)(k.p)``. The height ``h.R p``
    varies in ``(h.k)(k.p) +/- ||h_perp|| ||p_perp||``. When ``delta`` is
    outside that interval, the least-squares answer is the end nearer
    ``delta``.

    Parameters
    ----------
    h : array_like, shape (3,)
        Unit normal of the planes ``h.x = delta``.
    k : array_like, shape (3,)
        Unit rotation axis through the origin.
    p : array_like, shape (..., 3)
        Rotated point.
    delta : array_like, shape (...)
        Wanted height along ``h``, signed.

    Returns
    -------
    AngleSolutions
        ``theta`` has shape (..., 2). The roots are ``phi + half`` and then
        ``phi - half``, where ``phi = atan2(b, a)``.

    Notes
    -----
    Scale: ``S = ||p|| + |delta|``. The answer is exact when the height error
    is at most ``GEOMETRY_TOLERANCE * S``. The problem is degenerate
    (representative ``theta = 0``) when ``||h_perp|| ||p_perp|| <= tol S``, that
    is when ``h`` is parallel to ``k`` or ``p`` lies on the axis. The height
    then does not depend on ``theta``. At either end of the interval the two
    roots merge.

    Examples
    --------
    >>> sol = subproblem_4([0, 1, 0], [0, 0, 1], [1, 0, 0], 0.5)  # sin(theta) = 0.5
    >>> np.degrees(sol.theta).round(9).tolist()
    [150.0, 30.0]
    """
    h = _unit(h, "h")
    k = _unit(k, "k")
    p = _points(p, "p")
    delta = np.asarray(delta, dtype=float)
    hk = float(h @ k)
    # One product gives h_perp.p, (h x k).p and k.p for the whole batch.
    coords = p @ np.stack([h - hk * k, _cross3(h, k), k], axis=1)
    a = coords[..., 0]
    b = coords[..., 1]
    c = delta - hk * coords[..., 2]
    scale = _norm(p) + np.abs(delta)
    return _harmonic(a, b, c, scale)


# A root z of a trigonometric quartic (:func:`_trig_quartic_roots`) counts as a real angle when | |z| - 1 | is at
# most this. Real roots lie on the unit circle and the others come in pairs (z, 1 / conj(z)); a double root (a
# tangent case) that rounding splits lies about sqrt(eps) ~ 1.5e-8 off it, some 600 times inside. A root accepted
# here that solves nothing fails the caller's residual test after its Newton steps.
_ON_UNIT_CIRCLE = 1e-5
# The degree-2 terms of a trigonometric quartic count as absent below this fraction of its coefficients' size: the
# companion matrix would carry entries of 1 / this and more, while the harmonic equation left is off by at most
# this (the callers' Newton steps remove it).
_LEADING_NEGLIGIBLE = 1e-8
# A trigonometric quartic vanishes identically (every angle solves it) when each coefficient is at most this
# fraction of the problem's scale.
_VANISHING = 1e-12


def _rotation_parts(k: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``R(k, theta) p = fixed + cos(theta) perp + sin(theta) cross`` for points ``p`` (..., 3)."""
    fixed = (p @ k)[..., None] * k
    return fixed, p - fixed, np.cross(k, p)


def _inverse_2x2(A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(inverse, determinant)`` of 2 × 2 matrices (..., 2, 2); the inverse is NaN where the determinant is 0."""
    det = A[..., 0, 0] * A[..., 1, 1] - A[..., 0, 1] * A[..., 1, 0]
    adjugate = np.empty_like(A)
    adjugate[..., 0, 0], adjugate[..., 1, 1] = A[..., 1, 1], A[..., 0, 0]
    adjugate[..., 0, 1], adjugate[..., 1, 0] = -A[..., 0, 1], -A[..., 1, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        return adjugate / det[..., None, None], det


def _trig_quartic_roots(alpha0: np.ndarray, alpha1: np.ndarray, beta1: np.ndarray, alpha2: np.ndarray,
                        beta2: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The real roots of ``alpha0 + alpha1 cos t + beta1 sin t + alpha2 cos 2t + beta2 sin 2t = 0``: four slots.

    Times ``z**2`` with ``z = exp(i t)`` the equation is the quartic
    ``c4 z**4 + c3 z**3 + alpha0 z**2 + conj(c3) z + conj(c4)`` with ``c4 = (alpha2 - i beta2) / 2`` and
    ``c3 = (alpha1 - i beta1) / 2``, whose roots on the unit circle are the real angles (no tangent half-angle,
    so ``t = pi`` is an ordinary root). The roots are the eigenvalues of its companion matrices, one batched
    ``eigvals``. Where the degree-2 part is negligible (``|c4|`` at most :data:`_LEADING_NEGLIGIBLE` of the
    coefficients' size) the harmonic equation ``alpha1 cos t + beta1 sin t = -alpha0`` is solved instead: two
    slots, the other two copies of the first, not on the circle.

    The coefficients are arrays of one shape (...). Returns ``(theta, on_circle, double)``: ``theta``
    (..., 4) radians in (-pi, pi], each root's angle (off the circle too: the nearest angle for a row without
    a real root); ``on_circle`` (..., 4) where the root is real (within :data:`_ON_UNIT_CIRCLE` radially, or an
    exact root of the harmonic equation); ``double`` (...,) where the harmonic equation's two roots are one.
    Whether the quartic vanishes identically is the caller's to judge (:func:`_vanishes`).

    Examples
    --------
    ``cos 2t = 0``: t = +/-pi/4 and +/-3pi/4.

    >>> theta, on_circle, _ = _trig_quartic_roots(*np.array([[0.0], [0.0], [0.0], [1.0], [0.0]]))
    >>> np.sort(np.degrees(theta[on_circle])).round(9).tolist()
    [-135.0, -45.0, 45.0, 135.0]
    """
    shape = np.shape(alpha0)
    c4 = 0.5 * (alpha2 - 1j * beta2)
    c3 = 0.5 * (alpha1 - 1j * beta1)
    size = np.maximum.reduce([np.abs(alpha0), np.abs(alpha1) + np.abs(beta1), np.abs(alpha2) + np.abs(beta2)])
    size = np.where(size > 0.0, size, 1.0)
    quartic = np.abs(c4) > _LEADING_NEGLIGIBLE * size
    theta = np.full(shape + (4,), np.nan)
    on_circle = np.zeros(shape + (4,), dtype=bool)
    double = np.zeros(shape, dtype=bool)
    if quartic.any():
        lead = np.where(quartic, c4, 1.0)
        companion = np.zeros(shape + (4, 4), dtype=complex)
        companion[..., 1, 0] = companion[..., 2, 1] = companion[..., 3, 2] = 1.0
        companion[..., 0, 0] = -c3 / lead
        companion[..., 0, 1] = -alpha0 / lead
        companion[..., 0, 2] = -np.conj(c3) / lead
        companion[..., 0, 3] = -np.conj(c4) / lead
        companion[~quartic] = np.eye(4) * 2.0  # placeholder rows: roots off the circle, overwritten below
        z = np.linalg.eigvals(companion)
        on_circle = quartic[..., None] & (np.abs(np.abs(z) - 1.0) <= _ON_UNIT_CIRCLE)
        theta = np.angle(z)
    if not quartic.all():
        harmonic = _harmonic(alpha1, beta1, -alpha0, size)
        two = harmonic.valid & harmonic.exact
        theta[..., :2] = np.where(~quartic[..., None], np.nan_to_num(harmonic.theta), theta[..., :2])
        theta[..., 2:] = np.where(~quartic[..., None], theta[..., :1], theta[..., 2:])
        on_circle[..., :2] = np.where(~quartic[..., None], two, on_circle[..., :2])
        double = ~quartic & harmonic.merged
    return wrap_angle(np.nan_to_num(theta)), on_circle, double


def _vanishes(alpha0: np.ndarray, alpha1: np.ndarray, beta1: np.ndarray, alpha2: np.ndarray, beta2: np.ndarray,
              scale: np.ndarray) -> np.ndarray:
    """Whether the trigonometric quartic of :func:`_trig_quartic_roots` is 0 for every angle (...,): each of its
    complex coefficients at most :data:`_VANISHING` times ``scale`` (...,)."""
    largest = np.maximum.reduce([np.abs(alpha0), 0.5 * _hypot(alpha1, beta1), 0.5 * _hypot(alpha2, beta2)])
    return largest <= _VANISHING * scale


def subproblem_5(k1: ArrayLike, k2: ArrayLike, k3: ArrayLike, p0: ArrayLike, p1: ArrayLike, p2: ArrayLike,
                 p3: ArrayLike) -> AngleTripleSolutions:
    """IK-Geo 5: solve ``p0 + R(k1, theta1) p1 = R(k2, theta2) (p2 + R(k3, theta3) p3)``; up to 4 solutions.

    With ``L(theta1) = p0 + R(k1, theta1) p1`` and ``M(theta3) = p2 + R(k3, theta3) p3``,
    ``R(k2, theta2)`` keeps both the height along ``k2`` and the length, so a solution needs
    ``k2.L = k2.M`` and ``||L||**2 = ||M||**2``. Both are linear in ``u1 = (cos theta1, sin theta1)``
    and ``u3 = (cos theta3, sin theta3)``: ``A1 u1 - A3 u3 = r``, two rows of 2 × 2 blocks (the
    length row divided by the problem's length ``S`` so that both rows are lengths). Solving for one
    unit vector in terms of the other, ``u_s = f + G u_t`` (per row, the block with the larger
    ``|det| / ||A||_F**2``), ``||u_s||**2 = 1`` is a trigonometric quartic in ``theta_t``. With
    ``z = exp(i theta_t)`` it is a polynomial of degree 4 whose roots on the unit circle are the
    solutions (no tangent half-angle, so ``theta = pi`` is an ordinary root). The roots are the
    eigenvalues of its companion matrix, each refined by two Newton steps on the real equation;
    ``theta2`` follows by subproblem 1, ``R(k2, theta2) M = L``. This is Pieper's quartic for a
    3R positioner whose second and third axes are skew.

    Parameters
    ----------
    k1, k2, k3 : array_like, shape (3,)
        Unit rotation axes through the origin.
    p0, p1, p2, p3 : array_like, shape (..., 3)
        Offsets and rotated points, broadcast against each other.

    Returns
    -------
    AngleTripleSolutions
        ``theta1``, ``theta2``, ``theta3`` have shape (..., 4), the slots in no particular order.

    Notes
    -----
    Unlike subproblems 1–4 there is no least-squares candidate: a row whose quartic has no root
    on the unit circle (within :data:`_ON_UNIT_CIRCLE` radially) has no valid slot. Roots closer than
    ``DUPLICATE_TOLERANCE`` (a tangent root, the edge of the workspace) are reported once with
    ``merged`` set. Scale: ``S = ||p0|| + ||p1|| + ||p2|| + ||p3||``; a candidate is ``exact``
    when the vector equation holds to ``GEOMETRY_TOLERANCE * S``. Near a tangent root a root
    carries about the square root of the rounding error; such valid but inexact candidates are
    left to the caller (the IK solvers refine and verify every candidate by FK).
    ``degenerate``: the quartic vanishes identically, so ``theta_t`` is free (``p1`` on ``k1``
    or ``p3`` on ``k3``, with the target reachable); the representative has ``theta_t = 0``.
    When neither block is invertible the equations do not separate the angles (``k1 ∥ k2``
    with ``p2`` on ``k3``, or ``k2 ∥ k3``): no slot is valid, and those geometries are solved
    by subproblems 3 and 4 instead.

    Examples
    --------
    A point turned by three skew axes and found again (one slot holds the generating angles):

    >>> k1, k2, k3 = np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0.6, 0, 0.8])
    >>> p0, p2, p3 = np.array([0.3, 0.1, 0.0]), np.array([0.0, 0.4, 0.2]), np.array([0.5, 0.2, 0.1])
    >>> def R(k, t):
    ...     return np.cos(t) * np.eye(3) + np.sin(t) * np.cross(np.eye(3), k) + (1 - np.cos(t)) * np.outer(k, k)
    >>> p1 = R(k1, -0.4) @ (R(k2, 0.7) @ (p2 + R(k3, -1.1) @ p3) - p0)
    >>> sol = subproblem_5(k1, k2, k3, p0, p1, p2, p3)
    >>> found = np.stack([sol.theta1, sol.theta2, sol.theta3], axis=-1)[sol.valid]
    >>> bool(np.isclose(found, [0.4, 0.7, -1.1]).all(axis=-1).any())
    True
    """
    k1, k2, k3 = _unit(k1, "k1"), _unit(k2, "k2"), _unit(k3, "k3")
    p0, p1, p2, p3 = (_points(p, name) for p, name in ((p0, "p0"), (p1, "p1"), (p2, "p2"), (p3, "p3")))
    shape = np.broadcast_shapes(p0.shape, p1.shape, p2.shape, p3.shape)[:-1]
    p0, p1, p2, p3 = (np.broadcast_to(p, shape + (3,)) for p in (p0, p1, p2, p3))
    S = _norm(p0) + _norm(p1) + _norm(p2) + _norm(p3)
    S = np.where(S > 0.0, S, 1.0)
    fixed1, perp1, cross1 = _rotation_parts(k1, p1)
    fixed3, perp3, cross3 = _rotation_parts(k3, p3)
    A1 = np.stack([np.stack([perp1 @ k2, cross1 @ k2], axis=-1),
                   2.0 * np.stack([_dot(p0, perp1), _dot(p0, cross1)], axis=-1) / S[..., None]], axis=-2)
    A3 = np.stack([np.stack([perp3 @ k2, cross3 @ k2], axis=-1),
                   2.0 * np.stack([_dot(p2, perp3), _dot(p2, cross3)], axis=-1) / S[..., None]], axis=-2)
    r = np.stack([(p2 + fixed3 - p0 - fixed1) @ k2,
                  (_dot(p2, p2) + _dot(p3, p3) + 2 * _dot(p2, fixed3)
                   - _dot(p0, p0) - _dot(p1, p1) - 2 * _dot(p0, fixed1)) / S], axis=-1)
    inverse1, det1 = _inverse_2x2(A1)
    inverse3, det3 = _inverse_2x2(A3)
    quality1 = np.abs(det1) / np.maximum((A1 * A1).sum(axis=(-1, -2)), 1e-300)
    quality3 = np.abs(det3) / np.maximum((A3 * A3).sum(axis=(-1, -2)), 1e-300)
    by_theta1 = quality3 >= quality1  # solve for u3, the quartic in theta1
    # u_s = inverse_s (A_t u_t + rho): rho = -r solving for u3, +r solving for u1
    inverse = np.where(by_theta1[..., None, None], inverse3, inverse1)
    A_t = np.where(by_theta1[..., None, None], A1, A3)
    rho = np.where(by_theta1[..., None], -r, r)
    separable = np.maximum(quality1, quality3) > 1e-12
    G = inverse @ A_t
    f = np.einsum("...ij,...j->...i", inverse, rho)
    Q = np.swapaxes(G, -1, -2) @ G
    g = np.einsum("...ji,...j->...i", G, f)
    h = _dot(f, f) - 1.0
    # F(t) = u Q u + 2 g u + h as alpha0 + alpha1 cos t + beta1 sin t + alpha2 cos 2t + beta2 sin 2t
    coefficients = ((Q[..., 0, 0] + Q[..., 1, 1]) / 2 + h, 2 * g[..., 0], 2 * g[..., 1],
                    (Q[..., 0, 0] - Q[..., 1, 1]) / 2, Q[..., 0, 1])
    scale = 1.0 + Q[..., 0, 0] + Q[..., 1, 1] + _dot(f, f)
    with np.errstate(invalid="ignore"):
        theta_t, valid, double = _trig_quartic_roots(*coefficients)
        free = separable & _vanishes(*coefficients, scale)
        valid &= (separable & ~free)[..., None]
        theta_t = np.where(valid, theta_t, np.nan)
        theta_t[free, 0], valid[free, 0] = 0.0, True
        for _ in range(2):  # Newton on F(t) = u Q u + 2 g u + h, u = (cos t, sin t)
            u = np.stack([np.cos(theta_t), np.sin(theta_t)], axis=-1)
            du = np.stack([-u[..., 1], u[..., 0]], axis=-1)
            Qu = np.einsum("...ij,...mj->...mi", Q, u)
            F = np.einsum("...mi,...mi->...m", u, Qu + 2 * g[..., None, :]) + h[..., None]
            dF = 2 * np.einsum("...mi,...mi->...m", du, Qu + g[..., None, :])
            step = np.where(np.abs(dF) > 1e-9 * scale[..., None], F / np.where(dF == 0, 1.0, dF), 0.0)
            theta_t = np.where(free[..., None] | (np.abs(step) > 1e-3), theta_t, theta_t - step)
        u_t = np.stack([np.cos(theta_t), np.sin(theta_t)], axis=-1)
        u_s = f[..., None, :] + np.einsum("...ij,...mj->...mi", G, u_t)
        theta_s = np.arctan2(u_s[..., 1], u_s[..., 0])
    theta1 = wrap_angle(np.where(by_theta1[..., None], theta_t, theta_s))
    theta3 = wrap_angle(np.where(by_theta1[..., None], theta_s, theta_t))
    L = p0[..., None, :] + _rotate_points(k1, theta1, p1[..., None, :])
    M = p2[..., None, :] + _rotate_points(k3, theta3, p3[..., None, :])
    theta2, _, _ = _rotate_onto(axis_frame(k2), np.nan_to_num(M), np.nan_to_num(L), S[..., None])
    miss = _norm(L - _rotate_points(k2, theta2, M))
    # the same root twice (a tangent root): keep the first
    merged = double & separable & ~free  # a tangent root of the harmonic equation, already reported once
    for later in range(1, 4):
        for earlier in range(later):
            gap = np.abs(wrap_angle(theta_t[..., later] - theta_t[..., earlier]))
            same = valid[..., later] & valid[..., earlier] & (gap <= DUPLICATE_TOLERANCE)
            merged |= same
            valid[..., later] &= ~same
    nan = np.nan
    return AngleTripleSolutions(
        theta1=np.where(valid, theta1, nan), theta2=np.where(valid, theta2, nan),
        theta3=np.where(valid, theta3, nan), valid=valid,
        exact=valid & (miss <= GEOMETRY_TOLERANCE * S[..., None]), degenerate=free, merged=merged)


def _rotate_points(k: np.ndarray, theta: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``R(k, theta) p`` (Rodrigues), broadcasting ``theta`` (...) against points ``p`` (..., 3)."""
    fixed, perp, cross = _rotation_parts(k, p)
    c, s = np.cos(theta)[..., None], np.sin(theta)[..., None]
    return fixed + c * perp + s * cross


def planar_two_link_elbow(l1: float, l2: float, r: ArrayLike) -> AngleSolutions:
    """Elbow angle of a planar two-link arm: solve ``||l1 e(0) + l2 e(q2)|| = r`` for ``q2``.

    ``e(t)`` is the unit vector at angle ``t``, and ``q2`` is the angle of the
    second link relative to the first (0 when stretched out). By the law of
    cosines ``cos(q2) = D = (r**2 - l1**2 - l2**2) / (2 l1 l2)``. The branches
    are ``q2 = +acos(D)`` and then ``-acos(D)``. When ``|D| > 1`` the target is
    unreachable. The least-squares answer is then ``q2 = 0`` (stretched, when
    ``D > 1``) or ``pi`` (folded, when ``D < -1``).

    This is subproblem 3 with ``k = z``, ``p = (l2, 0, 0)``, ``q = (-l1, 0, 0)``
    and ``delta = r``. The equation ``l1 l2 cos(q2) = (r**2 - l1**2 - l2**2) / 2``
    goes straight to the same solver core, and the flags mean the same.
    ``merged`` marks the singular boundary ``|D| = 1``, where the branches
    meet: ``r = l1 + l2`` (``q2 = 0``) or ``r = |l1 - l2|`` (``q2 = pi``).
    ``exact`` false marks an unreachable ``r``.

    Parameters
    ----------
    l1, l2 : float
        Link lengths, ``>= 0``.
    r : array_like, shape (...)
        Distance from the first joint to the target, ``>= 0``.

    Returns
    -------
    AngleSolutions
        ``theta`` has shape (..., 2). The problem is degenerate
        (representative 0) when ``l1 l2`` is about 0.

    Notes
    -----
    Scale: ``S = l1**2 + l2**2 + r**2``. Tolerances as in :func:`subproblem_3`.

    Examples
    --------
    >>> sol = planar_two_link_elbow(1.0, 1.0, np.sqrt(2))
    >>> np.degrees(sol.theta).round(9).tolist()
    [90.0, -90.0]
    >>> planar_two_link_elbow(1.0, 1.0, [2.0, 2.5]).merged.tolist()
    [True, False]
    """
    lengths = []
    for name, value in (("l1", l1), ("l2", l2)):
        value = float(value)
        if not (math.isfinite(value) and value >= 0.0):
            raise InvalidInputError(f"{name} must be a finite length >= 0, got {value}", location=(name,))
        lengths.append(value)
    l1, l2 = lengths
    r = _distances(r, "r")
    r2 = r * r
    return _harmonic(l1 * l2, 0.0, 0.5 * (r2 - l1 * l1 - l2 * l2), l1 * l1 + l2 * l2 + r2)


# ---------------------------------------------------------------------------
# Prismatic analogues
# ---------------------------------------------------------------------------


def prismatic_to_distance(p: ArrayLike, v: ArrayLike, q: ArrayLike, delta: ArrayLike) -> DisplacementSolutions:
    """Slide to a distance: solve ``||p + s v - q|| = delta``; else minimise ``| ||p + s v - q|| - delta |``.

    With ``w = p - q``, ``b = v.w`` and ``e = ||w - b v||``, the distance from
    ``q`` to the line, the equation is ``(s + b)**2 = delta**2 - e**2``. The
    roots are ``s = -b + sqrt(...)`` and then ``-b - sqrt(...)``. When
    ``delta < e`` no point of the line is that close to ``q``. The
    least-squares answer is then the closest point, ``s = -b``.

    Parameters
    ----------
    p : array_like, shape (..., 3)
        Point at ``s = 0``.
    v : array_like, shape (3,)
        Unit sliding direction.
    q : array_like, shape (..., 3)
        Fixed point.
    delta : array_like, shape (...)
        Wanted distance, ``>= 0``.

    Returns
    -------
    DisplacementSolutions
        ``s`` has shape (..., 2). ``degenerate`` is always False, because the
        distance always grows along the line.

    Notes
    -----
    Scale: ``L = ||p - q|| + delta``. The answer is exact when
    ``e - delta <= GEOMETRY_TOLERANCE * L``. The roots merge (``merged``,
    the sphere of radius ``delta`` tangent to the line) when the midpoint
    ``s = -b`` meets the equation within ``DUPLICATE_TOLERANCE**2 * L``.

    Examples
    --------
    >>> sol = prismatic_to_distance([0, 0, 0], [1, 0, 0], [0, 3, 0], 5.0)
    >>> sol.s.round(9).tolist()
    [4.0, -4.0]
    """
    p = _points(p, "p")
    v = _unit(v, "v")
    q = _points(q, "q")
    delta = _distances(delta, "delta")
    wx, wy, b = _coords(p - q, axis_frame(v))  # b = v.(p - q)
    e = _hypot(wx, wy)
    scale = _hypot(e, b) + delta
    tol = GEOMETRY_TOLERANCE * scale
    excess = e - delta
    exact = np.asarray(excess <= tol)
    shape = exact.shape  # the broadcast batch shape
    root = np.sqrt(np.maximum(-excess, 0.0) * (delta + e))  # sqrt(delta**2 - e**2) without cancellation
    merged = exact & (-excess <= _MERGE_RESIDUAL * scale)  # the midpoint s = -b misses by -excess
    two = exact & ~merged
    return DisplacementSolutions(
        s=_pair(shape, root * two - b, np.where(two, -b - root, np.nan), float),
        valid=_pair(shape, True, two, bool),
        exact=_pair(shape, exact, two, bool),
        degenerate=np.zeros(shape, dtype=bool),
        merged=np.asarray(merged),
    )


def prismatic_to_plane(h: ArrayLike, p: ArrayLike, v: ArrayLike, delta: ArrayLike) -> DisplacementSolutions:
    """Slide to a plane: solve ``h.(p + s v) = delta``; else minimise ``|h.(p + s v) - delta|``.

    The equation is linear: ``s = (delta - h.p) / (h.v)``. It is degenerate
    when ``|h.v| <= GEOMETRY_TOLERANCE``, that is when the slide runs parallel
    to the plane. The height then does not depend on ``s``. The representative
    is ``s = 0``, and it is exact only if ``p`` already lies in the plane.
    Otherwise there is always one exact solution.

    Parameters
    ----------
    h : array_like, shape (3,)
        Unit normal of the planes ``h.x = delta``.
    p : array_like, shape (..., 3)
        Point at ``s = 0``.
    v : array_like, shape (3,)
        Unit sliding direction.
    delta : array_like, shape (...)
        Wanted height along ``h``, signed.

    Returns
    -------
    DisplacementSolutions
        ``s`` has shape (..., 1). ``merged`` is always False.

    Notes
    -----
    Scale: ``L = ||p|| + |delta|``. In the degenerate case the answer is exact
    when ``|h.p - delta| <= GEOMETRY_TOLERANCE * L``.

    Examples
    --------
    >>> prismatic_to_plane([0, 0, 1], [1, 2, 3], [0, 0, 1], 5.0).s.tolist()
    [2.0]
    """
    h = _unit(h, "h")
    p = _points(p, "p")
    v = _unit(v, "v")
    delta = np.asarray(delta, dtype=float)
    hv = float(h @ v)
    miss = delta - p @ h
    if abs(hv) <= GEOMETRY_TOLERANCE:
        scale = _norm(p) + np.abs(delta)
        s = np.zeros_like(miss)
        exact = np.abs(miss) <= GEOMETRY_TOLERANCE * scale
        degenerate = np.ones(miss.shape, dtype=bool)
    else:
        s = miss / hv
        exact = np.ones(miss.shape, dtype=bool)
        degenerate = np.zeros(miss.shape, dtype=bool)
    return DisplacementSolutions(
        s=s[..., None],
        valid=np.ones(miss.shape + (1,), dtype=bool),
        exact=exact[..., None],
        degenerate=degenerate,
        merged=np.zeros(miss.shape, dtype=bool),
    )


# ---------------------------------------------------------------------------
# Subproblem 6: two angles from two linear equations
# ---------------------------------------------------------------------------


class AngleQuadSolutions(NamedTuple):
    """Candidates for two joint angles with up to four slots. Slot ``j`` of ``theta1`` and ``theta2`` is one
    candidate. See the module docstring for the flags; ``merged`` marks a double root."""

    theta1: np.ndarray  #: (..., 4) float, radians in (-pi, pi]; NaN where not valid
    theta2: np.ndarray  #: (..., 4) float, radians in (-pi, pi]; NaN where not valid
    valid: np.ndarray  #: (..., 4) bool
    exact: np.ndarray  #: (..., 4) bool
    degenerate: np.ndarray  #: (...,) bool
    merged: np.ndarray  #: (...,) bool


_NEWTON_STEPS = 2  # on the pair of equations, after the quartic's roots
_EXACT_PAIR = 10 * GEOMETRY_TOLERANCE  # relative residual of an exact root: Newton-polished roots reach ~1e-15


def _term_coefficients(k: np.ndarray, h: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``h.R(k, theta) p = a cos(theta) + b sin(theta) + e``: the coefficients (a, b, e), each of the batch shape."""
    frame = axis_frame(k)
    hx, hy, hz = _coords(h, frame)
    px, py, pz = _coords(p, frame)
    return hx * px + hy * py, hy * px - hx * py, hz * pz


def subproblem_6(
    k1: ArrayLike, k2: ArrayLike,
    h1: ArrayLike, p1: ArrayLike, h2: ArrayLike, p2: ArrayLike, d1: ArrayLike,
    h3: ArrayLike, p3: ArrayLike, h4: ArrayLike, p4: ArrayLike, d2: ArrayLike,
) -> AngleQuadSolutions:
    """IK-Geo 6: solve the pair of equations

    ``h1.R(k1, theta1) p1 + h2.R(k2, theta2) p2 = d1`` and ``h3.R(k1, theta1) p3 + h4.R(k2, theta2) p4 = d2``.

    Each term ``h.R(k, theta) p`` is ``a cos(theta) + b sin(theta) + e`` (coordinates in a frame around ``k``), so
    the pair is linear in ``x1 = (cos theta1, sin theta1)`` and ``x2 = (cos theta2, sin theta2)``:
    ``A x1 + B x2 = r`` with A, B of shape (2, 2). Multiplying by the adjugate of B gives
    ``det(B) x2 = adj(B) (r - A x1)``; ``||x2|| = 1`` then reads ``||adj(B) (r - A x1)||**2 = det(B)**2``, a
    trigonometric polynomial of degree 2 in theta1, that is a quartic in ``exp(i theta1)``: at most four roots,
    each giving x2 and so theta2. The elimination runs on the block with the larger determinant (B, or A with
    the roles of the angles swapped), row by row. When both blocks are singular but the pair is not, each equation
    combination that removes one angle is a harmonic equation in the other: 2 x 2 candidates.

    Parameters
    ----------
    k1, k2 : array_like, shape (3,)
        Unit rotation axes through the origin.
    h1, h2, h3, h4 : array_like, shape (..., 3)
        Fixed vectors (any length) of the linear forms.
    p1, p2, p3, p4 : array_like, shape (..., 3)
        Rotated points: ``p1``, ``p3`` about ``k1``; ``p2``, ``p4`` about ``k2``.
    d1, d2 : array_like, shape (...)
        Right-hand sides.

    Returns
    -------
    AngleQuadSolutions
        Four slots; valid slots first. There is no least-squares answer: a row without a root has only its
        first slot valid, holding the angle pair nearest to a solution (``exact`` false), so that a solver
        can still refine it. ``merged`` marks a double root (reported once). ``degenerate`` marks a pair that
        does not fix both angles (rank below 2, or the eliminated equation met by every value of one angle),
        with a representative whose free angle is 0.

    Notes
    -----
    Scale: ``S = sum ||h_i|| ||p_i|| + |d1| + |d2|``. A root is exact when both equations hold to
    ``10 * GEOMETRY_TOLERANCE * S`` at the polished angles (Newton steps on the pair itself; near a double
    root, where they stall, the residual is still quadratic in the error). A block counts as singular when its determinant is at
    most ``GEOMETRY_TOLERANCE`` times the squared size of the coefficients.

    Examples
    --------
    ``cos(theta1) + cos(theta2) = 1`` and ``sin(theta1) - sin(theta2) = 0``: theta1 = theta2 = +/-60 degrees.

    >>> x, y, z = [1, 0, 0], [0, 1, 0], [0, 0, 1]
    >>> sol = subproblem_6(z, z, x, x, x, x, 1.0, y, x, y, [-1, 0, 0], 0.0)
    >>> sorted(np.degrees(sol.theta1[sol.valid]).round(9).tolist())
    [-60.0, 60.0]
    """
    k1 = _unit(k1, "k1")
    k2 = _unit(k2, "k2")
    vectors = [np.asarray(v, dtype=float) for v in (h1, p1, h2, p2, h3, p3, h4, p4)]
    for name, v in zip(("h1", "p1", "h2", "p2", "h3", "p3", "h4", "p4"), vectors):
        _points(v, name)
    h1, p1, h2, p2, h3, p3, h4, p4 = vectors
    d1 = np.asarray(d1, dtype=float)
    d2 = np.asarray(d2, dtype=float)
    a11, a12, e1 = _term_coefficients(k1, h1, p1)
    b11, b12, f1 = _term_coefficients(k2, h2, p2)
    a21, a22, e2 = _term_coefficients(k1, h3, p3)
    b21, b22, f2 = _term_coefficients(k2, h4, p4)
    r1 = d1 - e1 - f1
    r2 = d2 - e2 - f2
    a11, a12, a21, a22, b11, b12, b21, b22, r1, r2 = np.broadcast_arrays(a11, a12, a21, a22, b11, b12, b21, b22,
                                                                         r1, r2)
    shape = a11.shape
    scale = (_norm(h1) * _norm(p1) + _norm(h2) * _norm(p2) + _norm(h3) * _norm(p3) + _norm(h4) * _norm(p4)
             + np.abs(d1) + np.abs(d2))
    scale = np.broadcast_to(np.where(scale > 0.0, scale, 1.0), shape)
    det_a = a11 * a22 - a12 * a21
    det_b = b11 * b22 - b12 * b21
    size_a = a11**2 + a12**2 + a21**2 + a22**2
    size_b = b11**2 + b12**2 + b21**2 + b22**2
    # eliminate the block with the larger determinant (a near-zero block, however well shaped, is never taken);
    # swap means "eliminate theta1, solve theta2"
    swap = np.abs(det_a) > np.abs(det_b)
    coupled = np.maximum(np.abs(det_a), np.abs(det_b)) > GEOMETRY_TOLERANCE * np.maximum(size_a, size_b)
    # kept block P (its angle solved from the quartic), eliminated block Q
    block_a = np.stack([a11, a12, a21, a22], -1).reshape(shape + (2, 2))
    block_b = np.stack([b11, b12, b21, b22], -1).reshape(shape + (2, 2))
    if not swap.any():
        P, Q = block_a, block_b
    elif swap.all():
        P, Q = block_b, block_a
    else:
        P = np.where(swap[..., None, None], block_b, block_a)
        Q = np.where(swap[..., None, None], block_a, block_b)
    det_q = np.where(swap, det_a, det_b)
    adj_q = np.stack([np.stack([Q[..., 1, 1], -Q[..., 0, 1]], -1), np.stack([-Q[..., 1, 0], Q[..., 0, 0]], -1)], -2)
    r = np.stack([r1, r2], -1)
    u = np.einsum("...ij,...j->...i", adj_q, r)
    W = adj_q @ P
    S = np.swapaxes(W, -1, -2) @ W
    g = np.einsum("...ji,...j->...i", W, u)
    coefficients = (_dot(u, u) - det_q**2 + 0.5 * (S[..., 0, 0] + S[..., 1, 1]), -2 * g[..., 0], -2 * g[..., 1],
                    0.5 * (S[..., 0, 0] - S[..., 1, 1]), S[..., 0, 1])
    theta_p, found, double = _trig_quartic_roots(*coefficients)
    # every value of the kept angle solves the eliminated equation: that angle is free (its representative 0)
    identically = coupled & (np.maximum.reduce([np.abs(c) for c in coefficients])
                             <= GEOMETRY_TOLERANCE * (det_q**2 + _dot(u, u) + S[..., 0, 0] + S[..., 1, 1]))
    if identically.any():
        theta_p = np.where(identically[..., None], 0.0, theta_p)
        found = np.where(identically[..., None], np.arange(4) == 0, found)
    xp = np.stack([np.cos(theta_p), np.sin(theta_p)], -1)  # (..., 4, 2)
    xq = (u[..., None, :] - np.einsum("...ij,...sj->...si", W, xp)) / np.where(det_q != 0.0, det_q, 1.0)[..., None,
                                                                                                             None]
    theta_q = np.arctan2(xq[..., 1], xq[..., 0])
    theta1 = np.where(swap[..., None], theta_q, theta_p)
    theta2 = np.where(swap[..., None], theta_p, theta_q)

    if not coupled.all():
        # both blocks singular: A = a_u a_v^T, B = b_u b_v^T; the row combination orthogonal to b_u removes theta2
        # (and the one orthogonal to a_u removes theta1), leaving one harmonic equation per angle
        def left_null(m11, m12, m21, m22):
            c1, c2 = np.where(m11**2 + m21**2 >= m12**2 + m22**2, m11, m12), np.where(
                m11**2 + m21**2 >= m12**2 + m22**2, m21, m22)  # the block's column space direction
            return -c2, c1

        wb1, wb2 = left_null(b11, b12, b21, b22)
        wa1, wa2 = left_null(a11, a12, a21, a22)
        one = _harmonic(wb1 * a11 + wb2 * a21, wb1 * a12 + wb2 * a22, wb1 * r1 + wb2 * r2, scale)
        two = _harmonic(wa1 * b11 + wa2 * b21, wa1 * b12 + wa2 * b22, wa1 * r1 + wa2 * r2, scale)
        t1 = np.repeat(one.theta, 2, axis=-1)
        t2 = np.tile(two.theta, 2)
        ok = np.repeat(one.valid & one.exact, 2, axis=-1) & np.tile(two.valid & two.exact, 2)
        theta1 = np.where(coupled[..., None], theta1, t1)
        theta2 = np.where(coupled[..., None], theta2, t2)
        found = np.where(coupled[..., None], found, ok)
        rank_one = ~coupled & (one.degenerate | two.degenerate)
    else:
        rank_one = np.zeros(shape, dtype=bool)

    # Newton steps on the pair itself (the quartic squared it: its roots are good to about sqrt of the
    # rounding near a double root), then the residuals of both equations at each candidate
    ex = lambda x: x[..., None]  # noqa: E731
    for step in range(_NEWTON_STEPS + 1):
        c1, s1, c2, s2 = np.cos(theta1), np.sin(theta1), np.cos(theta2), np.sin(theta2)
        miss1 = ex(a11) * c1 + ex(a12) * s1 + ex(b11) * c2 + ex(b12) * s2 - ex(r1)
        miss2 = ex(a21) * c1 + ex(a22) * s1 + ex(b21) * c2 + ex(b22) * s2 - ex(r2)
        if step == _NEWTON_STEPS:
            break
        j11, j12 = ex(a12) * c1 - ex(a11) * s1, ex(b12) * c2 - ex(b11) * s2
        j21, j22 = ex(a22) * c1 - ex(a21) * s1, ex(b22) * c2 - ex(b21) * s2
        jac = j11 * j22 - j12 * j21
        usable = np.abs(jac) > 1e-6 * (j11**2 + j12**2 + j21**2 + j22**2)  # not at a double root
        inverse = np.where(usable, 1.0 / np.where(usable, jac, 1.0), 0.0)
        step1 = np.minimum(np.maximum((j22 * miss1 - j12 * miss2) * inverse, -1e-3), 1e-3)  # (np.clip is slow)
        step2 = np.minimum(np.maximum((j11 * miss2 - j21 * miss1) * inverse, -1e-3), 1e-3)
        theta1, theta2 = theta1 - step1, theta2 - step2
    miss = np.nan_to_num(_hypot(miss1, miss2) / ex(scale), nan=np.inf)
    exact = found & (miss <= _EXACT_PAIR)
    # a row without a root keeps its nearest candidate in slot 0
    nearest = np.argmin(miss, axis=-1)
    rank_one = rank_one | identically
    none = ~exact.any(axis=-1) & ~rank_one
    keep = exact.copy()
    keep[none, nearest[none]] = True

    # merge equal roots (a double root appears twice), keep distinct ones first
    gap1 = np.abs(wrap_angle(theta1[..., :, None] - theta1[..., None, :]))
    gap2 = np.abs(wrap_angle(theta2[..., :, None] - theta2[..., None, :]))
    same = (np.nan_to_num(gap1, nan=np.inf) <= DUPLICATE_TOLERANCE) & (np.nan_to_num(gap2, nan=np.inf)
                                                                         <= DUPLICATE_TOLERANCE)
    earlier = np.tril(np.ones((4, 4), dtype=bool), -1)
    duplicate = (same & earlier & keep[..., None, :]).any(axis=-1) & keep
    merged = duplicate.any(axis=-1) | (double & coupled)
    keep &= ~duplicate
    order = np.argsort(~keep, axis=-1, kind="stable")
    keep = np.take_along_axis(keep, order, -1)
    exact = np.take_along_axis(exact, order, -1) & keep
    theta1 = np.where(keep, np.take_along_axis(wrap_angle(theta1), order, -1), np.nan)
    theta2 = np.where(keep, np.take_along_axis(wrap_angle(theta2), order, -1), np.nan)
    decoupled_free = rank_one & ~identically
    if decoupled_free.any():
        theta1[..., 0] = np.where(decoupled_free, np.where(one.degenerate, 0.0, one.theta[..., 0]), theta1[..., 0])
        theta2[..., 0] = np.where(decoupled_free, np.where(two.degenerate, 0.0, two.theta[..., 0]), theta2[..., 0])
    keep[..., 0] |= rank_one
    return AngleQuadSolutions(theta1=theta1, theta2=theta2, valid=keep, exact=exact,
                              degenerate=np.asarray(rank_one), merged=np.asarray(merged))


# ---------------------------------------------------------------------------
# Subproblem 5 with a slide
# ---------------------------------------------------------------------------

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


def _trig_product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Coefficients (..., 5) over ``(1, cos, sin, cos 2t, sin 2t)`` of the product of two first-degree
    trigonometric polynomials given over ``(1, cos, sin)`` (..., 3)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a0 * b0 + (a1 * b1 + a2 * b2) / 2, a0 * b1 + a1 * b0, a0 * b2 + a2 * b0,
                     (a1 * b1 - a2 * b2) / 2, (a1 * b2 + a2 * b1) / 2], axis=-1)


def _trig_value(f: np.ndarray, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Value and derivative at ``theta`` (..., m) of trigonometric polynomials ``f`` (..., 5 or 3)."""
    c, s = np.cos(theta), np.sin(theta)
    value = f[..., 0, None] + f[..., 1, None] * c + f[..., 2, None] * s
    slope = -f[..., 1, None] * s + f[..., 2, None] * c
    if f.shape[-1] == 5:
        c2, s2 = np.cos(2 * theta), np.sin(2 * theta)
        value = value + f[..., 3, None] * c2 + f[..., 4, None] * s2
        slope = slope - 2 * f[..., 3, None] * s2 + 2 * f[..., 4, None] * c2
    return value, slope


# The slide within this cosine of normal to k2 (|b| at most this) is solved by the split (b taken as 0), else by
# the quartic; :func:`_refine_turn_slide` then finishes either. The quartic ``b**2 A2 - b A1 B2 + c A1**2`` tends
# to ``c A1**2`` as b -> 0: its roots pair up about |b| apart around the zeros of A1 (near-double roots, found to
# about eps / |b|), and ``s = -A1 / b`` divides that again by b, so s misses by about eps / b**2. The split misses
# by about |b|. The two meet at |b| = eps**(1/3), about 6e-6, where both miss by about 6e-6: well inside the
# reach of Newton's steps (a few, of at most 1e-3 each) on the undivided equations.
_SLIDE_NEARLY_NORMAL = 6e-6
_REFINE_STEPS, _REFINE_STEP = 4, 1e-3


def _refine_turn_slide(A1: np.ndarray, A2: np.ndarray, B2: np.ndarray, b: np.ndarray, c: float,
                       theta: np.ndarray, s: np.ndarray, active: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Newton steps on the undivided pair ``E1 = A1(theta) + b s``, ``E2 = A2(theta) + B2(theta) s + c s**2``.

    ``theta``, ``s`` and ``active`` are (..., 4); the coefficients (..., 3), ``b`` (...). The Jacobian
    ``[[A1', b], [A2' + B2' s, B2 + 2 c s]]`` stays regular as b -> 0 (it is singular only where two
    solutions meet), unlike the quartic's ``s = -A1 / b``. A step is taken only where it lowers ``|E1| + |E2|``
    and moves at most ``_REFINE_STEP`` (in theta and in s / S): a candidate that solves neither stays as it was.
    """
    def residual(t, x):
        (a1, a1_slope), (a2, a2_slope), (b2, b2_slope) = (_trig_value(f, t) for f in (A1, A2, B2))
        e1, e2 = a1 + b[..., None] * x, a2 + b2 * x + c * x * x
        return e1, e2, a1_slope, a2_slope + b2_slope * x, b2 + 2 * c * x

    bb = b[..., None]
    for _ in range(_REFINE_STEPS):
        e1, e2, j11, j21, j22 = residual(theta, s)
        det = j11 * j22 - bb * j21
        regular = np.abs(det) > 1e-9 * (np.abs(j11 * j22) + np.abs(bb * j21))
        safe = np.where(regular, det, 1.0)
        d_theta = (j22 * e1 - bb * e2) / safe
        d_s = (j11 * e2 - j21 * e1) / safe
        new_theta, new_s = theta - d_theta, s - d_s
        n1, n2 = residual(new_theta, new_s)[:2]
        better = active & regular & (np.abs(d_theta) <= _REFINE_STEP) & (np.abs(d_s) <= _REFINE_STEP) \
            & (np.abs(n1) + np.abs(n2) < np.abs(e1) + np.abs(e2))
        theta, s = np.where(better, new_theta, theta), np.where(better, new_s, s)
    return theta, s


def subproblem_5_prismatic(k2: ArrayLike, k: ArrayLike, p0: ArrayLike, p1: ArrayLike, p2: ArrayLike,
                           v: ArrayLike, slide_turns: bool) -> TurnSlideSolutions:
    """Subproblem 5 with one rotation replaced by a slide; up to 4 solutions ``(phi, theta, s)``.

    Solves ``p2 + s v = R(k2, phi) (p0 + R(k, theta) p1)`` (``slide_turns`` false: the slide is
    outside the rotation ``phi``) or ``p2 = R(k2, phi) (p0 + R(k, theta) p1 + s v)`` (``slide_turns``
    true). With ``L(theta) = p0 + R(k, theta) p1``, ``R(k2, phi)`` keeps the height along ``k2`` and
    the length, so a solution needs (slide outside, the inside case with the signs of the slide terms
    flipped and ``v`` moved onto ``L``)::

        E1:  k2.L(theta) - k2.p2 - s (k2.v)              = A1(theta) + b s       = 0
        E2:  ||L(theta)||**2 - ||p2 + s v||**2            = A2(theta) + B2(theta) s + c s**2 = 0

    ``A1``, ``A2`` and (inside) ``B2 = 2 v.L`` are trigonometric polynomials of degree 1 in theta
    (``||L||**2 = ||p0||**2 + ||p1||**2 + 2 p0.R(k, theta) p1``), ``c = -1`` outside and ``+1`` inside.

    * ``|b| = |k2.v| > 6e-6``: ``s = -A1 / b``, and ``b**2 A2 - b A1 B2 + c A1**2 = 0`` is a trigonometric
      quartic in theta (degree 2 in ``cos``, ``sin``). Its roots are those on the unit circle of a
      degree-4 polynomial in ``z = exp(i theta)`` (the companion matrix of subproblem 5), each refined
      by two Newton steps. With ``k ∥ k2`` the quartic drops to a quadratic: 2 roots.
    * ``|b| <= 6e-6`` (the slide normal, or nearly, to ``k2``): as if b were 0, ``A1(theta) = 0`` is a
      harmonic equation (two roots), and for each E2 is a quadratic in s (two roots): 4 in all.

    Every candidate then takes a few Newton steps on E1 and E2 themselves: as b -> 0 the quartic's
    roots pair up (near-double roots) and ``s = -A1 / b`` misses by about ``eps / b**2``, the split by
    about ``|b|``; the pair's Jacobian stays regular (see ``_SLIDE_NEARLY_NORMAL``).

    ``phi`` then follows by subproblem 1. This is the positioning problem of an RRP, RPR or PRR arm
    with skew axes: the slide is a line where subproblem 5 has a circle.

    Parameters
    ----------
    k2, k : array_like, shape (3,)
        Unit rotation axes through the origin.
    p0, p1, p2 : array_like, shape (..., 3)
        Offsets and the rotated point, broadcast against each other.
    v : array_like, shape (3,) or (..., 3)
        Unit sliding direction, one for all rows or one per row (a slide whose direction the target sets).
    slide_turns : bool
        Whether ``R(k2, phi)`` turns the slide (inside) or not (outside).

    Returns
    -------
    TurnSlideSolutions
        ``phi``, ``theta`` and ``s`` have shape (..., 4), the slots in no particular order.

    Notes
    -----
    Like subproblem 5 there is no least-squares candidate. Scale: ``S = ||p0|| + ||p1|| + ||p2||``;
    a candidate is ``exact`` when the vector equation holds to ``GEOMETRY_TOLERANCE * S``. Two roots
    are reported once, at their midpoint, with ``merged`` set (a tangent root, the edge of the
    workspace) when they are closer than ``DUPLICATE_TOLERANCE`` (in theta and in ``s / S``), or,
    for the quartic, closer than 1e-3 rad with the midpoint solving E2 (the quartic over ``b**2``) to
    ``DUPLICATE_TOLERANCE**2`` of the quartic's coefficients: near a triple root rounding splits a double root by far more than √ε. ``degenerate``: E1 and E2 do not depend on theta (``p1`` on ``k``, with the target
    reachable); the representative has ``theta = 0``. ``phi_free`` marks slots whose turned vector
    lies on ``k2`` (phi is then 0).

    Examples
    --------
    An RPR arm's point found again (one slot holds the generating values):

    >>> k2, k, v = np.array([0, 0, 1.0]), np.array([0.6, 0, 0.8]), np.array([0, 0.6, 0.8])
    >>> p0, p1 = np.array([0.3, 0.1, 0.2]), np.array([0.1, 0.4, 0.0])
    >>> def R(axis, t):
    ...     return np.cos(t) * np.eye(3) + np.sin(t) * np.cross(np.eye(3), axis) + (1 - np.cos(t)) * np.outer(axis, axis)
    >>> p2 = R(k2, 0.7) @ (p0 + R(k, -1.1) @ p1 + 0.25 * v)
    >>> sol = subproblem_5_prismatic(k2, k, p0, p1, p2, v, slide_turns=True)
    >>> found = np.stack([sol.phi, sol.theta, sol.s], axis=-1)[sol.valid]
    >>> bool(np.isclose(found, [0.7, -1.1, 0.25]).all(axis=-1).any())
    True
    """
    k2, k = _unit(k2, "k2"), _unit(k, "k")
    if np.ndim(v) == 1:
        v = _unit(v, "v")
    else:  # one sliding direction per row
        v = _points(v, "v")
        v = v / _norm(v)[..., None]
    p0, p1, p2 = (_points(p, name) for p, name in ((p0, "p0"), (p1, "p1"), (p2, "p2")))
    shape = np.broadcast_shapes(p0.shape, p1.shape, p2.shape, np.shape(v))[:-1]
    S = _norm(p0) + _norm(p1) + _norm(p2)
    S = np.broadcast_to(np.where(S > 0.0, S, 1.0), shape)
    # work in units of S: every coefficient below is then of order 1
    p0, p1, p2 = (np.broadcast_to(p / S[..., None], shape + (3,)) for p in (p0, p1, p2))
    v = np.broadcast_to(v, shape + (3,))
    fixed, perp, cross = _rotation_parts(k, p1)
    centre = p0 + fixed  # L(theta) = centre + cos perp + sin cross
    sign = 1.0 if slide_turns else -1.0
    b = sign * (v @ k2)  # (...)
    A1 = np.stack([centre @ k2 - p2 @ k2, perp @ k2, cross @ k2], axis=-1)
    A2 = np.stack([_dot(centre, centre) + _dot(perp, perp) - _dot(p2, p2), 2 * _dot(p0, perp),
                   2 * _dot(p0, cross)], axis=-1)
    if slide_turns:
        B2 = 2 * np.stack([_dot(centre, v), _dot(perp, v), _dot(cross, v)], axis=-1)
        c = 1.0
    else:
        B2 = np.zeros(shape + (3,))
        B2[..., 0] = -2 * _dot(p2, v)
        c = -1.0
    by_quartic = np.abs(b) > _SLIDE_NEARLY_NORMAL  # (...): else the slide is (nearly) normal to k2
    with np.errstate(invalid="ignore", divide="ignore"):
        quartic, quartic_scale = None, None
        if by_quartic.any():
            bq = np.where(by_quartic, b, 1.0)[..., None]
            F = bq * bq * np.pad(A2, [(0, 0)] * len(shape) + [(0, 2)]) - bq * _trig_product(A1, B2) \
                + c * _trig_product(A1, A1)
            scale = 1.0 + np.abs(F).sum(axis=-1)
            coefficients = tuple(np.moveaxis(F, -1, 0))
            theta, valid, double = _trig_quartic_roots(*coefficients)
            degenerate = _vanishes(*coefficients, scale)
            valid &= ~degenerate[..., None]
            theta = np.where(valid, theta, np.nan)
            theta[degenerate, 0], valid[degenerate, 0] = 0.0, True
            for _ in range(2):  # Newton on F(theta)
                value, slope = _trig_value(F, theta)
                step = np.where(np.abs(slope) > 1e-9 * scale[..., None], value / np.where(slope == 0, 1.0, slope),
                                0.0)
                theta = np.where(degenerate[..., None] | (np.abs(step) > 1e-3), theta, theta - step)
            s = -_trig_value(A1, theta)[0] / bq
            merged = double & ~degenerate  # a tangent root of the harmonic equation left, reported once
            # F = b**2 E2 with s = -A1 / b: the midpoint test below asks E2 (the length) to hold, not F
            quartic, quartic_scale = F, np.where(by_quartic, scale * b * b, -1.0)  # no residual merging elsewhere
        if not by_quartic.all():
            first = _harmonic(A1[..., 1], A1[..., 2], -A1[..., 0], np.ones(shape))
            split_degenerate = first.degenerate & first.exact[..., 0]
            roots = np.where(split_degenerate[..., None], np.array([0.0, np.nan]), first.theta)  # (..., 2)
            ok = first.valid & first.exact & ~(first.degenerate & ~split_degenerate)[..., None]
            linear, _ = _trig_value(B2, roots)
            constant, _ = _trig_value(A2, roots)
            discriminant = linear * linear - 4 * c * constant
            touching = np.abs(discriminant) <= 4 * _MERGE_RESIDUAL * (1.0 + linear * linear)
            root = np.sqrt(np.maximum(discriminant, 0.0))
            real = ok & ((discriminant >= 0) | touching)
            split_theta = np.repeat(roots, 2, axis=-1)
            split_s = np.stack([(-linear + root) / (2 * c), (-linear - root) / (2 * c)], axis=-1).reshape(shape + (4,))
            split_valid = np.stack([real, real & ~touching], axis=-1).reshape(shape + (4,))
            split_merged = (first.merged & ok[..., 0]) | (touching & ok).any(axis=-1)
            if quartic is None:
                theta, s, valid, merged, degenerate = split_theta, split_s, split_valid, split_merged, split_degenerate
            else:
                rows = ~by_quartic
                theta = np.where(rows[..., None], split_theta, theta)
                s = np.where(rows[..., None], split_s, s)
                valid = np.where(rows[..., None], split_valid, valid)
                merged = np.where(rows, split_merged, merged)
                degenerate = np.where(rows, split_degenerate, degenerate)
        # both eliminations lose digits as b -> 0 (the quartic's s, the split's b = 0): refine on E1, E2
        theta, s = _refine_turn_slide(A1, A2, B2, b, c, theta, s, valid & ~np.asarray(degenerate)[..., None])
        theta = wrap_angle(np.where(valid, theta, np.nan))
        s = np.where(valid, s, np.nan)
        # the same root twice (a tangent root): keep one, at the midpoint of the pair. A double root that
        # rounding splits along the circle splits symmetrically, so the midpoint is nearer than either half
        for later in range(1, 4):
            for earlier in range(later):
                gap = wrap_angle(theta[..., later] - theta[..., earlier])
                middle = wrap_angle(theta[..., earlier] + gap / 2)
                same = valid[..., later] & valid[..., earlier] & (np.abs(gap) <= DUPLICATE_TOLERANCE) \
                    & (np.abs(s[..., later] - s[..., earlier]) <= DUPLICATE_TOLERANCE)
                if quartic is not None:  # or a pair whose midpoint solves the quartic (a badly split double root)
                    at_middle = np.abs(_trig_value(quartic, middle[..., None])[0][..., 0])
                    same |= valid[..., later] & valid[..., earlier] & (np.abs(gap) <= 1e-3) \
                        & (at_middle <= _MERGE_RESIDUAL * quartic_scale)
                theta[..., earlier] = np.where(same, middle, theta[..., earlier])
                halfway = (s[..., earlier] + s[..., later]) / 2
                if quartic is not None:  # s = -A1 / b at the midpoint
                    halfway = np.where(by_quartic, -_trig_value(A1, middle[..., None])[0][..., 0]
                                       / np.where(by_quartic, b, 1.0), halfway)
                s[..., earlier] = np.where(same, halfway, s[..., earlier])
                merged |= same
                valid[..., later] &= ~same
        theta = np.where(valid, theta, np.nan)
        s = np.where(valid, s, np.nan)
        L = centre[..., None, :] + _rotate_points(k, np.nan_to_num(theta), p1[..., None, :]) - fixed[..., None, :]
        slide = s[..., None] * v[..., None, :]
        turned, onto = (L + slide, np.broadcast_to(p2[..., None, :], L.shape)) if slide_turns \
            else (L, p2[..., None, :] + slide)
        phi, _, phi_free = _rotate_onto(axis_frame(k2), np.nan_to_num(turned), np.nan_to_num(onto),
                                        np.ones(shape)[..., None])
        miss = _norm(onto - _rotate_points(k2, phi, turned))
    nan = np.nan
    return TurnSlideSolutions(
        phi=np.where(valid, phi, nan), theta=np.where(valid, theta, nan), s=np.where(valid, s * S[..., None], nan),
        valid=valid, exact=valid & (miss <= GEOMETRY_TOLERANCE), degenerate=np.asarray(degenerate), merged=merged,
        phi_free=valid & phi_free)
