"""Forward-kinematics requests and responses."""

from __future__ import annotations

from typing import Annotated

from pydantic import Field

from .collisions import CLEARANCE_FIELD, COLLISIONS_FIELD, CollisionOptions, CollisionPair
from .common import (ANGLE_UNIT_FIELD, IN_PIECES, JOINT_NAMES_FIELD, AngleUnit, ApiModel, Flag, Number, RequestFrames,
                     RobotId)
from .poses import NamedPose, Pose
from ...robots.schemas import RobotDescription


class FKRequest(RequestFrames):
    """Joint values whose tool pose (and link frames) to compute."""

    joints: list[Number] = Field(description="one value per joint, in table order")
    frames: Flag = Field(False, description="also return the pose of every link frame")
    angle_unit: AngleUnit = ANGLE_UNIT_FIELD
    collisions: CollisionOptions | None = Field(
        None, description="check these joint values against the robot's own link shapes and these obstacles: the "
                          "answer then carries clearance and collisions (filter does not apply)")


class FKInlineRequest(FKRequest):
    """Forward kinematics for a robot described in the request body."""

    robot: RobotDescription = Field(description="the robot, described as in the catalogue")


class FKResponse(ApiModel):
    """The tool pose, and with frames=true every link frame's."""

    robot_id: RobotId = Field(description="the catalogue id, or the inline robot's id")
    joint_names: list[str] = JOINT_NAMES_FIELD
    pose: Pose = Field(description="world_T_tool")
    frames: list[NamedPose] | None = Field(
        None, description="with frames=true: the base frame, every link frame (named by its joint), and the tool"
    )
    clearance: float | None = CLEARANCE_FIELD
    collisions: list[CollisionPair] | None = COLLISIONS_FIELD


class FKBatchRequest(RequestFrames):
    """Many joint vectors, one tool pose each (vectorised)."""

    joints: Annotated[list[list[Number]], IN_PIECES] = Field(min_length=1, description="one row of joint values per configuration")
    angle_unit: AngleUnit = ANGLE_UNIT_FIELD


class FKBatchResponse(ApiModel):
    """One tool pose per row of joint values."""

    robot_id: RobotId = Field(description="the catalogue id")
    joint_names: list[str] = JOINT_NAMES_FIELD
    poses: list[Pose] = Field(description="one pose per row, in request order")
