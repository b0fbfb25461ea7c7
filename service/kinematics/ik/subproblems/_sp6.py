"""IK-Geo subproblem 6: two angles from two equations linear in their cosines and sines.

``h1.R(k1, theta1) p1 + h2.R(k2, theta2) p2 = d1`` and ``h3.R(k1, theta1) p3 + h4.R(k2, theta2) p4 = d2``:
eliminated to a trigonometric quartic (:mod:`._roots`), or, when both blocks are singular, split into two
harmonic equations; every root polished by Newton steps on the pair itself.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..._angles import wrap_angle
from ..._tolerances import DUPLICATE_TOLERANCE, GEOMETRY_TOLERANCE
from .._screws import axis_frame
from ._records import AngleQuadSolutions
from ._roots import _harmonic, _trig_quartic_roots
from ._vectors import _coords, _dot, _hypot, _norm, _points, _unit


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
