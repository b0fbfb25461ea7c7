"""The robot catalogue."""

from __future__ import annotations

from fastapi import APIRouter, Depends, Query, Request

from ...robots.catalogue import Catalogue
from ..deps import catalogue_of, catalogue_robot, RobotRef
from ..problems import ProblemError, problem_responses
from ...robots.export import FormNotExact, description_in_form
from ...robots.schemas import AnyRobotDescription, DescriptionForm, RobotDescription, RobotList, RobotSummary

router = APIRouter(prefix="/v1/robots", tags=["robots"])


@router.get("", operation_id="list_robots", response_model=RobotList)
def list_robots(catalogue: Catalogue = Depends(catalogue_of)) -> RobotList:
    """List the catalogue: id, name, degrees of freedom, convention and joint types of every robot."""
    return RobotList(robots=[
        RobotSummary(id=e.description.id, name=e.description.name or e.robot.name, dof=e.robot.dof,
                     format=e.description.format,
                     convention=getattr(e.description, "convention", None),
                     joint_types=["revolute" if r else "prismatic" for r in e.robot.is_revolute.tolist()],
                     joint_names=e.robot.joint_names, source=e.description.source,
                     licence=getattr(e.description, "licence", None))
        for e in catalogue.entries()
    ])


@router.get("/{robot_id}", operation_id="get_robot", response_model=RobotDescription,
            responses=problem_responses(404, 422))
def get_robot(request: Request, ref: RobotRef = Depends(catalogue_robot),
              form: DescriptionForm | None = Query(None, description="restate the description in this form "
                                                   "(422 when that form is not exact for this robot)")
              ) -> AnyRobotDescription:
    """Return one robot's full description, as its catalogue file states it (units included), or in another form."""
    entry = catalogue_of(request).get(ref.id)
    if form is None:
        return entry.description
    try:
        return description_in_form(entry.description, entry.robot, form)
    except FormNotExact as error:
        raise ProblemError(422, "form-not-exact", "Form not exact",
                           f"robot {ref.id!r} cannot be described exactly in form {form!r}: {error}",
                           errors=[{"loc": ["query", "form"], "msg": str(error), "type": "form_not_exact"}]) from None
