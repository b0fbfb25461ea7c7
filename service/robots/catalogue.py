"""The robot catalogue: robot files loaded and validated once, at start-up.

Files are YAML (read with ``yaml.safe_load``) or JSON, one robot per file,
named ``<id>.yaml`` / ``<id>.yml`` / ``<id>.json``, in any description form
(DH table or joint screws). A URDF is ``<id>.urdf`` with a sidecar
``<id>.urdf.yaml`` that names its chain (``base_link``, ``tip_link``), its
``source`` and its ``licence`` (both required), and may set ``name``,
``limits_source``, ``notes``, ``base`` and ``tool``. A file that does not
validate stops start-up with a message naming the file and the field.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable

import yaml
from pydantic import TypeAdapter, ValidationError

from ..kinematics import KinematicsError, Robot
from ._fields import field_location
from .build import robot_from_description
from .schemas import MAX_URDF_CHARS, AnyRobotDescription, RobotDescription

ROBOT_FILE_SUFFIXES = (".yaml", ".yml", ".json", ".urdf")
URDF_SIDECAR_SUFFIX = ".urdf.yaml"
_description_adapter: TypeAdapter[AnyRobotDescription] = TypeAdapter(RobotDescription)


class CatalogueError(Exception):
    """A robot file is unreadable or invalid; the message names the file and the field."""


@dataclass(frozen=True)
class CatalogueEntry:
    description: AnyRobotDescription
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
    """Read and validate one robot file (for a ``.urdf``, with its sidecar)."""
    data = _read_data(path)
    if path.suffix == ".urdf":
        data = _urdf_entry(path, data)
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


def _read_data(path: Path) -> object:
    try:
        if path.suffix == ".urdf":
            if path.stat().st_size > MAX_URDF_CHARS * 4:
                raise ValueError(f"larger than {MAX_URDF_CHARS} characters")
            return path.read_text(encoding="utf-8")
        text = path.read_text(encoding="utf-8")
        return json.loads(text) if path.suffix == ".json" else yaml.safe_load(text)
    except (OSError, UnicodeDecodeError, ValueError, yaml.YAMLError) as error:
        raise CatalogueError(f"{path}: cannot be read as {path.suffix[1:].upper()}: {error}") from None


def _urdf_entry(path: Path, urdf: str) -> dict:
    """The description of a catalogue URDF: its sidecar's fields plus the URDF text."""
    sidecar = path.with_name(path.stem + URDF_SIDECAR_SUFFIX)
    if not sidecar.is_file():
        raise CatalogueError(f"{path}: needs a sidecar {sidecar.name} naming its chain, source and licence")
    meta = _read_data(sidecar)
    if not isinstance(meta, dict):
        raise CatalogueError(f"{sidecar}: must be a mapping of description fields")
    for required in ("source", "licence"):
        if not meta.get(required):
            raise CatalogueError(f"{sidecar}: {required}: a catalogue URDF must state its {required}")
    if "urdf" in meta or meta.get("format", "urdf") != "urdf":
        raise CatalogueError(f"{sidecar}: the URDF text comes from {path.name}; the sidecar sets the other fields")
    return {"id": path.stem, **meta, "format": "urdf", "urdf": urdf}


def load_catalogue(directories: Iterable[Path], *, max_joints: int) -> Catalogue:
    """Load every robot file in ``directories``; a later directory may not redefine an id."""
    entries: dict[str, CatalogueEntry] = {}
    for directory in directories:
        if not directory.is_dir():
            raise CatalogueError(f"{directory}: robot directory does not exist")
        for path in sorted(p for p in directory.iterdir() if p.suffix in ROBOT_FILE_SUFFIXES and p.is_file()
                           and not p.name.endswith(URDF_SIDECAR_SUFFIX)):
            entry = load_robot_file(path, max_joints=max_joints)
            robot_id = entry.description.id
            if robot_id in entries:
                raise CatalogueError(f"{path}: id: {robot_id!r} is already defined by {entries[robot_id].path}")
            entries[robot_id] = entry
    return Catalogue(entries.values())
