"""Scalar and array types shared by every schema."""

from __future__ import annotations

from enum import Enum
from typing import Annotated

from pydantic import AllowInfNan, BaseModel, BeforeValidator, ConfigDict, Field, Strict
from pydantic_core import PydanticCustomError

#: Largest magnitude of any number in a request. Float64 spacing at 1e6 is 1.2e-10, still below the service's
#: tolerances (1e-9), so every answer inside the bound keeps the promised accuracy, and no product or sum of such
#: values over KIN_MAX_JOINTS joints can overflow. Beyond it (1e308, say) answers would be overflow or rounding
#: noise, so such values are refused with a 422 that names the field.
MAX_MAGNITUDE = 1e6

#: A JSON number in a request: finite and within ±MAX_MAGNITUDE; strings, booleans, NaN and ±inf are rejected.
Number = Annotated[float, Strict(), AllowInfNan(False), Field(ge=-MAX_MAGNITUDE, le=MAX_MAGNITUDE)]


class AngleUnit(str, Enum):
    """Unit of angles: radians or degrees."""

    rad = "rad"
    deg = "deg"


def _square_shape(size: int, what: str):
    """A before-validator that names the expected shape when a matrix has the wrong number of rows or entries
    (rather than pydantic's generic list-length message)."""

    def check(value: object) -> object:
        if isinstance(value, list):
            if len(value) != size:
                raise PydanticCustomError("matrix_shape", "a {size}×{size} {what} is expected, got {rows} rows",
                                          {"size": size, "what": what, "rows": len(value)})
            for index, row in enumerate(value):
                if isinstance(row, list) and len(row) != size:
                    raise PydanticCustomError(
                        "matrix_shape", "a {size}×{size} {what} is expected, row {index} has {entries} entries",
                        {"size": size, "what": what, "index": index, "entries": len(row)})
        return value

    return BeforeValidator(check)


#: A JSON boolean in a request: true or false only (0, 1 and "yes" are refused, as the spec says).
Flag = Annotated[bool, Strict()]

Vector3 = Annotated[list[Number], Field(min_length=3, max_length=3)]
Vector4 = Annotated[list[Number], Field(min_length=4, max_length=4)]
Matrix3 = Annotated[list[Vector3], _square_shape(3, "rotation matrix"),
                    Field(min_length=3, max_length=3, description="3×3, row-major")]
Matrix4Row = Annotated[list[Number], Field(min_length=4, max_length=4)]
Matrix4 = Annotated[
    list[Matrix4Row],
    _square_shape(4, "homogeneous transform"),
    Field(min_length=4, max_length=4, description="4×4 homogeneous transform, row-major; last row 0 0 0 1"),
]
#: Numbers in responses: finite, but not bounded (a pose can sum many request-sized lengths).
Real = Annotated[float, AllowInfNan(False)]
RealVector3 = Annotated[list[Real], Field(min_length=3, max_length=3)]
RealVector4 = Annotated[list[Real], Field(min_length=4, max_length=4)]
RealMatrix4 = Annotated[
    list[RealVector4],
    Field(min_length=4, max_length=4, description="4×4 homogeneous transform, row-major; last row 0 0 0 1"),
]
RobotId = Annotated[str, Field(pattern=r"^[a-z0-9][a-z0-9_-]{0,63}$", examples=["puma560_modified"])]


class ApiModel(BaseModel):
    """Base for request bodies: unknown fields are errors, not silently dropped."""

    # Enums are named schemas in the spec (clean names in generated clients), but validated values are plain
    # strings, so code compares them with string literals.
    model_config = ConfigDict(extra="forbid", use_enum_values=True)


ANGLE_UNIT_FIELD = Field(
    "rad",
    description="Unit of every revolute joint value and every angle in this request and its response. "
    "Prismatic joint values are always in the robot's length unit.",
)
