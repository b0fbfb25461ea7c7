"""The robot catalogue: robot files loaded and validated once, at start-up.

Files are YAML (read with ``yaml.safe_load``) or JSON, one robot per file,
named ``<id>.yaml`` / ``<id>.yml`` / ``<id>.json``. A file that does not
validate stops start-up with a message naming the file and the field.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable

import yaml
from pydantic import TypeAdapter, ValidationError

from .api.boundary import robot_from_description
from .api.problems import field_location
from .api.schemas.robots import DHRobot, KhalilRobot, RobotDescription
from .kinematics import KinematicsError, Robot

ROBOT_FILE_SUFFIXES = (".yaml", ".yml", ".json")
_description_adapter: TypeAdapter[DHRobot | KhalilRobot] = TypeAdapter(RobotDescription)


class CatalogueError(Exception):
    """A robot file is unreadable or invalid; the message names the file and the field."""


@dataclass(frozen=True)
class CatalogueEntry:
    description: DHRobot | KhalilRobot
    robot: Robot
    path: Path


class Catalogue:
    """Robots by id, in id order."""

    def __init__(self, entries: Iterable[CatalogueEntry]) -> None:
        self._entries = {entry.description.id: entry for entry in sorted(entries, key=lambda e: e.description.id)}

    def __len__(self) -> int:
        return len(self._entries)

    def __contains__(self, robot_id: object) -> bool:
        return robot_id in self._entries

    def get(self, robot_id: str) -> CatalogueEntry | None:
        return self._entries.get(robot_id)

    def entries(self) -> list[CatalogueEntry]:
        return list(self._entries.values())


def load_robot_file(path: Path, *, max_joints: int) -> CatalogueEntry:
    """Read and validate one robot file."""
    try:
        text = path.read_text(encoding="utf-8")
        data = json.loads(text) if path.suffix == ".json" else yaml.safe_load(text)
    except (OSError, UnicodeDecodeError, ValueError, yaml.YAMLError) as error:
        raise CatalogueError(f"{path}: cannot be read as {path.suffix[1:].upper()}: {error}") from None
    try:
        description = _description_adapter.validate_python(data)
    except ValidationError as error:
        problems = "; ".join(
            f"{'.'.join(str(p) for p in field_location(e['loc'])) or '(top level)'}: {e['msg']}"
            for e in error.errors()
        )
        raise CatalogueError(f"{path}: {problems}") from None
    if description.id != path.stem:
        raise CatalogueError(f"{path}: id: {description.id!r} must match the file name {path.stem!r}")
    try:
        robot = robot_from_description(description, max_joints=max_joints)
    except KinematicsError as error:
        field = ".".join(str(p) for p in error.location) or "(robot)"
        raise CatalogueError(f"{path}: {field}: {error.message}") from None
    return CatalogueEntry(description, robot, path)


def load_catalogue(directories: Iterable[Path], *, max_joints: int) -> Catalogue:
    """Load every robot file in ``directories``; a later directory may not redefine an id."""
    entries: dict[str, CatalogueEntry] = {}
    for directory in directories:
        if not directory.is_dir():
            raise CatalogueError(f"{directory}: robot directory does not exist")
        for path in sorted(p for p in directory.iterdir() if p.suffix in ROBOT_FILE_SUFFIXES and p.is_file()):
            entry = load_robot_file(path, max_joints=max_joints)
            robot_id = entry.description.id
            if robot_id in entries:
                raise CatalogueError(f"{path}: id: {robot_id!r} is already defined by {entries[robot_id].path}")
            entries[robot_id] = entry
    return Catalogue(entries.values())
