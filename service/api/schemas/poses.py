"""Poses: targets in requests and poses in responses."""

from __future__ import annotations

from typing import Annotated, Literal, Union

from pydantic import Field, field_validator, model_validator
from pydantic_core import PydanticCustomError

from ...robots.orientations import EulerZYZOrientation, MatrixOrientation, QuaternionOrientation, RPYOrientation
from ...kinematics.ik import DEFAULT_ROLL_SAMPLES, MAX_ROLL_ROWS
from .common import ApiModel, Matrix4, Number, RealMatrix4, RealVector3, RealVector4, Vector3, Vector4


class DirectionOrientation(ApiModel):
    """Position + tool direction (IK targets of arms of 5 joints or more): the tool axis `tool_axis` (tool frame)
    must point along `world_direction` (world frame); the roll about it is left free. Neither needs to be a unit
    vector.

    An arm of 6 or more joints reaches such a target along a continuous family over the roll ψ of the tool about
    `tool_axis`. It is solved completely at sampled rolls (`roll_samples`, or `roll_values`): at each roll the
    full pose with rotation R_t · Rot(tool_axis, ψ), where R_t is the shortest rotation taking `tool_axis` onto
    `world_direction` (a half turn about an axis perpendicular to `tool_axis` when the two are opposite). Each
    solution reports its roll in `free_values` under the key `"roll"` (the request's angle unit, in (−π, π]);
    `solver.complete` means every solution at each sampled roll; with `reference` the roll is also searched
    continuously between the samples, so the first solution is the nearest over the whole family. A redundant arm
    samples its free joints (`free_joints`) at each roll as well. An answer with no solution is `not_found` (other
    rolls may reach the target), unless the position is beyond the arm's reach (`unreachable`)."""

    type: Literal["direction"] = Field(description="position + tool direction")
    tool_axis: Vector3 = Field(default_factory=lambda: [0.0, 0.0, 1.0],
                               description="the tool axis to align, in the tool frame (default z)")
    world_direction: Vector3 = Field(description="where the tool axis must point, in the world frame")
    roll_samples: int | None = Field(
        None, ge=1, le=MAX_ROLL_ROWS,
        description=f"arms of 6 or more joints: how many rolls about the tool axis to solve at, evenly over the "
                    f"turn from −π (default {DEFAULT_ROLL_SAMPLES}, 10° apart). Rolls × a redundant arm's free "
                    f"values: at most {MAX_ROLL_ROWS} per target. Not for 5-joint arms, whose roll is not free.")
    roll_values: list[Number] | None = Field(
        None, min_length=1, max_length=MAX_ROLL_ROWS,
        description="arms of 6 or more joints: the rolls about the tool axis to solve at, in the request's angle "
                    "unit, instead of roll_samples")

    @model_validator(mode="after")
    def _one_roll_form(self) -> "DirectionOrientation":
        if self.roll_samples is not None and self.roll_values is not None:
            raise ValueError("give either 'roll_samples' or 'roll_values', not both")
        return self


Orientation = Annotated[
    Union[MatrixOrientation, QuaternionOrientation, EulerZYZOrientation, RPYOrientation, DirectionOrientation],
    Field(discriminator="type"),
]


def _xyzw_hint(xyzw: list) -> str:
    """The wxyz form of a quaternion a client sent scalar last, for the error message."""
    w = xyzw[3]
    return f'{{"type": "quaternion", "wxyz": [{w}, {xyzw[0]}, {xyzw[1]}, {xyzw[2]}]}}'


def _scalar_last_quaternion(orientation: dict) -> list | None:
    """The (x, y, z, w) values of an orientation written in a scalar-last form, or None for any other form."""
    if {"x", "y", "z", "w"} <= orientation.keys():
        return [orientation[key] for key in "xyzw"]
    if isinstance(orientation.get("xyzw"), list) and len(orientation["xyzw"]) == 4:
        return orientation["xyzw"]
    return None


class PoseTarget(ApiModel):
    """A target pose, in the world frame, lengths in the robot's length unit. One of:

    * ``matrix``: a 4×4 homogeneous transform. ``position`` and ``quaternion_wxyz`` may accompany it, so that
      a pose from a forward-kinematics answer is accepted as it stands; they must then agree with the matrix
      (within 1e-6, relative to the position's size).
    * ``position`` with an ``orientation`` (one of the tagged variants) or a ``quaternion_wxyz``.
    * ``position`` alone: the position only is solved (arms with fewer than 6 joints).
    """

    matrix: Matrix4 | None = Field(None, description="world_T_tool, 4×4, row-major; last row 0 0 0 1")
    position: Vector3 | None = Field(None, description="tool origin in the world frame, robot length unit")
    orientation: Orientation | None = Field(
        None, description="tool orientation in the world frame; with position only, leave out for position-only IK")
    quaternion_wxyz: Vector4 | None = Field(
        None, description="tool orientation as a unit quaternion, scalar first (w, x, y, z), as forward "
                          "kinematics returns it; the same as orientation {type: quaternion, wxyz}")

    @field_validator("orientation", mode="before")
    @classmethod
    def _name_the_quaternion_order(cls, value: object) -> object:
        # A ROS-style {x, y, z, w} or an "xyzw" list would otherwise meet the union's discriminator jargon,
        # or worse, be read in the wrong order.
        if isinstance(value, dict):
            xyzw = _scalar_last_quaternion(value)
            if xyzw is not None:
                raise PydanticCustomError(
                    "quaternion_order",
                    "quaternions are taken scalar first, as {example} (w, x, y, z); this one looks scalar last "
                    "(x, y, z, w, as ROS and scipy write it)", {"example": _xyzw_hint(xyzw)})
        return value

    @model_validator(mode="after")
    def _one_form(self) -> "PoseTarget":
        if self.matrix is None and self.position is None:
            raise ValueError("give either 'matrix' or 'position' (with an optional 'orientation')")
        if self.matrix is not None and self.orientation is not None:
            raise ValueError("'orientation' goes with 'position'; a 'matrix' already holds the orientation")
        if self.orientation is not None and self.quaternion_wxyz is not None:
            raise ValueError("give the orientation once: 'orientation' or 'quaternion_wxyz', not both")
        return self


class Pose(ApiModel):
    """A pose in the world frame, in three forms so that no client has to convert."""

    matrix: RealMatrix4 = Field(description="the pose as a 4×4 homogeneous transform, row-major")
    position: RealVector3 = Field(description="the frame's origin, robot length unit")
    quaternion_wxyz: RealVector4 = Field(description="unit quaternion (w, x, y, z) with w ≥ 0")


class NamedPose(Pose):
    """The pose of one named frame."""

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
