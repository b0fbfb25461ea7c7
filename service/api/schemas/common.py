"""Scalar and array types shared by every schema."""

from __future__ import annotations

from typing import Annotated

from pydantic import AllowInfNan, Field

# The description fields live with the descriptions (service.robots); request schemas use them from here.
from ...robots._fields import (  # noqa: F401
    MAX_MAGNITUDE,
    AngleUnit,
    ApiModel,
    Matrix4,
    Matrix4Row,
    Number,
    RobotId,
    Vector3,
)

Vector4 = Annotated[list[Number], Field(min_length=4, max_length=4)]
Matrix3 = Annotated[list[Vector3], Field(min_length=3, max_length=3, description="3×3, row-major")]
#: Numbers in responses: finite, but not bounded (a pose can sum many request-sized lengths).
Real = Annotated[float, AllowInfNan(False)]
RealVector3 = Annotated[list[Real], Field(min_length=3, max_length=3)]
RealVector4 = Annotated[list[Real], Field(min_length=4, max_length=4)]
RealMatrix4 = Annotated[
    list[RealVector4],
    Field(min_length=4, max_length=4, description="4×4 homogeneous transform, row-major; last row 0 0 0 1"),
]


class RequestFrames(ApiModel):
    """Per-request base and tool: they replace the robot's own for this request only."""

    base: Matrix4 | None = Field(None, description="world_T_base for this request, replacing the robot's own; "
                                                   "validated as a rigid transform")
    tool: Matrix4 | None = Field(None, description="flange_T_tool for this request, replacing the robot's own; "
                                                   "validated as a rigid transform")


JOINT_NAMES_FIELD = Field(description="the robot's joint names, in the order of every joint vector in this answer")


ANGLE_UNIT_FIELD = Field(
    "rad",
    description="Unit of every revolute joint value and every angle in this request and its response. "
    "Prismatic joint values are always in the robot's length unit.",
)
