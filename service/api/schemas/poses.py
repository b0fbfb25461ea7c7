"""Poses: targets in requests and poses in responses."""

from __future__ import annotations

from typing import Annotated, Literal, Union

from pydantic import Field, model_validator

from .common import ApiModel, Matrix3, Matrix4, Number, RealMatrix4, RealVector3, RealVector4, Vector3, Vector4


class MatrixOrientation(ApiModel):
    """A 3×3 rotation matrix, orthonormal within 1e-6 with determinant +1."""

    type: Literal["matrix"]
    matrix: Matrix3


class QuaternionOrientation(ApiModel):
    """A unit quaternion (w, x, y, z), norm within 1e-6 of 1."""

    type: Literal["quaternion"]
    wxyz: Vector4


class EulerZYZOrientation(ApiModel):
    """ZYZ Euler angles (φ, θ, ψ): R = Rot_z(φ)·Rot_y(θ)·Rot_z(ψ), in the request's angle unit."""

    type: Literal["euler_zyz"]
    angles: Vector3


class RPYOrientation(ApiModel):
    """Roll, pitch, yaw about the fixed X, Y, Z axes: R = Rot_z(yaw)·Rot_y(pitch)·Rot_x(roll), in the request's angle unit."""

    type: Literal["rpy"]
    angles: Vector3


class DirectionOrientation(ApiModel):
    """Position + tool direction (IK targets of 5-joint arms): the tool axis `tool_axis` (tool frame) must point
    along `world_direction` (world frame); the roll about it is left free. Neither needs to be a unit vector."""

    type: Literal["direction"]
    tool_axis: Vector3 = Field(default_factory=lambda: [0.0, 0.0, 1.0])
    world_direction: Vector3


Orientation = Annotated[
    Union[MatrixOrientation, QuaternionOrientation, EulerZYZOrientation, RPYOrientation, DirectionOrientation],
    Field(discriminator="type"),
]


class PoseTarget(ApiModel):
    """A target pose: either ``matrix`` (4×4), or ``position`` with an optional ``orientation``.

    Leaving out the orientation asks for the position only (robots with fewer than 6 joints).
    Lengths are in the robot's length unit, expressed in the world frame.
    """

    matrix: Matrix4 | None = None
    position: Vector3 | None = None
    orientation: Orientation | None = None

    @model_validator(mode="after")
    def _one_form(self) -> "PoseTarget":
        if (self.matrix is None) == (self.position is None):
            raise ValueError("give either 'matrix' or 'position' (with an optional 'orientation'), not both or neither")
        if self.matrix is not None and self.orientation is not None:
            raise ValueError("'orientation' goes with 'position'; a 'matrix' already holds the orientation")
        return self


class Pose(ApiModel):
    """A pose in the world frame, in three forms so that no client has to convert."""

    matrix: RealMatrix4
    position: RealVector3
    quaternion_wxyz: RealVector4 = Field(description="unit quaternion (w, x, y, z) with w ≥ 0")


class NamedPose(Pose):
    name: str = Field(description="'base', the joint name of the link frame, or 'tool'")


# Re-exported so that the number type is visible where poses are built.
__all__ = [
    "DirectionOrientation",
    "EulerZYZOrientation",
    "MatrixOrientation",
    "NamedPose",
    "Number",
    "Orientation",
    "Pose",
    "PoseTarget",
    "QuaternionOrientation",
    "RPYOrientation",
]
