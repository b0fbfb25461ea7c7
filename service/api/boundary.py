"""Translation between wire models and the core, with units converted once, here.

Inbound: robot descriptions become :class:`~service.kinematics.Robot` (radians,
Craig rows for Khalil tables), joint values become radians, targets become
4×4 ``world_T_tool`` matrices. Outbound: matrices become :class:`Pose` dicts
and radians go back to the request's unit. Errors raised by the core carry
locations relative to the value passed in; they are prefixed here with the
request path so that the problem document points at the field.
"""

from __future__ import annotations

import math
from contextlib import contextmanager
from typing import Iterator, Sequence

import numpy as np

from ..kinematics import (
    InvalidInputError,
    Limits,
    Violation,
    Joint,
    KinematicsError,
    Robot,
    check_joint_values,
    check_rotation,
    check_transform,
    check_unit_quaternion,
    craig_row_from_khalil,
    matrix_from_euler_zyz,
    matrix_from_quaternion,
    matrix_from_rpy,
    quaternions_from_matrices,
)
from .schemas.common import AngleUnit
from .schemas.poses import (
    EulerZYZOrientation,
    MatrixOrientation,
    PoseTarget,
    QuaternionOrientation,
    RPYOrientation,
)
from .schemas.robots import DHRobot, KhalilRobot

_DEGREE = math.pi / 180.0


@contextmanager
def located(*prefix: str | int) -> Iterator[None]:
    """Prefix the location of any core error raised inside the block."""
    try:
        yield
    except KinematicsError as error:
        raise error.relocated(*prefix) from None


def robot_from_description(description: DHRobot | KhalilRobot, *, max_joints: int) -> Robot:
    """Build the core robot, converting the table's angles to radians once."""
    if len(description.joints) > max_joints:
        raise InvalidInputError(
            f"a robot may have at most {max_joints} joints, this one has {len(description.joints)}",
            location=("joints",),
        )
    angle = _DEGREE if description.angle_unit == "deg" else 1.0
    joints = []
    for index, row in enumerate(description.joints):
        if isinstance(description, KhalilRobot):
            a, alpha, d, theta = craig_row_from_khalil(row.alpha, row.d, row.theta, row.r)
        else:
            a, alpha, d, theta = row.a, row.alpha, row.d, row.theta
        scale = angle if row.type == "revolute" else 1.0
        lower, upper = _bounds(row.limits, scale)
        joints.append(Joint(row.name or f"q{index + 1}", row.type, a, alpha * angle, d, theta * angle, lower, upper))
    with located():
        return Robot(
            joints,
            convention=description.convention,
            world_T_base=None if description.base is None else np.asarray(description.base, dtype=float),
            flange_T_tool=None if description.tool is None else np.asarray(description.tool, dtype=float),
            name=description.name or description.id,
        )


def _bounds(limits, scale: float) -> tuple[float, float]:
    """(lower, upper) in core units from a wire limits object; open sides become ∓inf."""
    if limits is None:
        return -math.inf, math.inf
    lower = -math.inf if limits.lower is None else limits.lower * scale
    upper = math.inf if limits.upper is None else limits.upper * scale
    return lower, upper


def _unit_scale(robot: Robot, unit: AngleUnit) -> np.ndarray:
    """Per-joint factor from the request's unit to the core's (radians, lengths)."""
    return np.where(robot.is_revolute, _DEGREE if unit == "deg" else 1.0, 1.0)


def joints_to_core(robot: Robot, values: Sequence[float] | Sequence[Sequence[float]], unit: AngleUnit,
                   *, batch: bool = False) -> np.ndarray:
    """Joint values from the request's unit to radians, validated for ``robot``."""
    q = check_joint_values(robot, values, batch=batch)
    return q * _unit_scale(robot, unit)


def joints_from_core(robot: Robot, q: np.ndarray, unit: AngleUnit) -> np.ndarray:
    """Joint values from radians to the request's unit."""
    return np.asarray(q, dtype=float) / _unit_scale(robot, unit)


def target_matrix(target: PoseTarget, unit: AngleUnit) -> tuple[np.ndarray, bool]:
    """The 4×4 ``world_T_tool`` a target asks for, and whether it constrains orientation.

    A position-only target returns the identity rotation and ``False``.
    """
    if target.matrix is not None:
        with located("matrix"):
            return check_transform(np.asarray(target.matrix, dtype=float)), True
    T = np.eye(4)
    T[:3, 3] = target.position
    orientation = target.orientation
    if orientation is None:
        return T, False
    angle = _DEGREE if unit == "deg" else 1.0
    with located("orientation"):
        if isinstance(orientation, MatrixOrientation):
            with located("matrix"):
                T[:3, :3] = check_rotation(np.asarray(orientation.matrix, dtype=float))
        elif isinstance(orientation, QuaternionOrientation):
            with located("wxyz"):
                T[:3, :3] = matrix_from_quaternion(check_unit_quaternion(np.asarray(orientation.wxyz, dtype=float)))
        elif isinstance(orientation, EulerZYZOrientation):
            T[:3, :3] = matrix_from_euler_zyz(*(np.asarray(orientation.angles) * angle))
        elif isinstance(orientation, RPYOrientation):
            T[:3, :3] = matrix_from_rpy(*(np.asarray(orientation.angles) * angle))
    return T, True


def poses_from_matrices(matrices: np.ndarray) -> list[dict]:
    """Wire poses for a stack of transforms, shape (N, 4, 4)."""
    matrices = np.asarray(matrices, dtype=float)
    quaternions = quaternions_from_matrices(matrices[:, :3, :3])
    return [
        {"matrix": T.tolist(), "position": T[:3, 3].tolist(), "quaternion_wxyz": quaternion.tolist()}
        for T, quaternion in zip(matrices, quaternions)
    ]


def pose_from_matrix(matrix: np.ndarray) -> dict:
    """The wire pose of one transform, shape (4, 4)."""
    return poses_from_matrices(np.asarray(matrix)[None])[0]


def limits_to_core(robot: Robot, overrides: Sequence | None, unit: AngleUnit) -> Limits:
    """The limits a request works with: the robot's, or the request's overrides converted to radians."""
    if overrides is None:
        return Limits.of(robot)
    if len(overrides) != robot.dof:
        raise InvalidInputError(f"expected limits for {robot.dof} joints, got {len(overrides)}")
    bounds = [_bounds(o, factor) for o, factor in zip(overrides, _unit_scale(robot, unit))]
    return Limits.checked(robot, np.array([b[0] for b in bounds]), np.array([b[1] for b in bounds]))


def violation_to_wire(robot: Robot, violation: Violation, unit: AngleUnit) -> dict:
    scale = float(_unit_scale(robot, unit)[violation.joint])

    def bound(value: float) -> float | None:
        # An open side is ±inf in the core and null on the wire (JSON has no infinity).
        return value / scale if math.isfinite(value) else None

    return {"joint": violation.joint, "value": violation.value / scale,
            "lower": bound(violation.lower), "upper": bound(violation.upper)}
