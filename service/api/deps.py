"""Request dependencies: settings, the catalogue, and the robot a request is about."""

from __future__ import annotations

import difflib
import re
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


async def catalogue_robot(
    request: Request,
    robot_id: str = Path(pattern=r"^[A-Za-z0-9][A-Za-z0-9_-]{0,63}$",
                         description="catalogue id, see GET /v1/robots; ids are lower case and matched "
                                     "case-insensitively (UR5 is ur5)"),
) -> RobotRef:
    """The catalogue robot the path names (a dictionary look-up: async, so FastAPI calls it without a thread)."""
    catalogue = catalogue_of(request)
    entry = catalogue.get(robot_id.lower())
    if entry is None:
        ids = [e.description.id for e in catalogue.entries()]
        nearest = nearest_ids(robot_id, ids)
        hint = f" Did you mean {' or '.join(repr(i) for i in nearest)}?" if nearest else ""
        raise ProblemError(404, "unknown-robot", "Unknown robot",
                           f"No robot with id {robot_id!r} in the catalogue.{hint} GET /v1/robots lists all "
                           f"{len(ids)}.", nearest_ids=nearest)
    return RobotRef(entry.description.id, entry.robot)


def nearest_ids(wanted: str, ids: list[str], limit: int = 5) -> list[str]:
    """Catalogue ids a client may have meant by ``wanted``, best first.

    First the ids equal to it once case, ``-`` and ``_`` are ignored (``UR-5`` → ``ur5``), then ids that
    contain it or that it contains (``puma`` → the PUMA tables), then close spellings (difflib's ratio ≥ 0.6).
    """
    def folded(text: str) -> str:
        return text.lower().replace("-", "").replace("_", "")

    key = folded(wanted)
    chosen = [i for i in ids if folded(i) == key]
    chosen += [i for i in ids if i not in chosen and key and (
        folded(i).startswith(key) or len(key) >= 3 and key in folded(i) or folded(i) in key)]
    chosen += [i for i in difflib.get_close_matches(wanted.lower(), ids, n=limit, cutoff=0.6) if i not in chosen]
    family = re.match(r"[a-z]{2,}", key)  # the maker's letters: ur10 → ur5
    if family:
        chosen += [i for i in ids if i not in chosen and folded(i).startswith(family[0])
                   and not folded(i)[len(family[0]):][:1].isalpha()]
    return chosen[:limit]


def inline_robot(request: Request, description: AnyRobotDescription) -> RobotRef:
    """The robot a request describes, built once per canonical description (see :mod:`.robot_cache`)."""
    max_joints = settings_of(request).max_joints

    def build() -> Robot:
        with located("body", "robot"):
            return robot_from_description(description, max_joints=max_joints)

    key = (description.model_dump_json(), max_joints)
    return RobotRef(description.id, request.app.state.inline_robots.get(key, build))


def kept_inline_robot(request: Request, description: AnyRobotDescription) -> RobotRef | None:
    """The robot a request describes if the cache keeps it already, else None: building one (a URDF's parse and
    its chain) is not small work."""
    key = (description.model_dump_json(), settings_of(request).max_joints)
    robot = request.app.state.inline_robots.kept(key)
    return None if robot is None else RobotRef(description.id, robot)


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
                           f"{field} has {rows} rows; this service accepts at most {limit} (KIN_MAX_BATCH).",
                           errors=[{"loc": ["body", field], "msg": f"at most {limit} rows (KIN_MAX_BATCH)",
                                    "type": "too_long"}])
