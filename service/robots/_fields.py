"""Scalar and array field types of robot descriptions, shared with the request schemas of the web layer.

They depend on pydantic only, so that description files can be validated without the web framework.
"""

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


def square_shape(size: int, what: str):
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


Vector3 = Annotated[list[Number], Field(min_length=3, max_length=3)]
Vector4 = Annotated[list[Number], Field(min_length=4, max_length=4)]
Matrix3 = Annotated[list[Vector3], square_shape(3, "rotation matrix"),
                    Field(min_length=3, max_length=3, description="3×3, row-major")]
Matrix4Row = Annotated[list[Number], Field(min_length=4, max_length=4)]
Matrix4 = Annotated[
    list[Matrix4Row],
    square_shape(4, "homogeneous transform"),
    Field(min_length=4, max_length=4, description="4×4 homogeneous transform, row-major; last row 0 0 0 1"),
]
RobotId = Annotated[str, Field(pattern=r"^[a-z0-9][a-z0-9_-]{0,63}$", examples=["puma560_modified"])]


class ApiModel(BaseModel):
    """Base for request bodies: unknown fields are errors, not silently dropped; a dump uses the wire names (a
    capsule's ``from``, the collision options' ``self``), so that what is dumped validates again."""

    # Enums are named schemas in the spec (clean names in generated clients), but validated values are plain
    # strings, so code compares them with string literals.
    model_config = ConfigDict(extra="forbid", use_enum_values=True, serialize_by_alias=True)


#: Tags pydantic inserts into locations inside tagged unions: robot description forms and orientation types.
_UNION_TAGS = {"dh", "standard", "modified", "khalil", "urdf", "screws", "matrix", "quaternion", "euler_zyz", "rpy",
               "objects", "matrices"}
_UNION_FIELDS = {"robot", "orientation", "targets"}
#: Tags pydantic inserts after the index of an item of a list of unions: link shapes.
_ITEM_TAGS = {"capsule", "sphere", "box"}
_ITEM_UNION_FIELDS = {"collision", "obstacles"}


def field_location(loc: tuple | list) -> list[str | int]:
    """A validation location as a client reads it: the union tags pydantic inserts are left out.

    ``("body", "robot", "standard", "joints", 0)`` becomes ``["body", "robot", "joints", 0]``; a top-level tag
    (a description file validated on its own) is dropped too, and so is the tag after a link shape's index:
    ``("collision", 0, "capsule", "capsule", "radius")`` becomes ``["collision", 0, "capsule", "radius"]`` (and so
    for a request's ``obstacles``).
    """
    parts = [part if isinstance(part, (str, int)) else str(part) for part in loc]
    return [part for i, part in enumerate(parts)
            if not (part in _UNION_TAGS and (i == 0 or parts[i - 1] in _UNION_FIELDS))
            and not (part in _ITEM_TAGS and i >= 2 and isinstance(parts[i - 1], int)
                     and parts[i - 2] in _ITEM_UNION_FIELDS)]
