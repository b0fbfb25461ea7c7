"""Rotations written out here, independently of the service's rotation code: Rodrigues' formula, the rotations
about x, y and z, a URDF origin's fixed-axis roll, pitch and yaw, a unit quaternion's matrix, and random rotations."""

from __future__ import annotations

import numpy as np


def axis_angle(axis, angle: float) -> np.ndarray:
    """R(k, θ) (3, 3) by Rodrigues' formula, I + sin θ K + (1 − cos θ) K², about the unit axis k (3,)."""
    k = np.asarray(axis, dtype=float)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * K @ K


def about(axis: str, angle: float) -> np.ndarray:
    """The rotation (3, 3) by ``angle`` (rad) about the frame's ``axis``, "x", "y" or "z"."""
    c, s = np.cos(angle), np.sin(angle)
    return {"x": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
            "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
            "z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])}[axis]


def rpy(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """A URDF origin's rotation (3, 3) from fixed-axis roll, pitch, yaw (rad): R = Rz(yaw) Ry(pitch) Rx(roll)."""
    return about("z", yaw) @ about("y", pitch) @ about("x", roll)


def matrix_of_quaternion(w: float, x: float, y: float, z: float) -> np.ndarray:
    """The rotation (3, 3) of the unit quaternion w + xi + yj + zk."""
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def random_rotations(rng: np.random.Generator, n: int) -> np.ndarray:
    """(n, 3, 3) rotations, uniform over SO(3): the orthogonal factors of Gaussian matrices, their columns' signs
    fixed by R's diagonal, the first column turned where the determinant is −1."""
    Q, upper = np.linalg.qr(rng.standard_normal((n, 3, 3)))
    Q = Q * np.sign(np.diagonal(upper, axis1=-2, axis2=-1))[:, None, :]
    Q[np.linalg.det(Q) < 0, :, 0] *= -1.0
    return Q
