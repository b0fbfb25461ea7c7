"""The robot catalogue: robot files loaded and validated once, at start-up.

Files are YAML (read with ``yaml.safe_load``) or JSON, one robot per file,
named ``<id>.yaml`` / ``<id>.yml`` / ``<id>.json``, in any description form
(DH table or joint screws). A URDF is ``<id>.urdf`` with a sidecar
``<id>.urdf.yaml`` that names its chain (``base_link``, ``tip_link``), its
``source`` and its ``licence`` (both required), and may set ``name``,
``limits_source``, ``notes``, ``base``, ``tool`` and ``collision``. A file that does not
validate stops start-up with a message naming the file and the field.
"""

from __future__ import annotations

import json
import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable

import yaml
from pydantic import TypeAdapter, ValidationError

from ..kinematics import KinematicsError, Robot
from ._fields import field_location
from .build import robot_from_description, urdf_geometry_shown
from .schemas import MAX_URDF_CHARS, AnyRobotDescription, RobotDescription, URDFRobot

ROBOT_FILE_SUFFIXES = (".yaml", ".yml", ".json", ".urdf")
URDF_SIDECAR_SUFFIX = ".urdf.yaml"
logger = logging.getLogger("service.catalogue")
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
        if isinstance(description, URDFRobot):
            description = urdf_geometry_shown(description)
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


#: Largest robot file read by default (a DH table of 1,000 joints is about 150 KB).
MAX_ROBOT_FILE_BYTES = 1024 * 1024


def robot_files(directory: Path, *, max_file_bytes: int = MAX_ROBOT_FILE_BYTES) -> list[Path]:
    """The robot files of one directory, sorted. Every entry left out is logged with the reason.

    Refused: symbolic links that lead out of the directory (or nowhere), entries that are not regular files.
    A robot file over ``max_file_bytes`` stops start-up at once, before it is read (a 57 MB file took 267 s and
    5.8 GB to fail otherwise).
    """
    root = directory.resolve()
    files = []
    for path in sorted(directory.iterdir()):
        if path.name.endswith(URDF_SIDECAR_SUFFIX):
            continue  # read with its URDF
        if path.suffix not in ROBOT_FILE_SUFFIXES:
            logger.info("skipped %s: not a robot file (%s)", path, ", ".join(ROBOT_FILE_SUFFIXES))
            continue
        if path.is_symlink():
            target = path.resolve()
            if not target.exists():
                logger.warning("skipped %s: a broken symbolic link", path)
                continue
            if not target.is_relative_to(root):
                logger.warning("refused %s: a symbolic link out of the robot directory, to %s", path, target)
                continue
        if not path.is_file():
            logger.warning("skipped %s: not a regular file", path)
            continue
        size = path.stat().st_size
        if size > max_file_bytes:
            raise CatalogueError(f"{path}: {size} bytes, more than the {max_file_bytes} a robot file may have "
                                 f"(KIN_MAX_ROBOT_FILE_BYTES)")
        files.append(path)
    return files


def load_catalogue(directories: Iterable[Path], *, max_joints: int,
                   max_file_bytes: int = MAX_ROBOT_FILE_BYTES) -> Catalogue:
    """Load every robot file in ``directories``; a later directory may not redefine an id."""
    entries: dict[str, CatalogueEntry] = {}
    for directory in directories:
        if not directory.is_dir():
            raise CatalogueError(f"{directory}: robot directory does not exist")
        for path in robot_files(directory, max_file_bytes=max_file_bytes):
            entry = load_robot_file(path, max_joints=max_joints)
            robot_id = entry.description.id
            if robot_id in entries:
                raise CatalogueError(f"{path}: id: {robot_id!r} is already defined by {entries[robot_id].path}")
            entries[robot_id] = entry
    return Catalogue(entries.values())
