"""Rotations and rigid transforms: representations, conversions and validation.

Conventions
-----------
* Angles are radians. Units other than radians exist only at the API boundary,
  which converts them once.
* A rotation matrix ``a_R_b``, shape (3, 3), maps coordinates in frame b to
  coordinates in frame a; its columns are the axes of b expressed in a.
  A homogeneous transform ``a_T_b``, shape (4, 4), is ``[[a_R_b, a_p_b], [0 0 0 1]]``.
* Quaternions are ``(w, x, y, z)``, scalar first. Conversions return the
  canonical sign: ``w >= 0``, and when ``w == 0`` the first nonzero of
  ``(x, y, z)`` is positive.
* ZYZ Euler angles ``(phi, theta, psi)`` give ``Rz(phi) Ry(theta) Rz(psi)``.
* Roll, pitch, yaw ``(roll, pitch, yaw)`` give ``Rz(yaw) Ry(pitch) Rx(roll)``:
  a rotation about the fixed x axis, then the fixed y axis, then the fixed z axis.
* Returned angles are wrapped to ``(-pi, pi]``.

Validation
----------
The ``check_*`` functions validate a value at the boundary of the core and
return it as a new float64 array. Every conversion *from* a rotation
representation validates its input the same way, so a matrix that is not a
rotation can never be converted silently. Failures raise
:class:`InvalidInputError`. Its ``location`` is relative to the value given:
``(1, 2)`` is entry (1, 2) of a matrix, ``(4,)`` row 4 of a batch, and ``()``
the value as a whole. Functions with several arguments put the argument's
name first, for example ``("theta",)`` in :func:`matrix_from_euler_zyz`.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from ._angles import wrap_angle
from ._errors import InvalidInputError
from ._tolerances import ORTHONORMAL_TOLERANCE, SINGULARITY_TOLERANCE

__all__ = [
    "check_rotation",
    "check_transform",
    "check_transforms",
    "check_unit_quaternion",
    "euler_zyz_from_matrix",
    "frame_quaternion",
    "frame_quaternions",
    "matrix_from_euler_zyz",
    "matrix_from_quaternion",
    "matrix_from_rpy",
    "quaternions_from_matrices",
    "rot_x",
    "rot_y",
    "rot_z",
    "rpy_from_matrix",
]

# ---------------------------------------------------------------------------
# Validation helpers (private). They work on stacks of shape (..., m, n) so the
# single and the batch functions share one implementation; the leading index
# of the first offending element becomes the error's location.
# ---------------------------------------------------------------------------


def _as_float_array(value: ArrayLike, what: str) -> np.ndarray:
    """Return ``value`` as a new float64 array, or raise if it holds no real numbers."""
    try:
        array = np.asarray(value)
    except (ValueError, TypeError) as error:  # ragged nested sequences
        raise InvalidInputError(f"{what} must be an array of numbers ({error})") from None
    if array.dtype.kind not in "iuf":
        raise InvalidInputError(f"{what} must contain real numbers, got values of type {array.dtype}")
    return np.array(array, dtype=np.float64)


def _first_true(mask: np.ndarray) -> tuple[int, ...]:
    """Index of the first true element of ``mask`` (``()`` for a 0-d mask)."""
    return tuple(int(i) for i in np.unravel_index(int(np.argmax(mask)), mask.shape))


def _describe(index: tuple[int, ...]) -> str:
    return str(index[0]) if len(index) == 1 else str(index)


def _check_finite(array: np.ndarray, what: str) -> None:
    not_finite = ~np.isfinite(array)
    if not_finite.any():
        index = _first_true(not_finite)
        where = f"{what} entry {_describe(index)}" if index else what
        raise InvalidInputError(f"{where} is {array[index]}; every entry must be a finite number", location=index)


def _check_shape(array: np.ndarray, core_shape: tuple[int, ...], batch: bool, what: str) -> None:
    ndim = len(core_shape) + (1 if batch else 0)
    if array.ndim != ndim or array.shape[array.ndim - len(core_shape) :] != core_shape:
        expected = f"(N, {', '.join(map(str, core_shape))})" if batch else str(core_shape)
        raise InvalidInputError(f"{what} must have shape {expected}, got shape {array.shape}")


def _check_rotation_stack(R: np.ndarray, tolerance: float, what: str) -> None:
    """Raise unless every finite (..., 3, 3) matrix in ``R`` is a rotation within ``tolerance``."""
    gram_error = np.swapaxes(R, -1, -2) @ R - np.eye(3)
    worst = np.max(np.abs(gram_error), axis=(-2, -1))
    not_orthonormal = worst > tolerance
    if not_orthonormal.any():
        batch_index = _first_true(not_orthonormal)
        error = gram_error[batch_index]
        i, j = np.unravel_index(int(np.argmax(np.abs(error))), (3, 3))
        if i == j:
            detail = f"column {i} has length {math.sqrt(1.0 + error[i, j]):.9g}"
        else:
            detail = f"columns {min(i, j)} and {max(i, j)} have dot product {error[i, j]:.3g}"
        raise InvalidInputError(
            f"{what} is not orthonormal: max |R^T R - I| is {worst[batch_index]:.3g}, "
            f"more than the tolerance {tolerance:g} ({detail})",
            location=batch_index,
        )
    determinant = np.linalg.det(R)
    reflection = determinant < 0.0
    if reflection.any():
        batch_index = _first_true(reflection)
        raise InvalidInputError(
            f"{what} has determinant {determinant[batch_index]:.9g}: it is a reflection, not a rotation",
            location=batch_index,
        )
    off = np.abs(determinant - 1.0) > tolerance
    if off.any():
        batch_index = _first_true(off)
        raise InvalidInputError(
            f"{what} has determinant {determinant[batch_index]:.9g}, which differs from 1 by "
            f"{abs(determinant[batch_index] - 1.0):.3g}, more than the tolerance {tolerance:g}",
            location=batch_index,
        )


def _clearly_rigid(rows: list[list[float]], tolerance: float) -> bool:
    """Whether one matrix, its rows as lists of floats (a rotation (3, 3), or a transform (4, 4)), passes the
    checks below (:func:`_check_finite`, the bottom row's, :func:`_check_rotation_stack`) with half the tolerance
    to spare: a dozen float operations where the array checks make two dozen numpy calls, for the one target of a
    request. Anything else (a NaN, an infinity, an entry near a bound) gives False, and the array checks decide and
    word the error; the half keeps the two arithmetics, which differ in the last bits, from deciding otherwise."""
    if not math.isfinite(sum(map(sum, rows))):  # inf, −inf + inf and NaN all propagate
        return False
    margin = 0.5 * tolerance
    if len(rows) == 4:
        x, y, z, w = rows[3]
        if not (abs(x) <= margin and abs(y) <= margin and abs(z) <= margin and abs(w - 1.0) <= margin):
            return False
    (a0, b0, c0, *_), (a1, b1, c1, *_), (a2, b2, c2, *_) = rows[0], rows[1], rows[2]  # the columns a, b, c
    gram_error = max(abs(a0 * a0 + a1 * a1 + a2 * a2 - 1.0), abs(b0 * b0 + b1 * b1 + b2 * b2 - 1.0),
                     abs(c0 * c0 + c1 * c1 + c2 * c2 - 1.0), abs(a0 * b0 + a1 * b1 + a2 * b2),
                     abs(a0 * c0 + a1 * c1 + a2 * c2), abs(b0 * c0 + b1 * c1 + b2 * c2))
    determinant = a0 * (b1 * c2 - b2 * c1) - a1 * (b0 * c2 - b2 * c0) + a2 * (b0 * c1 - b1 * c0)
    return gram_error <= margin and abs(determinant - 1.0) <= margin


def _checked_rotations(R: ArrayLike, tolerance: float, batch: bool) -> np.ndarray:
    R = _as_float_array(R, "rotation matrix")
    _check_shape(R, (3, 3), batch, "rotation matrix")
    if not batch and _clearly_rigid(R.tolist(), tolerance):
        return R
    _check_finite(R, "rotation matrix")
    _check_rotation_stack(R, tolerance, "rotation matrix")
    return R


def _checked_transforms(T: ArrayLike, tolerance: float, batch: bool) -> np.ndarray:
    T = _as_float_array(T, "transform")
    _check_shape(T, (4, 4), batch, "transform")
    if not batch and _clearly_rigid(T.tolist(), tolerance):
        return T
    _check_finite(T, "transform")
    deviation = np.abs(T[..., 3, :] - np.array([0.0, 0.0, 0.0, 1.0]))
    bad_row = np.max(deviation, axis=-1) > tolerance
    if bad_row.any():
        batch_index = _first_true(bad_row)
        column = int(np.argmax(deviation[batch_index]))
        raise InvalidInputError(
            f"the bottom row of a homogeneous transform must be [0, 0, 0, 1], "
            f"but entry (3, {column}) is {T[(*batch_index, 3, column)]:.9g}",
            location=(*batch_index, 3, column),
        )
    # The rotation block shares its (row, column) indices with the 4x4, so the
    # locations of these errors are already relative to the transform.
    _check_rotation_stack(T[..., :3, :3], tolerance, "the rotation block of the transform")
    return T


def _checked_quaternion(wxyz: ArrayLike, tolerance: float) -> np.ndarray:
    q = _as_float_array(wxyz, "quaternion")
    _check_shape(q, (4,), False, "quaternion")
    _check_finite(q, "quaternion")
    norm = np.linalg.norm(q, axis=-1)
    not_unit = np.abs(norm - 1.0) > tolerance
    if not_unit.any():
        batch_index = _first_true(not_unit)
        raise InvalidInputError(
            f"quaternion (w, x, y, z) must have norm 1, but its norm is {norm[batch_index]:.9g} "
            f"(off by {abs(norm[batch_index] - 1.0):.3g}, tolerance {tolerance:g})",
            location=batch_index,
        )
    return q


def _checked_angles(angle: ArrayLike, what: str, *, scalar: bool = False) -> np.ndarray:
    """Angles as a float64 array of shape () or (N,) (only () when ``scalar``)."""
    angle = _as_float_array(angle, what)
    if angle.ndim > (0 if scalar else 1):
        shapes = "a scalar" if scalar else "a scalar or shape (N,)"
        raise InvalidInputError(f"{what} must be {shapes}, got shape {angle.shape}")
    _check_finite(angle, what)
    return angle


# ---------------------------------------------------------------------------
# Public validation
# ---------------------------------------------------------------------------


def check_rotation(R: ArrayLike, *, tolerance: float = ORTHONORMAL_TOLERANCE) -> np.ndarray:
    """Validate a rotation matrix.

    Parameters
    ----------
    R : array_like, shape (3, 3)
        Rotation matrix ``a_R_b``.
    tolerance : float
        Largest accepted ``max |R^T R - I|`` and ``|det R - 1|``.

    Returns
    -------
    R : ndarray, shape (3, 3), float64
        A new array with the same values (not re-orthonormalised).

    Raises
    ------
    InvalidInputError
        Wrong shape or not numbers (location ``()``); a NaN or infinite entry
        (location ``(i, j)``); not orthonormal, or a reflection (location ``()``).

    Examples
    --------
    >>> check_rotation([[0, -1, 0], [1, 0, 0], [0, 0, 1]]).dtype
    dtype('float64')
    >>> check_rotation(np.diag([1.0, 1.0, -1.0]))
    Traceback (most recent call last):
    ...
    service.kinematics._errors.InvalidInputError: rotation matrix has determinant -1: it is a reflection, not a rotation
    """
    return _checked_rotations(R, tolerance, batch=False)


def check_transform(T: ArrayLike, *, tolerance: float = ORTHONORMAL_TOLERANCE) -> np.ndarray:
    """Validate a homogeneous transform.

    Parameters
    ----------
    T : array_like, shape (4, 4)
        Transform ``a_T_b = [[a_R_b, a_p_b], [0, 0, 0, 1]]``.
    tolerance : float
        Tolerance for the bottom row and for the rotation block (see
        :func:`check_rotation`).

    Returns
    -------
    T : ndarray, shape (4, 4), float64
        A new array with the same values.

    Raises
    ------
    InvalidInputError
        Wrong shape (location ``()``); a NaN or infinite entry, or a bottom row
        other than ``[0, 0, 0, 1]`` (location ``(i, j)`` of the 4x4); a rotation
        block that is not a rotation (location ``()``).

    Examples
    --------
    >>> check_transform(np.eye(4)).shape
    (4, 4)
    """
    return _checked_transforms(T, tolerance, batch=False)


def check_transforms(T: ArrayLike, *, tolerance: float = ORTHONORMAL_TOLERANCE) -> np.ndarray:
    """Validate a stack of homogeneous transforms, shape (N, 4, 4); as :func:`check_transform`, row index first."""
    return _checked_transforms(T, tolerance, batch=True)


def check_unit_quaternion(wxyz: ArrayLike, *, tolerance: float = ORTHONORMAL_TOLERANCE) -> np.ndarray:
    """Validate a unit quaternion.

    Parameters
    ----------
    wxyz : array_like, shape (4,)
        Quaternion ``(w, x, y, z)``.
    tolerance : float
        Largest accepted ``| |q| - 1 |``.

    Returns
    -------
    wxyz : ndarray, shape (4,), float64
        A new array with the same values (not re-normalised).

    Raises
    ------
    InvalidInputError
        Wrong shape (location ``()``); a NaN or infinite entry (location
        ``(i,)``); a norm that is not 1 (location ``()``).

    Examples
    --------
    >>> check_unit_quaternion([1, 0, 0, 0]).tolist()
    [1.0, 0.0, 0.0, 0.0]
    """
    return _checked_quaternion(wxyz, tolerance)


# ---------------------------------------------------------------------------
# Elementary rotations
# ---------------------------------------------------------------------------


def _elementary(angle: ArrayLike, axis: int, what: str) -> np.ndarray:
    angle = _checked_angles(angle, what)
    c, s = np.cos(angle), np.sin(angle)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    R = np.zeros(angle.shape + (3, 3))
    R[..., axis, axis] = 1.0
    R[..., i, i] = c
    R[..., j, j] = c
    R[..., i, j] = -s
    R[..., j, i] = s
    return R


def rot_x(angle: ArrayLike) -> np.ndarray:
    """Rotation about the x axis by ``angle`` (radians).

    Parameters
    ----------
    angle : float or array_like, shape (N,)

    Returns
    -------
    R : ndarray, shape (3, 3) or (N, 3, 3)
        ``[[1, 0, 0], [0, c, -s], [0, s, c]]``.

    Examples
    --------
    >>> (rot_x(np.pi / 2) @ [0.0, 1.0, 0.0]).round(12).tolist()
    [0.0, 0.0, 1.0]
    """
    return _elementary(angle, 0, "angle")


def rot_y(angle: ArrayLike) -> np.ndarray:
    """Rotation about the y axis by ``angle`` (radians).

    Parameters
    ----------
    angle : float or array_like, shape (N,)

    Returns
    -------
    R : ndarray, shape (3, 3) or (N, 3, 3)
        ``[[c, 0, s], [0, 1, 0], [-s, 0, c]]``.

    Examples
    --------
    >>> (rot_y(np.pi / 2) @ [0.0, 0.0, 1.0]).round(12).tolist()
    [1.0, 0.0, 0.0]
    """
    return _elementary(angle, 1, "angle")


def rot_z(angle: ArrayLike) -> np.ndarray:
    """Rotation about the z axis by ``angle`` (radians).

    Parameters
    ----------
    angle : float or array_like, shape (N,)

    Returns
    -------
    R : ndarray, shape (3, 3) or (N, 3, 3)
        ``[[c, -s, 0], [s, c, 0], [0, 0, 1]]``.

    Examples
    --------
    >>> (rot_z(np.pi / 2) @ [1.0, 0.0, 0.0]).round(12).tolist()
    [0.0, 1.0, 0.0]
    >>> rot_z([0.0, 0.5]).shape
    (2, 3, 3)
    """
    return _elementary(angle, 2, "angle")


# ---------------------------------------------------------------------------
# Quaternions
# ---------------------------------------------------------------------------


def _matrices_from_quaternions(q: np.ndarray) -> np.ndarray:
    """(..., 4) quaternions, not necessarily of unit norm, to (..., 3, 3) rotations."""
    if q.ndim == 1:  # one quaternion: its entries on floats (as arrays of shape () they cost ~1 µs an operation)
        w, x, y, z = q.tolist()
        return np.array(_rotation_entries(w, x, y, z, 2.0 / (w * w + x * x + y * y + z * z)))
    w, x, y, z = np.moveaxis(q, -1, 0)
    R = np.empty(q.shape[:-1] + (3, 3))
    for i, row in enumerate(_rotation_entries(w, x, y, z, 2.0 / np.sum(q * q, axis=-1))):
        R[..., i, 0], R[..., i, 1], R[..., i, 2] = row
    return R


def _rotation_entries(w, x, y, z, s):
    """The rotation matrix of the quaternion (w, x, y, z) with s = 2 / |q|², row by row: floats or arrays."""
    return ((1.0 - s * (y * y + z * z), s * (x * y - w * z), s * (x * z + w * y)),
            (s * (x * y + w * z), 1.0 - s * (x * x + z * z), s * (y * z - w * x)),
            (s * (x * z - w * y), s * (y * z + w * x), 1.0 - s * (x * x + y * y)))


def _canonical_sign(q: np.ndarray) -> np.ndarray:
    """Flip (M, 4) quaternions so that w >= 0; if w == 0, the first nonzero of x, y, z is > 0."""
    vector = q[:, 1:]
    first_nonzero = vector[np.arange(len(q)), np.argmax(vector != 0.0, axis=-1)]
    w = q[:, 0]
    flip = (w < 0.0) | ((w == 0.0) & (first_nonzero < 0.0))
    q = np.where(flip[:, None], -q, q)
    q[:, 0] = np.abs(q[:, 0])  # turn a -0.0 into 0.0
    return q


def _quaternions_from_matrices(R: np.ndarray) -> np.ndarray:
    """(..., 3, 3) rotations to canonical (..., 4) unit quaternions (Shepperd's method).

    For a rotation, the symmetric matrix ``K`` below equals ``4 q q^T``. Its
    largest diagonal entry ``4 q_k^2`` is at least 1 (the diagonal sums to 4), so
    ``q = K[k] / (2 sqrt(K[k, k]))`` divides by a number no smaller than 2 and
    stays accurate for every rotation, including those near 180 degrees where
    ``1 + trace`` vanishes. ``K`` is stacked from its sixteen entries at once, over the rotations flattened to
    (M, 3, 3): a few numpy calls whatever M, so that one rotation costs little more than the call.
    """
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = R.reshape(-1, 9).T
    trace = r00 + r11 + r22
    diagonal = (1.0 + trace, 1.0 + r00 - r11 - r22, 1.0 - r00 + r11 - r22, 1.0 - r00 - r11 + r22)
    zx, xy_, xz_ = r21 - r12, r02 - r20, r10 - r01  # K[0, 1:]: 4 w (x, y, z)
    xy, xz, yz = r01 + r10, r02 + r20, r12 + r21  # K[1, 2], K[1, 3], K[2, 3]
    K = np.stack([diagonal[0], zx, xy_, xz_,
                  zx, diagonal[1], xy, xz,
                  xy_, xy, diagonal[2], yz,
                  xz_, xz, yz, diagonal[3]], axis=-1).reshape(-1, 4, 4)
    rows = np.arange(len(K))
    k = np.argmax(np.stack(diagonal, axis=-1), axis=-1)
    row = K[rows, k]
    q = row / (2.0 * np.sqrt(row[rows, k]))[:, None]
    q /= np.linalg.norm(q, axis=-1, keepdims=True)  # inputs are orthonormal only within a tolerance
    return _canonical_sign(q).reshape(*R.shape[:-2], 4)


def frame_quaternion(r: list[float]) -> list[float]:
    """The unit quaternion ``[w, x, y, z]`` of one rotation the core computed (an FK pose), given as its nine
    entries row by row, on floats, without input checks: :func:`quaternions_from_matrices`'s K, the same choice of
    its largest diagonal entry, the same normalisation and canonical sign, for a fraction of an array call's cost.

    >>> [round(value, 6) for value in frame_quaternion([0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0])]
    [0.707107, 0.0, 0.0, 0.707107]
    """
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = r
    trace = r00 + r11 + r22
    diagonal = (1.0 + trace, 1.0 + r00 - r11 - r22, 1.0 - r00 + r11 - r22, 1.0 - r00 - r11 + r22)
    zx, xy_, xz_ = r21 - r12, r02 - r20, r10 - r01
    xy, xz, yz = r01 + r10, r02 + r20, r12 + r21
    K = ((diagonal[0], zx, xy_, xz_), (zx, diagonal[1], xy, xz), (xy_, xy, diagonal[2], yz),
         (xz_, xz, yz, diagonal[3]))
    k = diagonal.index(max(diagonal))
    scale = 2.0 * math.sqrt(K[k][k])
    q = [value / scale for value in K[k]]
    length = math.sqrt(sum(value * value for value in q))
    q = [value / length for value in q]
    first_nonzero = next((value for value in q[1:] if value != 0.0), 0.0)
    if q[0] < 0.0 or (q[0] == 0.0 and first_nonzero < 0.0):
        q = [-value for value in q]
    q[0] = abs(q[0])  # turn a -0.0 into 0.0
    return q


def frame_quaternions(R: ArrayLike) -> np.ndarray:
    """:func:`quaternions_from_matrices` of rotations the core computed (FK poses, link frames), shape (N, 3, 3),
    without its input checks, which hold by construction; one rotation is converted on floats, where numpy's cost
    per call would be most of the time.

    >>> frame_quaternions(rot_z([np.pi / 2])).round(6).tolist()
    [[0.707107, 0.0, 0.0, 0.707107]]
    """
    R = np.asarray(R, dtype=float)
    if R.shape[0] == 1:
        return np.array([frame_quaternion(R.reshape(9).tolist())])
    return _quaternions_from_matrices(R)


def matrix_from_quaternion(wxyz: ArrayLike) -> np.ndarray:
    """Rotation matrix of a unit quaternion.

    Parameters
    ----------
    wxyz : array_like, shape (4,)
        Unit quaternion ``(w, x, y, z)``, validated by :func:`check_unit_quaternion`.
        ``q`` and ``-q`` give the same matrix.

    Returns
    -------
    R : ndarray, shape (3, 3)
        Orthonormal to rounding error (the small allowed norm error is divided out).

    Examples
    --------
    >>> h = np.sqrt(0.5)
    >>> (matrix_from_quaternion([h, 0.0, 0.0, h]) @ [1.0, 0.0, 0.0]).round(12).tolist()
    [0.0, 1.0, 0.0]
    """
    return _matrices_from_quaternions(check_unit_quaternion(wxyz))


def quaternions_from_matrices(R: ArrayLike) -> np.ndarray:
    """Unit quaternions of rotation matrices, with the canonical sign.

    Uses Shepperd's largest-diagonal method, accurate for every rotation
    including those near 180 degrees (trace near -1).

    Parameters
    ----------
    R : array_like, shape (N, 3, 3)
        Rotation matrices.

    Returns
    -------
    wxyz : ndarray, shape (N, 4)
        Canonical unit quaternions ``(w, x, y, z)``, one per matrix: ``w >= 0``;
        when ``w == 0`` (a half turn), the first nonzero of ``(x, y, z)`` is positive.

    Raises
    ------
    InvalidInputError
        Location ``(i,)`` for a matrix that is not a rotation, ``(i, j, k)`` for
        a NaN or infinite entry.

    Examples
    --------
    >>> quaternions_from_matrices(np.stack([np.eye(3), rot_x(np.pi)])).round(12).tolist()
    [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]]
    >>> quaternions_from_matrices(rot_z([np.pi / 2])).round(6).tolist()
    [[0.707107, 0.0, 0.0, 0.707107]]
    >>> quaternions_from_matrices(np.diag([-1.0, 1.0, -1.0])[None]).tolist()
    [[0.0, 0.0, 1.0, 0.0]]
    """
    return _quaternions_from_matrices(_checked_rotations(R, ORTHONORMAL_TOLERANCE, batch=True))


# ---------------------------------------------------------------------------
# Euler angles
# ---------------------------------------------------------------------------


def _checked_angle_triple(names: tuple[str, str, str], values: tuple[ArrayLike, ...]) -> list[np.ndarray]:
    angles = []
    for name, value in zip(names, values):
        try:
            angles.append(_checked_angles(value, name))
        except InvalidInputError as error:
            raise error.relocated(name) from None
    try:
        np.broadcast_shapes(*(a.shape for a in angles))
    except ValueError:
        shapes = ", ".join(f"{n} {a.shape}" for n, a in zip(names, angles))
        raise InvalidInputError(f"angle arrays must have the same length, got {shapes}") from None
    return angles


def matrix_from_euler_zyz(phi: ArrayLike, theta: ArrayLike, psi: ArrayLike) -> np.ndarray:
    """Rotation matrix of ZYZ Euler angles: ``Rz(phi) Ry(theta) Rz(psi)``.

    ::

        [ cφcθcψ − sφsψ   −cφcθsψ − sφcψ   cφsθ ]
        [ sφcθcψ + cφsψ   −sφcθsψ + cφcψ   sφsθ ]
        [ −sθcψ            sθsψ             cθ   ]

    Parameters
    ----------
    phi, theta, psi : float or array_like, shape (N,)
        Radians. Scalars and arrays of one length N broadcast together.

    Returns
    -------
    R : ndarray, shape (3, 3) or (N, 3, 3)

    Examples
    --------
    >>> matrix_from_euler_zyz(0.1, 0.2, 0.3)[:, 2].round(6).tolist()
    [0.197677, 0.019834, 0.980067]
    """
    phi, theta, psi = _checked_angle_triple(("phi", "theta", "psi"), (phi, theta, psi))
    return rot_z(phi) @ rot_y(theta) @ rot_z(psi)


def euler_zyz_from_matrix(
    R: ArrayLike, *, branch: int = 1, free_angle: float = 0.0
) -> tuple[np.ndarray, bool]:
    """ZYZ Euler angles ``(phi, theta, psi)`` with ``R = Rz(phi) Ry(theta) Rz(psi)``.

    Regular case, ``sin(theta) = hypot(r13, r23) >= SINGULARITY_TOLERANCE``:

    * ``branch=+1`` (``sin(theta) > 0``): ``theta = atan2(+s, r33)``,
      ``phi = atan2(r23, r13)``, ``psi = atan2(r32, -r31)``.
    * ``branch=-1`` (``sin(theta) < 0``): ``theta = atan2(-s, r33)``,
      ``phi = atan2(-r23, -r13)``, ``psi = atan2(-r32, r31)``; this is
      ``(phi + pi, -theta, psi + pi)`` of branch +1, wrapped.

    Singular case (``r13 = r23 = 0`` within the tolerance): only one
    combination is determined, ``phi = wrap_angle(free_angle)``, and both
    branches give the same answer:

    * ``r33 > 0``: ``theta = 0`` and ``phi + psi = atan2(r21, r11)``.
    * ``r33 < 0``: ``theta = pi`` and ``phi - psi = atan2(-r12, -r11)``.

    Parameters
    ----------
    R : array_like, shape (3, 3)
        Rotation matrix, validated by :func:`check_rotation`.
    branch : {1, -1}
        Sign of ``sin(theta)`` (textbook §1.4, the ``±`` root).
    free_angle : float
        Value of ``phi`` in the singular case.

    Returns
    -------
    angles : ndarray, shape (3,)
        ``(phi, theta, psi)`` in radians, each in ``(-pi, pi]``.
    singular : bool
        Whether the singular case applied.

    Examples
    --------
    >>> R = matrix_from_euler_zyz(0.1, 0.2, 0.3)
    >>> angles, singular = euler_zyz_from_matrix(R)
    >>> angles.round(6).tolist(), singular
    ([0.1, 0.2, 0.3], False)
    >>> euler_zyz_from_matrix(R, branch=-1)[0].round(6).tolist()
    [-3.041593, -0.2, -2.841593]
    >>> angles, singular = euler_zyz_from_matrix(matrix_from_euler_zyz(0.3, 0.0, 0.5))
    >>> angles.round(6).tolist(), singular
    ([0.0, 0.0, 0.8], True)
    """
    R = check_rotation(R)
    if branch not in (1, -1):
        raise InvalidInputError(f"branch must be 1 or -1, got {branch!r}", location=("branch",))
    try:
        phi = float(_checked_angles(free_angle, "free_angle", scalar=True))
    except InvalidInputError as error:
        raise error.relocated("free_angle") from None
    sin_theta = math.hypot(R[0, 2], R[1, 2])
    if sin_theta < SINGULARITY_TOLERANCE:
        if R[2, 2] > 0.0:
            theta = 0.0
            psi = math.atan2(R[1, 0], R[0, 0]) - phi
        else:
            theta = math.pi
            psi = phi - math.atan2(-R[0, 1], -R[0, 0])
        return wrap_angle(np.array([phi, theta, psi])), True
    if branch == 1:
        angles = [
            math.atan2(R[1, 2], R[0, 2]),
            math.atan2(sin_theta, R[2, 2]),
            math.atan2(R[2, 1], -R[2, 0]),
        ]
    else:
        angles = [
            math.atan2(-R[1, 2], -R[0, 2]),
            math.atan2(-sin_theta, R[2, 2]),
            math.atan2(-R[2, 1], R[2, 0]),
        ]
    return wrap_angle(np.array(angles)), False


def matrix_from_rpy(roll: ArrayLike, pitch: ArrayLike, yaw: ArrayLike) -> np.ndarray:
    """Rotation matrix of roll, pitch, yaw: ``Rz(yaw) Ry(pitch) Rx(roll)``.

    Roll about the fixed x axis first, then pitch about the fixed y axis, then
    yaw about the fixed z axis (equivalently intrinsic z, y', x'')::

        [ cy·cp   cy·sp·sr − sy·cr   cy·sp·cr + sy·sr ]
        [ sy·cp   sy·sp·sr + cy·cr   sy·sp·cr − cy·sr ]
        [ −sp     cp·sr              cp·cr            ]

    Parameters
    ----------
    roll, pitch, yaw : float or array_like, shape (N,)
        Radians. Scalars and arrays of one length N broadcast together.

    Returns
    -------
    R : ndarray, shape (3, 3) or (N, 3, 3)

    Examples
    --------
    >>> matrix_from_rpy(0.1, 0.2, 0.3)[2].round(6).tolist()
    [-0.198669, 0.097843, 0.97517]
    """
    roll, pitch, yaw = _checked_angle_triple(("roll", "pitch", "yaw"), (roll, pitch, yaw))
    return rot_z(yaw) @ rot_y(pitch) @ rot_x(roll)


def rpy_from_matrix(R: ArrayLike, *, free_angle: float = 0.0) -> tuple[np.ndarray, bool]:
    """Roll, pitch, yaw with ``R = Rz(yaw) Ry(pitch) Rx(roll)``.

    Regular case, ``cos(pitch) = hypot(r11, r21) >= SINGULARITY_TOLERANCE``:
    ``pitch = atan2(-r31, cos(pitch))`` in ``(-pi/2, pi/2)``,
    ``roll = atan2(r32, r33)``, ``yaw = atan2(r21, r11)``. (The other solution,
    ``(roll + pi, pi - pitch, yaw + pi)``, is not returned.)

    Gimbal lock (``r11 = r21 = 0`` within the tolerance): only one combination
    is determined, and ``roll = wrap_angle(free_angle)``:

    * ``r31 < 0``: ``pitch = +pi/2`` and ``roll - yaw = atan2(r12, r22)``.
    * ``r31 > 0``: ``pitch = -pi/2`` and ``roll + yaw = atan2(-r12, r22)``.

    Parameters
    ----------
    R : array_like, shape (3, 3)
        Rotation matrix, validated by :func:`check_rotation`.
    free_angle : float
        Value of ``roll`` at gimbal lock.

    Returns
    -------
    angles : ndarray, shape (3,)
        ``(roll, pitch, yaw)`` in radians, each in ``(-pi, pi]``.
    singular : bool
        Whether the gimbal-lock case applied.

    Examples
    --------
    >>> angles, singular = rpy_from_matrix(matrix_from_rpy(0.1, 0.2, 0.3))
    >>> angles.round(6).tolist(), singular
    ([0.1, 0.2, 0.3], False)
    >>> angles, singular = rpy_from_matrix(matrix_from_rpy(0.3, np.pi / 2, 0.5))
    >>> angles.round(6).tolist(), singular
    ([0.0, 1.570796, 0.2], True)
    """
    R = check_rotation(R)
    try:
        roll = float(_checked_angles(free_angle, "free_angle", scalar=True))
    except InvalidInputError as error:
        raise error.relocated("free_angle") from None
    cos_pitch = math.hypot(R[0, 0], R[1, 0])
    if cos_pitch < SINGULARITY_TOLERANCE:
        if R[2, 0] < 0.0:
            pitch = math.pi / 2
            yaw = roll - math.atan2(R[0, 1], R[1, 1])
        else:
            pitch = -math.pi / 2
            yaw = math.atan2(-R[0, 1], R[1, 1]) - roll
        return wrap_angle(np.array([roll, pitch, yaw])), True
    angles = [
        math.atan2(R[2, 1], R[2, 2]),
        math.atan2(-R[2, 0], cos_pitch),
        math.atan2(R[1, 0], R[0, 0]),
    ]
    return wrap_angle(np.array(angles)), False
