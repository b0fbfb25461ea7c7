"""Verification of candidate solutions by forward kinematics, merging and ordering.

No solution leaves the core unless FK of it reproduces the target within a
tolerance relative to the robot's size.
"""

from __future__ import annotations

import math

import numpy as np

from .._cache import memo
from .._forward import forward_kinematics, tool_columns, tool_columns_scalar_rows
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
    """:func:`residual_arrays` by :func:`residuals_of_rows`, target by target."""
    n_targets, m, _ = q.shape
    position, orientation = np.empty((n_targets, m)), np.empty((n_targets, m))
    for row, (candidates, target) in enumerate(zip(q.tolist(), world_T_targets[:, :3, :].tolist())):
        position[row], orientation[row] = zip(*residuals_of_rows(robot, candidates, target))
    return position, orientation


def residuals_of_rows(robot: Robot, rows: list[list[float]], target: list[list[float]]) -> list[tuple[float, float]]:
    """:func:`residual_arrays` of a few candidates (lists of n floats) against one target (the top three rows of
    its matrix, as lists), in scalar arithmetic on the scalar FK
    (:func:`~service.kinematics._forward.tool_columns_scalar_rows`): the same formulas. Returns (position,
    orientation) per candidate."""
    (tx0, ty0, tz0, tp0), (tx1, ty1, tz1, tp1), (tx2, ty2, tz2, tp2) = target
    sqrt, atan2 = math.sqrt, math.atan2
    out = []
    for (x0, x1, x2), (y0, y1, y2), (z0, z1, z2), (p0, p1, p2) in tool_columns_scalar_rows(robot, rows):
        d0, d1, d2 = p0 - tp0, p1 - tp1, p2 - tp2
        cosine = 0.5 * ((tx0 * x0 + tx1 * x1 + tx2 * x2) + (ty0 * y0 + ty1 * y1 + ty2 * y2)
                        + (tz0 * z0 + tz1 * z1 + tz2 * z2) - 1.0)
        sine = 0.5 * sqrt(((tz0 * y0 + tz1 * y1 + tz2 * y2) - (ty0 * z0 + ty1 * z1 + ty2 * z2)) ** 2
                          + ((tx0 * z0 + tx1 * z1 + tx2 * z2) - (tz0 * x0 + tz1 * x1 + tz2 * x2)) ** 2
                          + ((ty0 * x0 + ty1 * x1 + ty2 * x2) - (tx0 * y0 + tx1 * y1 + tx2 * y2)) ** 2)
        out.append((sqrt(d0 * d0 + d1 * d1 + d2 * d2), atan2(sine, cosine)))
    return out


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Dot products along the leading axis of length 3, broadcasting the rest."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def accepted(robot: Robot, position: np.ndarray, orientation: np.ndarray, constrain_orientation: bool) -> np.ndarray:
    """Which residuals pass the FK check."""
    ok = position <= ACCEPT_RESIDUAL * arm_size(robot)
    if constrain_orientation:
        ok &= orientation <= ACCEPT_RESIDUAL
    return ok


def duplicate_tolerance(robot: Robot) -> np.ndarray:
    """Per joint (n,), how close two solutions' values must be to count as one: ``DUPLICATE_TOLERANCE`` radians
    for a revolute joint, that times the arm's size for a prismatic one."""
    return memo(robot, "duplicate_tolerance", lambda: np.where(
        robot.is_revolute, DUPLICATE_TOLERANCE, DUPLICATE_TOLERANCE * arm_size(robot)))


def first_of_each(robot: Robot, joints: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """Which slots (N, m) hold the first occurrence of a distinct solution among the ``ok`` ones.

    ``joints`` (N, m, n) has its revolute joints wrapped to (−π, π]; they are
    compared modulo 2π, each joint within :func:`duplicate_tolerance`. A slot
    is dropped when it equals a slot kept before it, exactly as a sequential
    scan would (:func:`first_of_each_one` is that scan for one target): the
    loop runs over the m slots, each step vectorised over the targets.
    """
    m = joints.shape[1]
    if m == 1:
        return ok.copy()
    revolute = robot.is_revolute
    # every pair (earlier slot, later slot) at once; joints are wrapped to (−π, π], so a revolute difference d
    # lies in (−2π, 2π) and |wrap(d)| = min(|d|, 2π − |d|)
    earlier, later = _slot_pairs(m)
    gap = np.abs(joints[:, later, :] - joints[:, earlier, :])  # (N, pairs, n)
    if revolute.all():
        np.minimum(gap, 2 * np.pi - gap, out=gap)
    elif revolute.any():
        gap[..., revolute] = np.minimum(gap[..., revolute], 2 * np.pi - gap[..., revolute])
    same = (gap <= duplicate_tolerance(robot)).all(axis=-1)  # (N, pairs)
    # then the sequential scan over slots, on booleans only: the pairs of slot s are those with later == s
    kept = ok.copy()
    start = 0
    for slot in range(1, m):
        kept[:, slot] &= ~np.any(same[:, start:start + slot] & kept[:, :slot], axis=1)
        start += slot
    return kept


def first_of_each_one(robot: Robot, joints: list[list[float]], ok: list[bool]) -> list[bool]:
    """:func:`first_of_each` for one target's m slots (lists of floats, revolute joints wrapped), by a plain scan:
    cheaper than the array operations at that size."""
    rule = memo(robot, "duplicate_rule", lambda: list(zip(robot.is_revolute.tolist(),
                                                           duplicate_tolerance(robot).tolist())))
    two_pi = 2 * math.pi
    kept: list[bool] = []
    first: list[list[float]] = []
    for q, good in zip(joints, ok):
        if good:
            for other in first:
                for a, b, (turn, tolerance) in zip(q, other, rule):
                    gap = abs(a - b)
                    if not (gap <= tolerance or turn and two_pi - gap <= tolerance):
                        break  # this joint differs (modulo 2π for a revolute one)
                else:  # every joint within tolerance: the same solution
                    good = False
                    break
            if good:
                first.append(q)
        kept.append(good)
    return kept


def _slot_pairs(m: int) -> tuple[np.ndarray, np.ndarray]:
    """Every pair of slots (earlier, later), grouped by the later slot: (0, 1), (0, 2), (1, 2), (0, 3), …"""
    pairs = _PAIRS.get(m)
    if pairs is None:
        later, earlier = np.tril_indices(m, -1)
        pairs = _PAIRS[m] = (earlier, later)
    return pairs


_PAIRS: dict[int, tuple[np.ndarray, np.ndarray]] = {}


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
