"""Joint-limit checks."""

from __future__ import annotations

from pydantic import Field

from .common import ANGLE_UNIT_FIELD, JOINT_NAMES_FIELD, AngleUnit, ApiModel, Number, RequestFrames
from ...robots.schemas import RobotDescription


class JointLimitsOverride(ApiModel):
    """Bounds for one joint in a request: the request's angle unit (revolute), the robot's length unit (prismatic).

    Inclusive; a null side is open. lower > upper is a 422 that names the joint (checked against the robot).
    """

    lower: Number | None
    upper: Number | None


class LimitViolation(ApiModel):
    """One joint outside its inclusive bounds, in the request's angle unit / the robot's length unit."""

    joint: int = Field(description="0-based joint index")
    value: float
    lower: float | None = Field(description="null when the range is open below")
    upper: float | None = Field(description="null when the range is open above")


class LimitsRequest(RequestFrames):
    """Limits concern joint values only: a base or tool given here is validated but changes no answer."""

    joints: list[list[Number]] = Field(min_length=1, description="joint vectors to check")
    angle_unit: AngleUnit = ANGLE_UNIT_FIELD
    limits: list[JointLimitsOverride | None] | None = Field(
        None, description="replace the robot's limits: one entry per joint, null for an unlimited joint")


class LimitsInlineRequest(LimitsRequest):
    robot: RobotDescription


class LimitsResult(ApiModel):
    within_limits: bool
    violations: list[LimitViolation]
    equivalent: list[float] | None = Field(
        description="when the vector is out of range only by whole turns of revolute joints: the 2π-equivalent "
                    "that fits (nearest to the given values); null otherwise or when already within limits")


class LimitsResponse(ApiModel):
    robot_id: str
    joint_names: list[str] = JOINT_NAMES_FIELD
    tolerance: float = Field(description="inclusive-bound tolerance: radians (revolute), fraction of the robot's "
                                         "size (prismatic)")
    results: list[LimitsResult]
