"""Request dependencies: settings, the catalogue, and the robot a request is about."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from fastapi import Path, Request

from ..robots.catalogue import Catalogue
from ..config import Settings
from ..kinematics import Robot
from ..robots.build import robot_from_description
from ..robots.schemas import AnyRobotDescription
from .boundary import located
from .problems import ProblemError


@dataclass(frozen=True)
class RobotRef:
    """The robot a request works on: a catalogue robot or an inline one."""

    id: str
    robot: Robot


def settings_of(request: Request) -> Settings:
    return request.app.state.settings


def catalogue_of(request: Request) -> Catalogue:
    catalogue = request.app.state.catalogue
    if catalogue is None:
        raise ProblemError(503, "not-ready", "Not ready", "The robot catalogue is not loaded yet.")
    return catalogue


def catalogue_robot(
    request: Request,
    robot_id: str = Path(pattern=r"^[a-z0-9][a-z0-9_-]{0,63}$", description="catalogue id, see GET /v1/robots"),
) -> RobotRef:
    entry = catalogue_of(request).get(robot_id)
    if entry is None:
        raise ProblemError(404, "unknown-robot", "Unknown robot",
                           f"No robot with id {robot_id!r} in the catalogue; GET /v1/robots lists them.")
    return RobotRef(robot_id, entry.robot)


def inline_robot(request: Request, description: AnyRobotDescription) -> RobotRef:
    with located("body", "robot"):
        robot = robot_from_description(description, max_joints=settings_of(request).max_joints)
    return RobotRef(description.id, robot)


def with_request_frames(ref: RobotRef, body) -> RobotRef:
    """The robot with the request's own ``base`` (world_T_base) and ``tool`` (flange_T_tool), when it has them."""
    base, tool = getattr(body, "base", None), getattr(body, "tool", None)
    if base is None and tool is None:
        return ref
    robot = ref.robot
    with located("body"):
        robot = robot.with_frames(None if base is None else np.asarray(base, dtype=float),
                                  None if tool is None else np.asarray(tool, dtype=float))
    return RobotRef(ref.id, robot)


def check_batch_size(request: Request, rows: int, field: str) -> None:
    limit = settings_of(request).max_batch
    if rows > limit:
        raise ProblemError(413, "batch-too-large", "Batch too large",
                           f"{field} has {rows} rows; this service accepts at most {limit} (KIN_MAX_BATCH).")
