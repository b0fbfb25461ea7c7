"""Roots of the scalar equations the subproblems reduce to.

* The harmonic equation ``a cos(theta) + b sin(theta) = c`` (:func:`_harmonic`): subproblems 3 and 4, the
  two-link elbow, the degenerate rows of the quartic and of subproblem 6, and the turn-slide split; on floats,
  where its answer is clear, :func:`_harmonic_clear` (the one-pose paths).
* The quadratic ``A t² + B t + C = 0`` with a rounding band for its double root (:func:`quadratic_roots`): the
  cylindrical positioners' slides.
* The trigonometric quartic ``alpha0 + alpha1 cos t + beta1 sin t + alpha2 cos 2t + beta2 sin 2t = 0``
  (:func:`_trig_quartic_roots`, :func:`_vanishes`): subproblems 5 and 6 and the turn-slide subproblem 5, through
  the companion matrix of a quartic in ``exp(i t)``.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from ..._angles import wrap_angle, wrap_float
from ..._tolerances import GEOMETRY_TOLERANCE, ROUNDING_TOLERANCE
from ._records import _MERGE_COS_GAP, AngleSolutions
from ._vectors import _hypot, _pair


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


def _harmonic_clear(a: float, b: float, c: float, scale: float, margin: float,
                    out_of_reach: bool = False) -> tuple[float, float] | None:
    """:func:`_harmonic` on floats where its answer is clear, for the one-pose paths (numpy's per-call cost
    would exceed the arithmetic): the two roots ``phi + half`` and ``phi - half``, or None where a quantity is
    within ``margin`` times its band of one of :func:`_harmonic`'s thresholds (degenerate, exact, merged).

    With ``out_of_reach``, a ``c`` clearly out of reach gives :func:`_harmonic`'s least-squares root and NaN
    (its empty second slot); without it, None.
    """
    tol = GEOMETRY_TOLERANCE * scale
    rho = math.sqrt(a * a + b * b)
    excess = abs(c) - rho
    phi = math.atan2(b, a)
    if out_of_reach and rho > margin * tol and excess > margin * tol:
        return wrap_float(phi + math.atan2(0.0, c)), math.nan
    if not (rho > margin * tol and -excess > margin * (rho * _MERGE_COS_GAP + tol)):
        return None
    half = math.atan2(math.sqrt(-excess * (rho + abs(c))), c)
    return wrap_float(phi + half), wrap_float(phi - half)


#: A quadratic's leading coefficient at most this is linear (one root), and a linear one's B at most this has none;
#: this times the scale squared floors the discriminant's rounding band. :func:`quadratic_roots` and its float form
#: :func:`_quadratic_clear` read it.
_QUADRATIC_NEGLIGIBLE = 1e-12


def quadratic_roots(A: np.ndarray | float, B: np.ndarray, C: np.ndarray, scale: float
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Real roots of ``A t² + B t + C = 0`` per row, B and C (N,), A (N,) or a number: (N, 2) roots, their
    validity (N, 2), and merged flags (N,) where the two are one (the midpoint, in the first slot).

    A row with ``|A| <=`` :data:`_QUADRATIC_NEGLIGIBLE` is linear: one root. ``scale`` is the length the
    coefficients are built from (t is a length): it floors the discriminant's rounding band, within which the
    roots are one.
    """
    A = np.broadcast_to(np.asarray(A, dtype=float), B.shape)
    roots = np.full(B.shape + (2,), np.nan)
    valid = np.zeros(B.shape + (2,), dtype=bool)
    merged = np.zeros(B.shape, dtype=bool)
    linear = np.abs(A) <= _QUADRATIC_NEGLIGIBLE
    with np.errstate(divide="ignore", invalid="ignore"):
        roots[linear, 0] = -C[linear] / B[linear]
        valid[linear, 0] = np.abs(B[linear]) > _QUADRATIC_NEGLIGIBLE
        quad = ~linear
        discriminant = B[quad] ** 2 - 4 * A[quad] * C[quad]
        # the discriminant's rounding: a double root only within it. (SINGULARITY_TOLERANCE here merged roots
        # ±1e-10 of the scale apart and kept the + one: the cylindrical arm's radial slide at −1e-10 came back
        # at +1e-10 with joint 1 turned by π.)
        tolerance = ROUNDING_TOLERANCE * (B[quad] ** 2 + np.abs(4 * A[quad] * C[quad])
                                          + scale ** 2 * _QUADRATIC_NEGLIGIBLE)
        touching = np.abs(discriminant) <= tolerance
        root = np.sqrt(np.maximum(discriminant, 0.0)) * ~touching  # a double root: the midpoint
        roots[quad, 0] = (-B[quad] + root) / (2 * A[quad])
        roots[quad, 1] = (-B[quad] - root) / (2 * A[quad])
        valid[quad, 0] = discriminant >= -tolerance
        valid[quad, 1] = (discriminant >= -tolerance) & ~touching
        merged[quad] = touching
    return roots, valid, merged


def _quadratic_clear(A: float, B: float, C: float, scale: float, margin: float) -> tuple[float, float] | None:
    """:func:`quadratic_roots` on floats where its answer is clear, for the one-pose paths: the two roots in its
    slot order, or one and NaN (a linear row), or None where a quantity is within ``margin`` times its band of one
    of its thresholds (linear or not, a double root) or the roots are not real (the array path words that)."""
    if abs(A) * margin <= _QUADRATIC_NEGLIGIBLE:
        return (-C / B, math.nan) if abs(B) > margin * _QUADRATIC_NEGLIGIBLE else None
    if not abs(A) > margin * _QUADRATIC_NEGLIGIBLE:
        return None
    discriminant = B * B - 4 * A * C
    tolerance = ROUNDING_TOLERANCE * (B * B + abs(4 * A * C) + scale * scale * _QUADRATIC_NEGLIGIBLE)
    if not discriminant > margin * tolerance:
        return None
    root = math.sqrt(discriminant)
    return (-B + root) / (2 * A), (-B - root) / (2 * A)


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
