"""The robot catalogue."""

from __future__ import annotations

from fastapi import APIRouter, Depends, Request

from ...catalogue import Catalogue
from ...kinematics.ik import target_kinds
from ..deps import catalogue_of, catalogue_robot, RobotRef
from ..problems import problem_responses
from ..schemas.robots import DHRobot, KhalilRobot, RobotDescription, RobotList, RobotSummary

router = APIRouter(prefix="/v1/robots", tags=["robots"])


@router.get("", operation_id="list_robots", response_model=RobotList)
def list_robots(catalogue: Catalogue = Depends(catalogue_of)) -> RobotList:
    """List the catalogue: id, name, degrees of freedom, convention and joint types of every robot."""
    return RobotList(robots=[
        RobotSummary(id=e.description.id, name=e.description.name, dof=e.robot.dof,
                     convention=e.description.convention, joint_types=[j.type for j in e.description.joints],
                     source=e.description.source)
        for e in catalogue.entries()
    ])


@router.get("/{robot_id}", operation_id="get_robot", response_model=RobotDescription,
            responses=problem_responses(404, 422))
def get_robot(request: Request, ref: RobotRef = Depends(catalogue_robot)) -> DHRobot | KhalilRobot:
    """Return one robot's full description, exactly as its catalogue file states it (units included), with the
    IK target kinds it takes."""
    return catalogue_of(request).get(ref.id).description.model_copy(update={"target_kinds": target_kinds(ref.robot)})
