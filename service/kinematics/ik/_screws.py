"""Rigid motions of single joints, vectorised: the exponentials of the screw model (Rodrigues' formula for one
axis, applied to points or built as matrices), and the frame about an axis that they and the subproblems turn
points in. Float twins for the one-pose paths are in :mod:`._scalar`."""

from __future__ import annotations

import math

import numpy as np

from .._cache import AxisCache
from .._forward import JointTrig


def rotate_about(k: np.ndarray, theta: np.ndarray, v: np.ndarray,
                 cos_sin: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """R(k, θ)·v by Rodrigues' formula.

    k : (3,) unit axis; theta : (...,); v : (..., 3), broadcast together; ``cos_sin`` (cos θ, sin θ), theta's
    shape, when the caller has them already.
    In a frame (e1, e2, k) around the axis the turn is a plane rotation of the
    (e1, e2) coordinates, so the work is two small matrix products and four
    elementwise products (cheaper than the cross-product form).
    """
    theta = np.asarray(theta, dtype=float)
    v = np.asarray(v, dtype=float)
    shape = v.shape if v.shape[:-1] == theta.shape else np.broadcast_shapes(v.shape, theta.shape + (3,))
    frame = axis_frame(k)  # columns e1, e2, k
    if v.shape != shape:
        v = np.broadcast_to(v, shape)
    if cos_sin is None:
        cos_sin = np.cos(theta), np.sin(theta)
    if theta.shape != shape[:-1]:
        cos_sin = tuple(np.broadcast_to(part, shape[:-1]) for part in cos_sin)
    # (3, 3) @ (3, M) products run as one BLAS call; (M, 3) @ (3, 3) would not
    local = frame.T @ v.reshape(-1, 3).T  # (3, M): coordinates along e1, e2, k
    cos, sin = (part.reshape(-1) for part in cos_sin)
    a, b = local[0], local[1]
    turned = np.empty_like(local)
    np.subtract(a * cos, b * sin, out=turned[0])
    np.add(a * sin, b * cos, out=turned[1])
    turned[2] = local[2]
    return (frame @ turned).T.reshape(shape)


def axis_frame(k: np.ndarray) -> np.ndarray:
    """The right-handed orthonormal frame ``[e1, e2, k]`` (as columns, (3, 3)) around the unit axis ``k`` (3,),
    read-only, remembered by value in a bounded cache (the joint axes are a few constants).

    ``p @ axis_frame(k)`` gives the coordinates ``(x, y, z)`` of ``p``, where ``z = k·p`` is the height along
    the axis. A rotation about ``k`` turns ``(x, y)`` like a plane rotation: ``R(k, θ) p`` has
    ``(x cos θ − y sin θ, x sin θ + y cos θ, z)``.
    """
    key = tuple(k.tolist()) if isinstance(k, np.ndarray) else tuple(float(value) for value in k)
    frame = _FRAMES.get(key)
    if frame is None:
        frame = _built_frame(*key)
        frame.setflags(write=False)
        _FRAMES.keep(key, frame)
    return frame


_FRAMES = AxisCache()


def perpendicular_unit(k: np.ndarray) -> np.ndarray:
    """A unit vector perpendicular to the unit axis ``k`` (3,): e1 of :func:`axis_frame` (k × the coordinate axis
    least aligned with k, normalised), read-only."""
    return axis_frame(k)[:, 0]


def _built_frame(kx: float, ky: float, kz: float) -> np.ndarray:
    """:func:`axis_frame` of (kx, ky, kz): e1 = k × (the coordinate axis least aligned with k), normalised."""
    if abs(kx) <= abs(ky) and abs(kx) <= abs(kz):
        e1 = (0.0, kz, -ky)
    elif abs(ky) <= abs(kz):
        e1 = (-kz, 0.0, kx)
    else:
        e1 = (ky, -kx, 0.0)
    n = math.sqrt(e1[0] ** 2 + e1[1] ** 2 + e1[2] ** 2)
    ax, ay, az = e1[0] / n, e1[1] / n, e1[2] / n
    e2 = (ky * az - kz * ay, kz * ax - kx * az, kx * ay - ky * ax)  # k × e1
    return np.array([[ax, e2[0], kx], [ay, e2[1], ky], [az, e2[2], kz]])


def rotation_about(k: np.ndarray, theta: np.ndarray, cos_sin: tuple[np.ndarray, np.ndarray] | None = None
                   ) -> np.ndarray:
    """R(k, θ) as matrices, shape (..., 3, 3); ``cos_sin`` (cos θ, sin θ) when the caller has them already."""
    theta = np.asarray(theta, dtype=float)
    K, KK = _cross_matrices(k)
    cos, sin = (np.cos(theta), np.sin(theta)) if cos_sin is None else cos_sin
    # I + sin θ K + (1 − cos θ) K², entry by entry as rows (9, M) of one long loop each (a (M, 3, 3) broadcast
    # runs nine values at a time), then laid out (M, 3, 3)
    entries = K.reshape(9, 1) * sin.reshape(-1)
    entries += _EYE3.reshape(9, 1)
    entries += KK.reshape(9, 1) * (1.0 - cos.reshape(-1))
    return entries.T.copy().reshape(theta.shape + (3, 3))


def _cross_matrices(k: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """[k]× and [k]×², memoised by value (the joint axes are a few constants)."""
    key = tuple(np.asarray(k, dtype=float).tolist())
    pair = _CROSS.get(key)
    if pair is None:
        K = np.array([[0.0, -key[2], key[1]], [key[2], 0.0, -key[0]], [-key[1], key[0], 0.0]])
        pair = (K, K @ K)
        for matrix in pair:
            matrix.setflags(write=False)
        _CROSS.keep(key, pair)
    return pair


_CROSS = AxisCache()
_EYE3 = np.eye(3)
_EYE3.setflags(write=False)


def joint_motion(direction: np.ndarray, point: np.ndarray, revolute: bool, q: np.ndarray) -> np.ndarray:
    """exp([S] q): the motion of joint S by q, as transforms of shape (..., 4, 4).

    A revolute joint turns by q about ``direction`` through ``point``; a
    prismatic joint slides by q along ``direction``.
    """
    q = np.asarray(q, dtype=float)
    T = np.zeros(q.shape + (4, 4))
    T[..., 3, 3] = 1.0
    if revolute:
        R = rotation_about(direction, q)
        T[..., :3, :3] = R
        T[..., :3, 3] = point - R @ point
    else:
        T[..., :3, :3] = np.eye(3)
        T[..., :3, 3] = direction * q[..., None]
    return T


def chain_motion(directions: np.ndarray, points: np.ndarray, revolute: np.ndarray, q: np.ndarray) -> np.ndarray:
    """exp([S_1] q_1) ⋯ exp([S_k] q_k) for joint values q of shape (..., k); returns (..., 4, 4)."""
    q = np.asarray(q, dtype=float)
    T = np.broadcast_to(np.eye(4), q.shape[:-1] + (4, 4))
    for i in range(q.shape[-1]):
        T = T @ joint_motion(directions[i], points[i], bool(revolute[i]), q[..., i])
    return T


def move_point(directions: np.ndarray, points: np.ndarray, revolute: np.ndarray, q: np.ndarray,
               x: np.ndarray, trig: JointTrig | None = None) -> np.ndarray:
    """:func:`chain_motion` applied to the point x (3,): shape (..., 3), turning the point joint by joint
    from the last to the first (vector operations only, no 4×4 products). ``trig``: q's cos and sin, when shared."""
    q = np.asarray(q, dtype=float)
    x = np.broadcast_to(np.asarray(x, dtype=float), q.shape[:-1] + (3,))
    for i in reversed(range(q.shape[-1])):
        if revolute[i]:
            x = points[i] + rotate_about(directions[i], q[..., i], x - points[i], None if trig is None else trig[i])
        else:
            x = x + directions[i] * q[..., i, None]
    return x


def chain_rotation(directions: np.ndarray, revolute: np.ndarray, q: np.ndarray, trig: JointTrig | None = None
                   ) -> np.ndarray:
    """The rotation part of :func:`chain_motion`, shape (..., 3, 3): prismatic joints do not turn. ``trig``: q's
    cos and sin, when shared."""
    q = np.asarray(q, dtype=float)
    R = None
    for i in range(q.shape[-1]):
        if revolute[i]:
            turn = rotation_about(directions[i], q[..., i], None if trig is None else trig[i])
            R = turn if R is None else R @ turn
    return np.broadcast_to(np.eye(3), q.shape[:-1] + (3, 3)) if R is None else R


def apply(T: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Transform points: T (..., 4, 4) applied to x (..., 3)."""
    return np.einsum("...ij,...j->...i", T[..., :3, :3], x) + T[..., :3, 3]


def invert(T: np.ndarray) -> np.ndarray:
    """Inverse of rigid transforms (..., 4, 4)."""
    R = np.swapaxes(T[..., :3, :3], -1, -2)
    inverse = np.zeros(T.shape)
    inverse[..., :3, :3] = R
    inverse[..., :3, 3] = -np.einsum("...ij,...j->...i", R, T[..., :3, 3])
    inverse[..., 3, 3] = 1.0
    return inverse
