"""The paper's two kinematic functions, and the input checks of the Assur modules.

* :func:`angle_function`: the paper's Fig. 2, the angle of a plane vector and its first two time derivatives.
* :func:`distance_function`: the paper's Fig. 3, the distance between two moving points and its first two time
  derivatives.

Both are the building blocks of the RRR group and the SCARA of :mod:`._assur`, which re-exports them; its module
docstring gives the paper, the corrected misprints (item 7 is Fig. 2's) and the conventions (units, ``d``/``dd``
derivative suffixes, batch shapes) that hold here too. The ``_check_*`` functions validate at the boundary for
both modules and raise :class:`~service.kinematics._errors.InvalidInputError`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._errors import InvalidInputError
from ._tolerances import GEOMETRY_TOLERANCE

__all__ = [
    "AngleFunctionResult",
    "DistanceFunctionResult",
    "angle_function",
    "distance_function",
]


# --------------------------------------------------------------------------
# Validation at the boundary
# --------------------------------------------------------------------------


def _check_finite_array(value, name: str, last_dim: int | None) -> np.ndarray:
    """Return ``value`` as a finite float64 array whose last axis is ``last_dim``."""
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"{name} must be numeric: {exc}", location=(name,)) from None
    if last_dim is not None and (array.ndim == 0 or array.shape[-1] != last_dim):
        raise InvalidInputError(
            f"{name} must have shape (..., {last_dim}), got shape {array.shape}",
            location=(name,),
        )
    if not np.all(np.isfinite(array)):
        raise InvalidInputError(f"{name} must contain only finite values", location=(name,))
    return array


def _check_length(value, name: str) -> float:
    """Return a link length as a positive finite float."""
    try:
        length = float(value)
    except (TypeError, ValueError):
        raise InvalidInputError(
            f"{name} must be a positive number, got {value!r}", location=(name,)
        ) from None
    if not np.isfinite(length) or length <= 0.0:
        raise InvalidInputError(f"{name} must be a positive number, got {length}", location=(name,))
    return length


def _check_assembly_mode(assembly_mode) -> int:
    """Return the assembly mode, 1 (φ = θ + β) or 2 (φ = θ - β)."""
    if isinstance(assembly_mode, (bool, np.bool_)) or assembly_mode not in (1, 2):
        raise InvalidInputError(
            f"assembly_mode must be 1 (phi = theta + beta) or 2 (phi = theta - beta), "
            f"got {assembly_mode!r}",
            location=("assembly_mode",),
        )
    return int(assembly_mode)


def _check_tolerance(value, name: str) -> float:
    tolerance = float(value)
    if not np.isfinite(tolerance) or tolerance < 0.0:
        raise InvalidInputError(f"{name} must be a non-negative number, got {value!r}", location=(name,))
    return tolerance


# --------------------------------------------------------------------------
# Fig. 2: angle function
# --------------------------------------------------------------------------


@dataclass(frozen=True)
class AngleFunctionResult:
    """Angle of a plane vector and its time derivatives (paper Fig. 2).

    Attributes
    ----------
    theta : ndarray, shape (...)
        ``atan2(y, x)`` in (-π, π] [rad]; NaN for the null vector.
    thetad : ndarray, shape (...)
        θ' [rad/s]; NaN for the null vector.
    thetadd : ndarray, shape (...)
        θ'' [rad/s²]; NaN for the null vector.
    is_null : ndarray of bool, shape (...)
        True where the vector is null (its norm is within the tolerance of 0)
        and has no angle.
    """

    theta: np.ndarray
    thetad: np.ndarray
    thetadd: np.ndarray
    is_null: np.ndarray


def angle_function(
    x, y, xd, yd, xdd, ydd, *, tolerance: float = GEOMETRY_TOLERANCE
) -> AngleFunctionResult:
    """Angle of the vector (x, y) from +X, and its first two time derivatives.

    The paper's Fig. 2, corrected (``textbook.md`` §4.2 item 1, errata §10
    item 7)::

        θ   = atan2(y, x)
        θ'  = (y'x - yx') / (x² + y²)
        θ'' = [(y''x - yx'')(x² + y²) - (y'x - yx')·2(xx' + yy')] / (x² + y²)²

    The paper's case split on the signs of x and y is exactly atan2. Its x = 0
    branch is not needed: for x = 0 and y ≠ 0 the formulas above reduce to
    ``θ' = -x'/y`` and ``θ'' = -x''/y + 2x'y'/y²`` for both signs of y, which
    are the corrected branch formulas.

    Parameters
    ----------
    x, y : array-like, shape (...)
        Components of the vector [length].
    xd, yd : array-like, shape (...)
        Their first time derivatives [length/s].
    xdd, ydd : array-like, shape (...)
        Their second time derivatives [length/s²].
    tolerance : float, optional (default: GEOMETRY_TOLERANCE)
        The vector is null, and has no angle, where ``hypot(x, y) <= tolerance``
        (in the caller's length unit). Callers with a natural length scale L
        pass ``SINGULARITY_TOLERANCE * L``.

    Returns
    -------
    result : AngleFunctionResult
        ``theta, thetad, thetadd`` of the broadcast shape, NaN where
        ``is_null``.

    Examples
    --------
    A vector turning at 1 rad/s about the origin, seen on the -Y axis:

    >>> r = angle_function(0.0, -2.0, 2.0, 0.0, 0.0, 2.0)
    >>> print(f"{r.theta:.6f} {r.thetad:.6f} {r.thetadd:.6f} {r.is_null}")
    -1.570796 1.000000 0.000000 False
    >>> bool(angle_function(0.0, 0.0, 1.0, 0.0, 0.0, 0.0).is_null)
    True
    """
    x, y, xd, yd, xdd, ydd = np.broadcast_arrays(
        *(
            _check_finite_array(v, n, None)
            for v, n in zip((x, y, xd, yd, xdd, ydd), ("x", "y", "xd", "yd", "xdd", "ydd"))
        )
    )
    tolerance = _check_tolerance(tolerance, "tolerance")
    r2 = x * x + y * y
    is_null = np.sqrt(r2) <= tolerance
    r2_safe = np.where(is_null, 1.0, r2)

    cross_d = yd * x - y * xd  # y'x - yx'
    cross_dd = ydd * x - y * xdd  # y''x - yx''  (printed as y'x - yx')
    dot_d = x * xd + y * yd  # xx' + yy'

    theta = np.arctan2(y, x)
    thetad = cross_d / r2_safe
    thetadd = (cross_dd * r2_safe - cross_d * 2.0 * dot_d) / (r2_safe * r2_safe)

    nan = np.nan
    return AngleFunctionResult(
        theta=np.where(is_null, nan, theta),
        thetad=np.where(is_null, nan, thetad),
        thetadd=np.where(is_null, nan, thetadd),
        is_null=is_null,
    )


# --------------------------------------------------------------------------
# Fig. 3: distance function
# --------------------------------------------------------------------------


@dataclass(frozen=True)
class DistanceFunctionResult:
    """Distance between two moving points and its time derivatives (paper Fig. 3).

    Attributes
    ----------
    l : ndarray, shape (...)
        ``|AB|`` [length].
    ld : ndarray, shape (...)
        l' [length/s]; NaN where ``is_zero``.
    ldd : ndarray, shape (...)
        l'' [length/s²]; NaN where ``is_zero``.
    is_zero : ndarray of bool, shape (...)
        True where the points coincide (l within the tolerance of 0): l' and
        l'' do not exist there.
    """

    l: np.ndarray
    ld: np.ndarray
    ldd: np.ndarray
    is_zero: np.ndarray


def distance_function(
    A, Ad, Add, B, Bd, Bdd, *, tolerance: float = GEOMETRY_TOLERANCE
) -> DistanceFunctionResult:
    """Distance from A to B and its first two time derivatives.

    The paper's Fig. 3 (as in source, and correct; ``textbook.md`` §4.2 item
    2). With ``d = B - A``::

        l   = |d|
        l'  = (d · d') / l
        l'' = [(|d'|² + d · d'')·l - (d · d')·l'] / l²

    Parameters
    ----------
    A, B : array-like, shape (..., 2)
        Positions of the two points [length].
    Ad, Bd : array-like, shape (..., 2)
        Their velocities [length/s].
    Add, Bdd : array-like, shape (..., 2)
        Their accelerations [length/s²].
    tolerance : float, optional (default: GEOMETRY_TOLERANCE)
        The points coincide where ``l <= tolerance`` (caller's length unit).

    Returns
    -------
    result : DistanceFunctionResult
        ``l, ld, ldd`` of the broadcast batch shape; ``ld, ldd`` are NaN where
        ``is_zero``.

    Examples
    --------
    B moves away from A along +X at 3 units/s and accelerates along +Y:

    >>> r = distance_function([0, 0], [0, 0], [0, 0], [4, 0], [3, 0], [0, 2])
    >>> print(f"{r.l:.6f} {r.ld:.6f} {r.ldd:.6f} {r.is_zero}")
    4.000000 3.000000 0.000000 False
    """
    names = ("A", "Ad", "Add", "B", "Bd", "Bdd")
    A, Ad, Add, B, Bd, Bdd = np.broadcast_arrays(
        *(_check_finite_array(v, n, 2) for v, n in zip((A, Ad, Add, B, Bd, Bdd), names))
    )
    tolerance = _check_tolerance(tolerance, "tolerance")
    d = B - A
    dd = Bd - Ad
    ddd = Bdd - Add

    l = np.hypot(d[..., 0], d[..., 1])
    is_zero = l <= tolerance
    l_safe = np.where(is_zero, 1.0, l)

    dot_d = np.sum(d * dd, axis=-1)  # d · d'
    ld = dot_d / l_safe
    ldd = ((np.sum(dd * dd, axis=-1) + np.sum(d * ddd, axis=-1)) * l_safe - dot_d * ld) / (l_safe * l_safe)

    return DistanceFunctionResult(
        l=l,
        ld=np.where(is_zero, np.nan, ld),
        ldd=np.where(is_zero, np.nan, ldd),
        is_zero=is_zero,
    )
