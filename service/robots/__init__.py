"""Robot descriptions: their schemas (DH tables, URDF chains, joint screws), the loaders that turn them into core
robots, the exports to other forms, and the catalogue of robot files.

This package depends on the kinematics core and pydantic, never on the web layer (``service.api``).
"""

from .build import robot_from_description
from .catalogue import Catalogue, CatalogueEntry, CatalogueError, ROBOT_FILE_SUFFIXES, load_catalogue, load_robot_file
from .schemas import AnyRobotDescription, RobotDescription

__all__ = [
    "AnyRobotDescription",
    "Catalogue",
    "CatalogueEntry",
    "CatalogueError",
    "ROBOT_FILE_SUFFIXES",
    "RobotDescription",
    "load_catalogue",
    "load_robot_file",
    "robot_from_description",
]
