"""Render requests: pictures of an arm at one or more joint vectors (the answer is image/svg+xml)."""

from __future__ import annotations

from enum import Enum

from pydantic import Field

from .collisions import CollisionOptions
from .common import ANGLE_UNIT_FIELD, AngleUnit, Number, RequestFrames
from ...robots.schemas import RobotDescription

#: Most configurations one picture draws (each is a panel of its own).
MAX_RENDER_CONFIGURATIONS = 256


class RenderView(str, Enum):
    """Direction the picture looks from, z up: iso from (1, −1, 1); front from −y; side from +x; top from +z."""

    iso = "iso"
    front = "front"
    side = "side"
    top = "top"


class RenderRequest(RequestFrames):
    """The arm in each configuration, drawn side by side with one projection and scale for all."""

    joints: list[list[Number]] = Field(
        min_length=1, max_length=MAX_RENDER_CONFIGURATIONS,
        description="one joint vector per panel, in table order and the request's angle unit")
    view: RenderView = Field("iso", description="projection of every panel")
    angle_unit: AngleUnit = ANGLE_UNIT_FIELD
    captions: list[str] | None = Field(
        None, description="one caption per joint vector (a newline starts a second line); default #1, #2, …")
    columns: int | None = Field(None, ge=1, le=32, description="panels per row; default up to 4")
    panel_size: int = Field(300, ge=120, le=1200, description="width and drawing height of one panel, px")
    title: str | None = Field(None, max_length=200, description="a line of text above the panels")
    collisions: CollisionOptions | None = Field(
        None, description="draw the obstacles and the robot's link shapes (capsules, spheres, boxes) in every panel, "
                          "the links and obstacles of each pair closer than the margin in red, with a line that "
                          "gives the clearance or the colliding pairs; checked as IK and FK check them ('filter' "
                          "is not used: every panel is drawn). The robot must carry link shapes")


class RenderInlineRequest(RenderRequest):
    """A picture of a robot described in the request body."""

    robot: RobotDescription = Field(description="the robot, described as in the catalogue")
