"""IK-Geo subproblem 5: three angles about three axes, ``p0 + R(k1, t1) p1 = R(k2, t2) (p2 + R(k3, t3) p3)``.

Pieper's quartic for a 3R positioner whose axes are skew: two scalar conditions linear in two unit vectors,
eliminated to a trigonometric quartic (:mod:`._roots`), polished by Newton steps; the middle angle by
subproblem 1.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..._angles import wrap_angle
from ..._tolerances import DUPLICATE_TOLERANCE, GEOMETRY_TOLERANCE
from .._screws import axis_frame, rotate_about
from ._records import AngleTripleSolutions
from ._roots import _trig_quartic_roots, _vanishes
from ._vectors import _dot, _norm, _points, _rotate_onto, _rotation_parts, _unit


def _inverse_2x2(A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(inverse, determinant)`` of 2 × 2 matrices (..., 2, 2); the inverse is NaN where the determinant is 0."""
    det = A[..., 0, 0] * A[..., 1, 1] - A[..., 0, 1] * A[..., 1, 0]
    adjugate = np.empty_like(A)
    adjugate[..., 0, 0], adjugate[..., 1, 1] = A[..., 1, 1], A[..., 0, 0]
    adjugate[..., 0, 1], adjugate[..., 1, 0] = -A[..., 0, 1], -A[..., 1, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        return adjugate / det[..., None, None], det


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
    L = p0[..., None, :] + rotate_about(k1, theta1, p1[..., None, :])
    M = p2[..., None, :] + rotate_about(k3, theta3, p3[..., None, :])
    theta2, _, _ = _rotate_onto(axis_frame(k2), np.nan_to_num(M), np.nan_to_num(L), S[..., None])
    miss = _norm(L - rotate_about(k2, theta2, M))
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
