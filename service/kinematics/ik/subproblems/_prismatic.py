"""The prismatic subproblems: a slide to a distance or a plane, and subproblem 5 with a slide.

:func:`prismatic_to_distance` and :func:`prismatic_to_plane` are the line analogues of subproblems 3 and 4.
:func:`subproblem_5_prismatic` (turn-turn-slide) is subproblem 5 with one circle replaced by a line: a
trigonometric quartic (:mod:`._roots`) or, with the slide normal to the axis, a harmonic equation and a
quadratic, each finished by Newton steps on the undivided pair.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from ..._angles import wrap_angle
from ..._tolerances import DUPLICATE_TOLERANCE, GEOMETRY_TOLERANCE
from .._screws import axis_frame, rotate_about
from ._records import _MERGE_RESIDUAL, DisplacementSolutions, TurnSlideSolutions
from ._roots import _harmonic, _trig_quartic_roots, _vanishes
from ._vectors import (
    _coords,
    _distances,
    _dot,
    _hypot,
    _norm,
    _pair,
    _points,
    _rotate_onto,
    _rotation_parts,
    _unit,
)


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


def _slide_to_distance_clear(p: tuple[float, ...], v: tuple[float, ...], q: tuple[float, ...], delta: float,
                             margin: float) -> tuple[float, float] | None:
    """:func:`prismatic_to_distance` on floats (p, v, q three floats each) where its answer is clear, for the
    one-pose paths: its two roots in its slot order, or None where the roots are within ``margin`` times its band
    of merging, or the distance is not clearly reached (the array path words that)."""
    w = (p[0] - q[0], p[1] - q[1], p[2] - q[2])
    b = v[0] * w[0] + v[1] * w[1] + v[2] * w[2]  # along the line; e: the distance from it
    e = math.sqrt((w[0] - b * v[0]) ** 2 + (w[1] - b * v[1]) ** 2 + (w[2] - b * v[2]) ** 2)
    scale = math.hypot(e, b) + delta
    excess = e - delta
    if not -excess > margin * max(_MERGE_RESIDUAL, GEOMETRY_TOLERANCE) * scale:
        return None
    root = math.sqrt(-excess * (delta + e))
    return root - b, -b - root


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
        L = centre[..., None, :] + rotate_about(k, np.nan_to_num(theta), p1[..., None, :]) - fixed[..., None, :]
        slide = s[..., None] * v[..., None, :]
        turned, onto = (L + slide, np.broadcast_to(p2[..., None, :], L.shape)) if slide_turns \
            else (L, p2[..., None, :] + slide)
        phi, _, phi_free = _rotate_onto(axis_frame(k2), np.nan_to_num(turned), np.nan_to_num(onto),
                                        np.ones(shape)[..., None])
        miss = _norm(onto - rotate_about(k2, phi, turned))
    nan = np.nan
    return TurnSlideSolutions(
        phi=np.where(valid, phi, nan), theta=np.where(valid, theta, nan), s=np.where(valid, s * S[..., None], nan),
        valid=valid, exact=valid & (miss <= GEOMETRY_TOLERANCE), degenerate=np.asarray(degenerate), merged=merged,
        phi_free=valid & phi_free)
