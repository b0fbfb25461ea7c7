"""Scalar and array types shared by every schema."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import AllowInfNan, BaseModel, ConfigDict, Field, Strict

#: A JSON number that must be finite: strings, booleans, NaN and ±inf are rejected.
Number = Annotated[float, Strict(), AllowInfNan(False)]
AngleUnit = Literal["rad", "deg"]
Vector3 = Annotated[list[Number], Field(min_length=3, max_length=3)]
Vector4 = Annotated[list[Number], Field(min_length=4, max_length=4)]
Matrix3 = Annotated[list[Vector3], Field(min_length=3, max_length=3, description="3×3, row-major")]
Matrix4Row = Annotated[list[Number], Field(min_length=4, max_length=4)]
Matrix4 = Annotated[
    list[Matrix4Row],
    Field(min_length=4, max_length=4, description="4×4 homogeneous transform, row-major; last row 0 0 0 1"),
]
RobotId = Annotated[str, Field(pattern=r"^[a-z0-9][a-z0-9_-]{0,63}$", examples=["puma560_modified"])]


class ApiModel(BaseModel):
    """Base for request bodies: unknown fields are errors, not silently dropped."""

    model_config = ConfigDict(extra="forbid")


ANGLE_UNIT_FIELD = Field(
    "rad",
    description="Unit of every revolute joint value and every angle in this request and its response. "
    "Prismatic joint values are always in the robot's length unit.",
)
