"""The robot catalogue."""

from __future__ import annotations

from fastapi import APIRouter, Depends, Request

from ...robots.catalogue import Catalogue
from ..deps import catalogue_of, catalogue_robot, RobotRef
from ..problems import problem_responses
from ...robots.schemas import AnyRobotDescription, RobotDescription, RobotList, RobotSummary

router = APIRouter(prefix="/v1/robots", tags=["robots"])


@router.get("", operation_id="list_robots", response_model=RobotList)
def list_robots(catalogue: Catalogue = Depends(catalogue_of)) -> RobotList:
    """List the catalogue: id, name, degrees of freedom, convention and joint types of every robot."""
    return RobotList(robots=[
        RobotSummary(id=e.description.id, name=e.description.name or e.robot.name, dof=e.robot.dof, format=e.description.format,
                     convention=getattr(e.description, "convention", None),
                     joint_types=["revolute" if r else "prismatic" for r in e.robot.is_revolute.tolist()],
                     joint_names=e.robot.joint_names, source=e.description.source,
                     licence=getattr(e.description, "licence", None))
        for e in catalogue.entries()
    ])


@router.get("/{robot_id}", operation_id="get_robot", response_model=RobotDescription,
            responses=problem_responses(404, 422))
def get_robot(request: Request, ref: RobotRef = Depends(catalogue_robot)) -> AnyRobotDescription:
    """Return one robot's full description, exactly as its catalogue file states it (units included)."""
    return catalogue_of(request).get(ref.id).description
