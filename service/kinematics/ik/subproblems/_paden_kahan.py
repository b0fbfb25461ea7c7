"""Paden-Kahan subproblems 1-3 and IK-Geo subproblem 4: one or two angles about intersecting axes.

Subproblem 1 turns a point onto another, 2 turns a point about two intersecting axes (also in the chain form
``R(k1, theta1) R(k2, theta2) p = q``), 3 reaches a distance and 4 a height. Subproblems 3 and 4 and the planar
two-link elbow (subproblem 3 in the plane) reduce to the harmonic equation of :mod:`._roots`.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from ..._errors import InvalidInputError
from ..._angles import wrap_angle, wrap_float
from ..._tolerances import GEOMETRY_TOLERANCE
from .._screws import axis_frame
from ._records import (_GAP_PER_ERROR, _GAP_ROUNDING, _MERGE_SIN_SQUARED, _NEAR_TANGENT_GAP, AnglePairSolutions,
                       AngleSolutions)
from ._roots import _harmonic
from ._vectors import _coords, _cross3, _distances, _hypot, _norm, _pair, _points, _rotate_onto, _unit


def subproblem_1(k: ArrayLike, p: ArrayLike, q: ArrayLike, free_below: ArrayLike | None = None,
                 scale: float | None = None) -> AngleSolutions:
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
    scale : float, optional
        The length ``L`` the tolerances are relative to; by default ``max(||p||, ||q||)``. A positioner passes
        its arm's size: a point at the axis's origin and a target there (both ~0, one of them rounding dust) are
        then judged against the arm, not against the dust.

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
    theta, exact, degenerate = _rotate_onto(axis_frame(k), p, q, None if scale is None else np.float64(scale),
                                            free_below=free_below)  # all of the batch shape
    return AngleSolutions(
        theta=theta[..., None],
        valid=np.ones(theta.shape + (1,), dtype=bool),
        exact=exact[..., None],
        degenerate=np.asarray(degenerate),
        merged=np.zeros(theta.shape, dtype=bool),
    )


def subproblem_2(k1: ArrayLike, k2: ArrayLike, p: ArrayLike, q: ArrayLike, *, error: ArrayLike = 0.0
                 ) -> AnglePairSolutions:
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
    error : array_like, shape (...), optional
        How far (length units) ``p`` and ``q`` may be from the vectors the caller means, beyond their rounding
        (which is counted here): two crossings that an error that size could have split from a tangency are
        one root, ``merged``.

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
    then ``merged``. A larger gap up to ``sqrt(GEOMETRY_TOLERANCE)`` (with the
    norms as close, relative to L) is a tangency that an error of the inputs
    split (an angle found upstream at a double root, such as a stretched
    elbow, carries the square root of its inputs' error): the closest pair is
    the touching root, ``merged`` but not ``exact``, for the caller to refine
    and verify, never a proof that there is no solution. ``theta1`` is free (degenerate, representative 0) when
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
    merge_below = np.maximum(_MERGE_SIN_SQUARED * rho, _GAP_ROUNDING)
    if np.any(error):  # and within what the inputs' error can make of a tangency
        merge_below = np.maximum(merge_below, _GAP_PER_ERROR * np.asarray(error) / np.where(scale > 0.0, scale, 1.0))
    close = g <= merge_below * rho
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
        near_miss = ~meet & (gap <= _NEAR_TANGENT_GAP) & (np.abs(norm_p - norm_q) <= _NEAR_TANGENT_GAP * scale)
        merged = (touch | near_miss) & ~degenerate
    else:
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
    return np.where(rho1 <= rho2, _circle_gap(rho1, beta_sin), _circle_gap(rho2, alpha_sin))


def _circle_gap(rho, offset):
    """``rho**2 - offset**2`` as ``(rho - |offset|) (rho + |offset|)``, on floats or arrays: :func:`_crossing_gap`
    on the circle of radius ``rho``, the crossings' offset ``offset`` from the axes' plane."""
    return (rho - abs(offset)) * (rho + abs(offset))


def _subproblem_2_chain_clear(p: tuple[float, ...], q: tuple[float, ...], cos: float, sin: float, sin2: float,
                              free_below: float, margin: float, error: float = 0.0
                              ) -> tuple[tuple[float, float], tuple[float, float] | None] | None:
    """:func:`subproblem_2_chain` on floats where its answer is clear, for the one-pose paths (numpy's per-call
    cost would exceed the arithmetic): :func:`subproblem_2` with ``theta1`` negated.

    ``p`` (the chain's goal) is ``(p1, pn, d1, radius_p, norm_p)`` and ``q`` (its start) ``(q2, qn, e2, radius_q,
    norm_q)``, as :func:`subproblem_2` names them; ``cos``, ``sin`` and ``sin2`` are ``k1 . k2``, ``||k1 x k2||``
    and its square as :func:`subproblem_2` computes them; ``free_below`` the radius (relative to the vectors'
    size) at or below which the caller holds a joint free, ``error`` :func:`subproblem_2`'s. Returns the two
    ``(theta1, theta2)`` slots, the +gamma crossing first; where the cones clearly miss (beyond a near tangency,
    :data:`._records._NEAR_TANGENT_GAP`, that :func:`subproblem_2` reports merged) the least-squares pair and
    None; and None where a quantity is within ``margin`` times its band of one of :func:`subproblem_2`'s
    thresholds (a free joint, norms that differ, crossings that merge).
    """
    p1, pn, d1, radius_p, norm_p = p
    q2, qn, e2, radius_q, norm_q = q
    size = norm_p if norm_p > norm_q else norm_q
    tol, free = GEOMETRY_TOLERANCE * size, free_below * size
    if not (radius_p > margin * free and radius_q > margin * free and abs(norm_p - norm_q) * margin <= tol):
        return None
    h1, h2 = p1 / norm_p, q2 / norm_q
    rho1, rho2 = radius_p / norm_p, radius_q / norm_q
    alpha, beta = (h1 - cos * h2) / sin2, (h2 - cos * h1) / sin2
    if rho1 <= rho2:
        rho, g = rho1, _circle_gap(rho1, beta * sin)
    else:
        rho, g = rho2, _circle_gap(rho2, alpha * sin)
    merge_below = max(_MERGE_SIN_SQUARED * rho, _GAP_ROUNDING, _GAP_PER_ERROR * error / size)
    atan2, wrap = math.atan2, wrap_float
    s1, c1, s2, c2 = -beta * pn, beta * d1, alpha * qn, alpha * e2
    if not g > margin * merge_below * rho:
        if -g > 2 * margin * _NEAR_TANGENT_GAP * (rho1 + rho2):
            return (wrap(-atan2(s1, c1)), wrap(atan2(s2, c2))), None
        return None
    gamma = math.sqrt(g) / sin
    t1, u1, t2, u2 = gamma * d1, gamma * pn, gamma * e2, gamma * qn
    return ((wrap(-atan2(s1 + t1, c1 + u1)), wrap(atan2(s2 - t2, c2 + u2))),
            (wrap(-atan2(s1 - t1, c1 - u1)), wrap(atan2(s2 + t2, c2 - u2))))


def subproblem_2_chain(k1: ArrayLike, k2: ArrayLike, p: ArrayLike, q: ArrayLike, *, error: ArrayLike = 0.0
                       ) -> AnglePairSolutions:
    """Paden-Kahan 2, chain form: solve ``R(k1, theta1) R(k2, theta2) p = q``; else least squares.

    This is :func:`subproblem_2` applied to ``R(k1, -theta1) q = R(k2, theta2) p``.
    It minimises the same residual, because rotations preserve length. Flags,
    slots and tolerances are as in :func:`subproblem_2`. In this form
    ``theta2`` is free when ``p`` lies on ``k2``, and ``theta1`` is free when
    ``q`` lies on ``k1``. ``error`` is :func:`subproblem_2`'s.

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
    sol = subproblem_2(k1, k2, q, p, error=error)
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
    return _harmonic(*_distance_equation(*_coords(p, frame), *_coords(q, frame), delta))


def _distance_equation(px, py, pz, qx, qy, qz, delta):
    """Subproblem 3 as the harmonic equation ``a cos(theta) + b sin(theta) = c``: ``(a, b, c, scale)`` from the
    coordinates of ``p`` and ``q`` in the axis frame, on floats or arrays (see :func:`subproblem_3`)."""
    rp2 = px * px + py * py
    rq2 = qx * qx + qy * qy
    delta2 = delta * delta
    c = 0.5 * (rp2 + rq2 + (pz - qz) ** 2 - delta2)
    scale = rp2 + rq2 + pz * pz + qz * qz + delta2
    return px * qx + py * qy, px * qy - py * qx, c, scale


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
