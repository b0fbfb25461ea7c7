"""Rigid motions of single joints, vectorised: the exponentials of the screw model."""

from __future__ import annotations

import numpy as np


def rotate_about(k: np.ndarray, theta: np.ndarray, v: np.ndarray) -> np.ndarray:
    """R(k, θ)·v by Rodrigues' formula.

    k : (3,) unit axis; theta : (...,); v : (..., 3), broadcast together.
    """
    theta = np.asarray(theta, dtype=float)[..., None]
    cos, sin = np.cos(theta), np.sin(theta)
    return v * cos + np.cross(k, v) * sin + k * (v @ k)[..., None] * (1.0 - cos)


def rotation_about(k: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """R(k, θ) as matrices, shape (..., 3, 3)."""
    theta = np.asarray(theta, dtype=float)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    sin, cos = np.sin(theta)[..., None, None], np.cos(theta)[..., None, None]
    return np.eye(3) + sin * K + (1.0 - cos) * (K @ K)


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


def chain_rotation(directions: np.ndarray, revolute: np.ndarray, q: np.ndarray) -> np.ndarray:
    """The rotation part of :func:`chain_motion`, shape (..., 3, 3): prismatic joints do not turn."""
    q = np.asarray(q, dtype=float)
    R = None
    for i in range(q.shape[-1]):
        if revolute[i]:
            turn = rotation_about(directions[i], q[..., i])
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
