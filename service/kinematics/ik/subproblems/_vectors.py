"""Checked inputs, axis frames and the small vector algebra the subproblems share.

* Input checks at the subproblems' boundary: constant unit axes (``_unit``, remembered by value in a bounded
  cache), batches of points (``_points``) and distances (``_distances``).
* Coordinates of points in an axis frame (:func:`.._screws.axis_frame`, the right-handed frame ``[e1, e2, k]``
  around an axis).
* Vector helpers: row-wise dot products and norms, the cross product of two 3-vectors, two-slot candidates,
  the parts of a point that a rotation keeps and turns, and the subproblem 1 core ``_rotate_onto`` that
  subproblems 1, 2, 5 and the turn-slide subproblem 5 all end with.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from ..._cache import AxisCache
from ..._errors import InvalidInputError
from ..._forward import cross
from ..._angles import wrap_angle, wrap_float
from ..._tolerances import GEOMETRY_TOLERANCE, ORTHONORMAL_TOLERANCE


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
    if key is not None:
        unit.setflags(write=False)
        _UNITS.keep(key, unit)
    return unit


_UNITS = AxisCache()


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


def _rotation_parts(k: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``R(k, theta) p = fixed + cos(theta) perp + sin(theta) cross`` for points ``p`` (..., 3)."""
    fixed = (p @ k)[..., None] * k
    return fixed, p - fixed, cross(k, p)


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


def _rotate_onto_clear(p: tuple[float, ...], q: tuple[float, ...], margin: float,
                       free_below: float = GEOMETRY_TOLERANCE, scale: float | None = None) -> float | None:
    """:func:`_rotate_onto` on floats where its answer is clear, for the one-pose paths (numpy's per-call cost
    would exceed the arithmetic): ``p`` and ``q`` as ``(x, y, z, radius, length)`` in the axis frame; theta, or
    None where either lies within ``margin`` times ``free_below`` (relative to the longer one) of the axis
    (degenerate). With ``scale`` (the length a caller of :func:`_rotate_onto` passes), the band is ``free_below``
    times it, and an answer that is not clearly exact (its radii or heights apart by more than that band over
    ``margin``) is None too."""
    px, py, pz, radius_p, length_p = p
    qx, qy, qz, radius_q, length_q = q
    tol = free_below * (scale if scale is not None else length_p if length_p > length_q else length_q)
    if not (radius_p > margin * tol and radius_q > margin * tol):
        return None
    if scale is not None and not (margin * abs(radius_p - radius_q) <= tol and margin * abs(pz - qz) <= tol):
        return None
    return wrap_float(math.atan2(px * qy - py * qx, px * qx + py * qy))
