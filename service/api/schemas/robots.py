"""Robot descriptions: the format of the catalogue files and of inline robots.

The ``d`` property is declared last in each joint schema, and joints forbid
extra properties: generated Python clients (openapi-python-client) bind the
incoming dict to a local named ``d`` and break otherwise (see api.md).
"""

from __future__ import annotations

from enum import Enum
from typing import Annotated, Literal, Union

from pydantic import Field, RootModel, model_validator

from .common import AngleUnit, Matrix4, Number, RobotId, ApiModel

class JointType(str, Enum):
    revolute = "revolute"
    prismatic = "prismatic"


class Convention(str, Enum):
    """standard: DH (Spong/Paul); modified: Craig; khalil: Khalil–Kleinfinger."""

    standard = "standard"
    modified = "modified"
    khalil = "khalil"


class RobotParameters(RootModel[dict[str, Number]]):
    """Values given to the source's symbolic lengths, by symbol (informational)."""


class JointLimits(ApiModel):
    """Inclusive bounds on the joint variable q: the robot's angle unit for revolute joints, its length unit for
    prismatic ones. A null bound is open on that side (a slide that only has to stay positive: lower 0, upper null).
    """

    lower: Number | None
    upper: Number | None

    @model_validator(mode="after")
    def _ordered(self) -> "JointLimits":
        if self.lower is not None and self.upper is not None and self.lower > self.upper:
            raise ValueError(f"lower limit {self.lower:g} is greater than upper limit {self.upper:g}")
        return self


class DHJoint(ApiModel):
    """One row of a standard (Spong) or modified (Craig) DH table.

    Standard: A_i = Rot_z(theta)·Trans_z(d)·Trans_x(a)·Rot_x(alpha). Modified: the row holds
    a_{i-1}, alpha_{i-1}, d_i, theta_i and T_i = Rot_x(alpha)·Trans_x(a)·Rot_z(theta)·Trans_z(d).
    The value of the joint's variable parameter (theta or d) is an offset added to q.
    """

    name: str | None = Field(None, max_length=64, description="defaults to q1, q2, …")
    type: JointType = "revolute"
    a: Number = 0.0
    alpha: Number = 0.0
    theta: Number = 0.0
    limits: JointLimits | None = None
    d: Number = 0.0


class KhalilJoint(ApiModel):
    """One row of a Khalil–Kleinfinger table: T_j = Rot_x(alpha_j)·Trans_x(d_j)·Rot_z(theta_j)·Trans_z(r_j).

    ``d`` is the distance along x_{j-1} (Craig's a_{j-1}); ``r`` the distance along z_j.
    """

    name: str | None = Field(None, max_length=64, description="defaults to q1, q2, …")
    type: JointType = "revolute"
    alpha: Number = 0.0
    theta: Number = 0.0
    r: Number = 0.0
    limits: JointLimits | None = None
    d: Number = 0.0


class TargetKind(str, Enum):
    """An IK target kind (api.md): a full pose, a position only, or a position + tool direction."""

    pose = "pose"
    position = "position"
    position_direction = "position_direction"


class _RobotFields(ApiModel):
    id: RobotId = "inline"
    name: str = Field("", max_length=200)
    source: str = Field("", max_length=2000, description="where the parameters come from")
    angle_unit: AngleUnit = Field("rad", description="unit of alpha, theta and revolute limits in this description")
    length_unit: str = Field("m", max_length=16)
    parameters: RobotParameters | None = Field(
        None, description="values given to the source's symbolic lengths (informational)"
    )
    limits_source: str | None = Field(None, max_length=2000, description="where the joint limits come from")
    notes: str | None = Field(None, max_length=4000)
    base: Matrix4 | None = Field(None, description="world_T_base; identity when null")
    tool: Matrix4 | None = Field(None, description="flange_T_tool; identity when null")
    target_kinds: list[TargetKind] = Field(
        default_factory=list, max_length=3,
        description="in GET /v1/robots/{robot_id}: the IK target kinds the arm takes (a full pose, a position, a "
                    "position + tool direction); ignored in requests")


class DHRobot(_RobotFields):
    """A robot described by a standard (Spong/Paul) or modified (Craig) DH table."""

    convention: Literal["standard", "modified"]
    joints: list[DHJoint] = Field(min_length=1)


class KhalilRobot(_RobotFields):
    """A robot described by a Khalil–Kleinfinger table."""

    convention: Literal["khalil"]
    joints: list[KhalilJoint] = Field(min_length=1)


RobotDescription = Annotated[Union[DHRobot, KhalilRobot], Field(discriminator="convention")]


class RobotSummary(ApiModel):
    id: RobotId
    name: str
    dof: int
    convention: Convention
    joint_types: list[JointType]
    source: str


class RobotList(ApiModel):
    robots: list[RobotSummary]
