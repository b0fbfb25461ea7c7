"""Verification of candidate solutions by forward kinematics, merging and ordering.

No solution leaves the core unless FK of it reproduces the target within a
tolerance relative to the robot's size.
"""

from __future__ import annotations

import math

import numpy as np

from .._budget import UNLIMITED, Budget
from .._forward import forward_kinematics, tool_columns, tool_columns_scalar
from .._robot import Robot
from .._rotations import wrap_angle
from .._tolerances import ACCEPT_RESIDUAL, DUPLICATE_TOLERANCE
from ._structure import arm_size


def wrap_revolute(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Revolute joint values wrapped to (−π, π]; prismatic values unchanged. Shape (..., n)."""
    return np.where(robot.is_revolute, wrap_angle(q), q)


def joint_difference(robot: Robot, q: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """q − reference with revolute differences taken across the 2π wrap, in (−π, π]. Shape (..., n)."""
    return wrap_revolute(robot, np.asarray(q) - reference)


def residuals(robot: Robot, q: np.ndarray, world_T_target: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Position error (length units) and orientation error (radians) of FK(q) against the target: k candidates
    for one target, or one candidate per target (:func:`residual_arrays`, the one formula).

    Parameters
    ----------
    q : ndarray, shape (k, n)
    world_T_target : ndarray, shape (4, 4) or (k, 4, 4)

    Returns
    -------
    position, orientation : ndarrays, shape (k,)
    """
    q, world_T_target = np.asarray(q, dtype=float), np.asarray(world_T_target, dtype=float)
    if world_T_target.ndim == 2:
        position, orientation = residual_arrays(robot, q[None], world_T_target[None])
        return position[0], orientation[0]
    position, orientation = residual_arrays(robot, q[:, None], world_T_target)
    return position[:, 0], orientation[:, 0]


def residual_arrays(robot: Robot, q: np.ndarray, world_T_targets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`residuals` for m candidates per target, without repeating the targets.

    Parameters
    ----------
    q : ndarray, shape (N, m, n)
    world_T_targets : ndarray, shape (N, 4, 4)

    Returns
    -------
    position, orientation : ndarrays, shape (N, m)
        Length units and radians, as :func:`residuals`.
    """
    n_targets, m, n = q.shape
    if n_targets * m <= SCALAR_CANDIDATES:
        return _residuals_scalar(robot, q, world_T_targets)
    x, y, z, p = (c.reshape(3, n_targets, m) for c in tool_columns(robot, q.reshape(-1, n)))
    target = np.moveaxis(world_T_targets[:, :3, :], 0, -1)[..., None]  # (3, 4, N, 1)
    tx, ty, tz, tp = target[:, 0], target[:, 1], target[:, 2], target[:, 3]
    delta = p - tp
    position = np.sqrt(_dot(delta, delta))
    # relative = target_R^T · R: entry (i, j) is target column i · column j
    dot = _dot
    cosine = 0.5 * (dot(tx, x) + dot(ty, y) + dot(tz, z) - 1.0)
    sine = 0.5 * np.sqrt((dot(tz, y) - dot(ty, z)) ** 2 + (dot(tx, z) - dot(tz, x)) ** 2
                         + (dot(ty, x) - dot(tx, y)) ** 2)
    return position, np.arctan2(sine, cosine)


#: Up to this many candidates in all (one pose's), :func:`residual_arrays` runs the scalar FK on each: cheaper
#: than the array operations, whose fixed cost dominates at that size.
SCALAR_CANDIDATES = 16


def _residuals_scalar(robot: Robot, q: np.ndarray, world_T_targets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`residual_arrays` by the scalar FK, candidate by candidate (the same formulas)."""
    n_targets, m, _ = q.shape
    position, orientation = np.empty((n_targets, m)), np.empty((n_targets, m))
    for row, (candidates, target) in enumerate(zip(q.tolist(), world_T_targets[:, :3, :].tolist())):
        (tx0, ty0, tz0, tp0), (tx1, ty1, tz1, tp1), (tx2, ty2, tz2, tp2) = target
        for slot, joints in enumerate(candidates):
            (x0, x1, x2), (y0, y1, y2), (z0, z1, z2), (p0, p1, p2) = tool_columns_scalar(robot, joints)
            d0, d1, d2 = p0 - tp0, p1 - tp1, p2 - tp2
            position[row, slot] = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            cosine = 0.5 * ((tx0 * x0 + tx1 * x1 + tx2 * x2) + (ty0 * y0 + ty1 * y1 + ty2 * y2)
                            + (tz0 * z0 + tz1 * z1 + tz2 * z2) - 1.0)
            sine = 0.5 * math.sqrt(((tz0 * y0 + tz1 * y1 + tz2 * y2) - (ty0 * z0 + ty1 * z1 + ty2 * z2)) ** 2
                                   + ((tx0 * z0 + tx1 * z1 + tx2 * z2) - (tz0 * x0 + tz1 * x1 + tz2 * x2)) ** 2
                                   + ((ty0 * x0 + ty1 * x1 + ty2 * x2) - (tx0 * y0 + tx1 * y1 + tx2 * y2)) ** 2)
            orientation[row, slot] = math.atan2(sine, cosine)
    return position, orientation


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Dot products along the leading axis of length 3, broadcasting the rest."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def accepted(robot: Robot, position: np.ndarray, orientation: np.ndarray, constrain_orientation: bool) -> np.ndarray:
    """Which residuals pass the FK check."""
    ok = position <= ACCEPT_RESIDUAL * arm_size(robot)
    if constrain_orientation:
        ok &= orientation <= ACCEPT_RESIDUAL
    return ok


def distinct(robot: Robot, q: np.ndarray, budget: Budget = UNLIMITED) -> np.ndarray:
    """Indices of the first occurrence of each distinct joint vector, revolute joints compared modulo 2π.

    Each row is compared with every kept row at once; ``budget`` is checked every 64 rows.
    """
    tolerance = np.where(robot.is_revolute, DUPLICATE_TOLERANCE, DUPLICATE_TOLERANCE * arm_size(robot))
    keep: list[int] = []
    for i in range(len(q)):
        if i % 64 == 63:
            budget.check("merging the numeric solutions")
        if not keep or not np.any(np.all(np.abs(joint_difference(robot, q[keep], q[i])) <= tolerance, axis=1)):
            keep.append(i)
    return np.array(keep, dtype=int)


def distance_to_reference(robot: Robot, q: np.ndarray, reference: np.ndarray, *, norm: str = "linf",
                          weights: np.ndarray | None = None) -> np.ndarray:
    """Wrap-aware distance of each row of q from the reference, shape (k,).

    ``norm`` is ``"linf"`` (the largest single joint move, the default) or ``"l2"``;
    ``weights`` scale each joint's difference.
    """
    difference = np.abs(joint_difference(robot, q, reference))
    if weights is not None:
        difference = difference * weights
    return difference.max(axis=-1) if norm == "linf" else np.linalg.norm(difference, axis=-1)


def polish(robot: Robot, q: np.ndarray, world_T_targets: np.ndarray, constrain_orientation: bool,
           steps: int = 3) -> np.ndarray:
    """A few damped Gauss–Newton steps towards the target, for candidates that are close but not exact.

    q : (k, n); world_T_targets : (k, 4, 4). Returns the refined (k, n). Rows
    already within :data:`ACCEPT_RESIDUAL` * 1e-3 are left as they are.
    """
    from .._forward import geometric_jacobian
    from ._numeric import pose_error

    scale = arm_size(robot)
    rows = slice(0, 6) if constrain_orientation else slice(0, 3)
    q = q.copy()
    for _ in range(steps):
        error = pose_error(forward_kinematics(robot, q), world_T_targets, scale)[:, rows]
        size = np.abs(error).max(axis=1)
        active = size > ACCEPT_RESIDUAL * 1e-3
        if not active.any():
            break
        J = geometric_jacobian(robot, q[active])
        J[:, :3, :] /= scale
        J = J[:, rows, :]
        JJt = J @ np.swapaxes(J, -1, -2) + 1e-12 * np.eye(J.shape[1])
        step = np.einsum("kji,kj->ki", J, np.linalg.solve(JJt, error[active][..., None])[..., 0])
        q[active] += step
    return q
