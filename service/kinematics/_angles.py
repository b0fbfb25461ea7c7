"""Angles wrapped to (−π, π]: the one angle wrap of the core, on arrays (:func:`wrap_angle`) and on floats
(:func:`wrap_float`, :func:`wrap_any_float`, bit for bit the same), for the scalar one-pose paths."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

_TWO_PI = 2.0 * np.pi

__all__ = ["wrap_angle", "wrap_any_float", "wrap_float"]


def wrap_angle(x: ArrayLike) -> np.float64 | np.ndarray:
    """Wrap angles to ``(-pi, pi]``: the one angle wrap of the core.

    Values already in ``(-pi, pi]`` are returned unchanged, bit for bit.
    ``-pi`` maps to ``pi``. NaN stays NaN; infinities become NaN. Angles within
    one turn of the range (``|x| < 3 pi``, what sums of two wrapped angles give)
    take one exact add or subtract of ``2 pi``; only others pay for a modulo.

    Parameters
    ----------
    x : float or array_like
        Radians, any shape.

    Returns
    -------
    numpy.float64 (a float) for a scalar, or ndarray of the same shape

    Examples
    --------
    >>> float(wrap_angle(3 * np.pi / 2)) == -np.pi / 2
    True
    >>> wrap_angle([-np.pi, 0.5, 100.0]).round(6).tolist() == [round(np.pi, 6), 0.5, round(100.0 - 32 * np.pi, 6)]
    True
    """
    a = np.asarray(x, dtype=np.float64)
    # For |a| <= 3π (3π is exact in floating point) a ∓ 2π is exact (Sterbenz), so it lands in (−π, π].
    wrapped = a - (_TWO_PI * (a > np.pi) - _TWO_PI * (a <= -np.pi))  # a − 0.0 keeps a −0.0
    far = np.abs(a) >= 3.0 * np.pi  # infinities too
    if far.any():
        # np.mod is exact here, and its remainder a multiple of ulp(2π), so it never rounds up to a full turn.
        with np.errstate(invalid="ignore"):
            wrapped = np.where(far, np.pi - np.mod(np.pi - a, _TWO_PI), wrapped)
    return wrapped[()]  # a 0-d result as a numpy float, as numpy's own functions return it


_PI, _THREE_PI = math.pi, 3.0 * math.pi


def wrap_float(theta: float) -> float:
    """:func:`wrap_angle` of one float in (−3π, 3π] (a sum of two wrapped angles), bit for bit, on floats."""
    if theta > _PI:
        return theta - _TWO_PI
    if theta <= -_PI:
        return theta + _TWO_PI
    return theta


def wrap_any_float(theta: float) -> float:
    """:func:`wrap_angle` of one float of any size (as :func:`wrap_float` within three half-turns)."""
    if -_THREE_PI < theta < _THREE_PI:
        return wrap_float(theta)
    return _PI - (_PI - theta) % _TWO_PI
