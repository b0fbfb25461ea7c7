"""Forward-kinematics requests and responses."""

from __future__ import annotations

from pydantic import Field

from .common import ANGLE_UNIT_FIELD, JOINT_NAMES_FIELD, AngleUnit, ApiModel, Number, RequestFrames, RobotId
from .poses import NamedPose, Pose
from ...robots.schemas import RobotDescription


class FKRequest(RequestFrames):
    joints: list[Number] = Field(description="one value per joint, in table order")
    frames: bool = Field(False, description="also return the pose of every link frame")
    angle_unit: AngleUnit = ANGLE_UNIT_FIELD


class FKInlineRequest(FKRequest):
    robot: RobotDescription


class FKResponse(ApiModel):
    robot_id: RobotId
    joint_names: list[str] = JOINT_NAMES_FIELD
    pose: Pose = Field(description="world_T_tool")
    frames: list[NamedPose] | None = Field(
        None, description="with frames=true: the base frame, every link frame (named by its joint), and the tool"
    )


class FKBatchRequest(RequestFrames):
    joints: list[list[Number]] = Field(min_length=1, description="one row of joint values per configuration")
    angle_unit: AngleUnit = ANGLE_UNIT_FIELD


class FKBatchResponse(ApiModel):
    robot_id: RobotId
    joint_names: list[str] = JOINT_NAMES_FIELD
    poses: list[Pose] = Field(description="one pose per row, in request order")
