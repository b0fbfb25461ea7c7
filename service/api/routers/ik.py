"""Inverse kinematics: every solution, verified by forward kinematics."""

from __future__ import annotations

from fastapi import APIRouter, Depends, Query, Request

from ...kinematics.ik import is_small
from ..budget import budget_of
from ..deps import RobotRef, catalogue_robot, check_batch_size, inline_robot, kept_inline_robot
from ..ik_encoding import ik_columns, ik_objects
from ..ik_requests import AskedIK, answered, ik_request_in_core
from ..pictures import IK_PICTURE_RESPONSE, ik_answer_svg, svg_response, wants_svg
from ..problems import problem_responses
from ..responses import FastJSONResponse
from ..routing import FastJSONRoute, computed, small_first
from ..schemas.ik import (IKBatchArraysResponse, IKBatchRequest, IKBatchResponse, IKInlineRequest, IKRequest,
                          IKResponse)
from ..schemas.render import RenderView

router = APIRouter(prefix="/v1", route_class=FastJSONRoute, tags=["inverse kinematics"])
RENDER_QUERY = Query(None, description="answer with an SVG picture of every distinct solution (those that differ "
                                       "only by whole turns share a panel) seen from this view, instead of JSON; "
                                       "the same as Accept: image/svg+xml with the iso view. With 'collisions', "
                                       "each panel draws the obstacles and link shapes, colliding ones red")


@router.post("/robots/{robot_id}/ik", operation_id="inverse_kinematics", response_model=IKResponse,
             responses={200: IK_PICTURE_RESPONSE, **problem_responses(404, 422)})
@small_first
async def inverse_kinematics(request: Request, body: IKRequest, ref: RobotRef = Depends(catalogue_robot),
                             render: RenderView | None = RENDER_QUERY):
    """Every joint vector that reaches the target pose, each checked by forward kinematics."""
    return await _answer_or_picture(request, ref, body, render)


@router.post("/ik", operation_id="inverse_kinematics_inline", response_model=IKResponse,
             responses={200: IK_PICTURE_RESPONSE, **problem_responses(422)})
@small_first
async def inverse_kinematics_inline(request: Request, body: IKInlineRequest, render: RenderView | None = RENDER_QUERY):
    """Inverse kinematics for a robot described in the request body."""
    ref = kept_inline_robot(request, body.robot)
    if ref is None:  # building the robot is not small work
        return await computed(lambda: _single_answer(request, inline_robot(request, body.robot), body, render),
                              small=False)
    return await _answer_or_picture(request, ref, body, render)


async def _answer_or_picture(request: Request, ref: RobotRef, body: IKRequest, render: RenderView | None):
    """A single IK's answer (or picture), computed where the request is when its work is small (decided once,
    here, after validation)."""
    asked = ik_request_in_core(request, ref, body)
    picture = render is not None or wants_svg(request)
    small = is_small(asked.ref.robot, asked.targets, asked.options)
    return await computed(lambda: _single_response(request, asked, body, render, picture, small),
                          small=small and not picture)


def _single_answer(request: Request, ref: RobotRef, body: IKRequest, render: RenderView | None):
    return _single_response(request, ik_request_in_core(request, ref, body), body, render,
                            render is not None or wants_svg(request))


def _single_response(request: Request, asked: AskedIK, body: IKRequest, render: RenderView | None, picture: bool,
                     small: bool | None = None):
    ref = asked.ref
    answer = ik_objects(ref.id, ref.robot, answered(request, asked, "objects", small=small), body.angle_unit,
                        budget_of(request))[0]
    if not picture:
        return FastJSONResponse(answer)  # built to IKResponse field by field (a test validates it), as it stands
    return svg_response(ik_answer_svg(ref.robot, ref.id, answer, body.angle_unit, render or "iso",
                                      body.reference is not None, asked.options.collisions))


@router.post("/robots/{robot_id}/ik/batch", operation_id="inverse_kinematics_batch",
             response_model=IKBatchResponse | IKBatchArraysResponse, responses=problem_responses(404, 413, 422))
@small_first  # a motion planner's few waypoints: computed where the request is, as a single IK
async def inverse_kinematics_batch(request: Request, body: IKBatchRequest, ref: RobotRef = Depends(catalogue_robot)):
    """Every solution for each target; the analytic solvers run vectorised over the targets."""
    check_batch_size(request, body.target_count, "targets")
    asked = ik_request_in_core(request, ref, body)
    small = is_small(asked.ref.robot, asked.targets, asked.options)
    return await computed(lambda: _batch_response(request, asked, body, small), small=small)


def _batch_response(request: Request, asked: AskedIK, body: IKBatchRequest, small: bool):
    encode = ik_columns if body.format == "arrays" else ik_objects
    encoded = encode(asked.ref.id, asked.ref.robot, answered(request, asked, body.format, small=small),
                     body.angle_unit, budget_of(request))
    # built field by field to the response models (a test validates them), so encoded as they stand: validating
    # tens of thousands of solution objects again would cost more than solving them
    return FastJSONResponse(encoded if body.format == "arrays" else {"robot_id": asked.ref.id, "results": encoded})
