"""Scalar and array types shared by every schema."""

from __future__ import annotations

from typing import Annotated, Any, get_args

from pydantic import AllowInfNan, Field, Strict, ValidationError, ValidatorFunctionWrapHandler, WrapValidator
from pydantic_core import InitErrorDetails, PydanticCustomError
from pydantic_core.core_schema import ErrorType

# The description fields live with the descriptions (service.robots); request schemas use them from here.
from ...robots._fields import (  # noqa: F401
    MAX_MAGNITUDE,
    AngleUnit,
    ApiModel,
    Matrix3,
    Matrix4,
    Matrix4Row,
    Number,
    RobotId,
    Vector3,
    Vector4,
    square_shape,
)

#: A JSON boolean in a request: true or false only (0, 1 and "yes" are refused, as the spec says).
Flag = Annotated[bool, Strict()]

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


#: Items of a long request list (batch targets, FK rows, trajectory samples) validated per pydantic call.
VALIDATION_PIECE = 256
_BUILTIN_ERROR_TYPES = frozenset(get_args(ErrorType))


def _validate_in_pieces(value: Any, handler: ValidatorFunctionWrapHandler) -> Any:
    """Validate a long list :data:`VALIDATION_PIECE` items per call, with the errors' indices as in one call.

    One pydantic call holds the GIL from start to end: a 1 MB batch body took 145–251 ms, during which the
    server's loop (and ``/healthz``) could not run. Between the calls the interpreter hands the GIL to a thread
    that waits for it (within its switch interval), so the server answers while a large body is validated. Only
    for lists whose constraints hold piece by piece (a minimum length of one, no maximum).
    """
    if not isinstance(value, list) or len(value) <= VALIDATION_PIECE:
        return handler(value)
    validated: list = []
    errors: list[InitErrorDetails] = []
    for start in range(0, len(value), VALIDATION_PIECE):
        try:
            validated.extend(handler(value[start:start + VALIDATION_PIECE]))
        except ValidationError as error:
            errors.extend(_shifted(error, start))
    if errors:
        raise ValidationError.from_exception_data("list", errors)
    return validated


def _shifted(error: ValidationError, offset: int) -> list[InitErrorDetails]:
    """``error``'s line errors with their item index moved by ``offset`` (type, message and input kept)."""
    shifted = []
    for line in error.errors():
        loc = line["loc"]
        if loc and isinstance(loc[0], int):
            loc = (loc[0] + offset, *loc[1:])
        kind = line["type"]
        if kind not in _BUILTIN_ERROR_TYPES:  # a validator's own error type: its message as it was worded
            kind = PydanticCustomError(kind, line["msg"].replace("{", "{{").replace("}", "}}"))
        shifted.append(InitErrorDetails(type=kind, loc=loc, input=line["input"], ctx=line.get("ctx", {})))
    return shifted


#: Validate this (long) list in pieces: see :func:`_validate_in_pieces`.
IN_PIECES = WrapValidator(_validate_in_pieces)
