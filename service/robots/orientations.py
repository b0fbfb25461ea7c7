"""Orientations: the tagged variants of a rotation on the wire, and the one conversion of each into a matrix.

Pose targets (``service.api``) and the boxes of robot descriptions (:mod:`.schemas`) take the same variants; the
angles of the Euler and RPY variants are in the angle unit of the request or description that carries them.
"""

from __future__ import annotations

from typing import Annotated, Literal, Union

import numpy as np
from pydantic import Field

from ..kinematics import (
    InvalidInputError,
    check_rotation,
    check_unit_quaternion,
    matrix_from_euler_zyz,
    matrix_from_quaternion,
    matrix_from_rpy,
)
from ._fields import ApiModel, Matrix3, Vector3, Vector4


class MatrixOrientation(ApiModel):
    """A 3×3 rotation matrix, orthonormal within 1e-6 with determinant +1."""

    type: Literal["matrix"] = Field(description="names this variant")
    matrix: Matrix3 = Field(description="world_R_tool, 3×3, row-major")


class QuaternionOrientation(ApiModel):
    """A unit quaternion, scalar first (w, x, y, z), norm within 1e-6 of 1.

    ROS, scipy and Eigen's coefficient order put the scalar last (x, y, z, w): reorder before sending.
    ``[0, 0, 0, 1]`` here is w = 0, z = 1, a half turn about z, not the identity ``[1, 0, 0, 0]``.
    """

    type: Literal["quaternion"] = Field(description="names this variant")
    wxyz: Vector4 = Field(description="(w, x, y, z), scalar first")


class EulerZYZOrientation(ApiModel):
    """ZYZ Euler angles (φ, θ, ψ): R = Rot_z(φ)·Rot_y(θ)·Rot_z(ψ), in the request's angle unit."""

    type: Literal["euler_zyz"] = Field(description="names this variant")
    angles: Vector3 = Field(description="(φ, θ, ψ), the request's angle unit")


class RPYOrientation(ApiModel):
    """Roll, pitch, yaw about the fixed X, Y, Z axes: R = Rot_z(yaw)·Rot_y(pitch)·Rot_x(roll), in the request's angle unit."""

    type: Literal["rpy"] = Field(description="names this variant")
    angles: Vector3 = Field(description="(roll, pitch, yaw), the request's angle unit")


RigidOrientation = Annotated[
    Union[MatrixOrientation, QuaternionOrientation, EulerZYZOrientation, RPYOrientation],
    Field(discriminator="type"),
]


def rotation_from_orientation(orientation: MatrixOrientation | QuaternionOrientation | EulerZYZOrientation
                              | RPYOrientation, radians_per_unit: float) -> np.ndarray:
    """The rotation matrix, shape (3, 3), of a wire orientation whose angles are in a unit of ``radians_per_unit``.

    Raises :class:`InvalidInputError` located at the offending field (``("matrix", 1, 2)``, ``("wxyz",)``).
    """
    try:
        if isinstance(orientation, MatrixOrientation):
            return check_rotation(np.asarray(orientation.matrix, dtype=float))
        if isinstance(orientation, QuaternionOrientation):
            return matrix_from_quaternion(check_unit_quaternion(np.asarray(orientation.wxyz, dtype=float)))
    except InvalidInputError as error:
        raise error.relocated("matrix" if isinstance(orientation, MatrixOrientation) else "wxyz") from None
    angles = np.asarray(orientation.angles, dtype=float) * radians_per_unit
    if isinstance(orientation, EulerZYZOrientation):
        return matrix_from_euler_zyz(*angles)
    return matrix_from_rpy(*angles)
