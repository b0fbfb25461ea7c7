"""Inverse kinematics: every solution, verified by forward kinematics."""

from __future__ import annotations

import numpy as np
from fastapi import APIRouter, Depends, Query, Request

from ...kinematics.ik import (AnswerOptions, IKAnswer, IKOptions, NumericOptions, UnsupportedTargetError, answer_ik,
                               plans_are_kept, solutions_per_target)
from ..boundary import free_joints_to_core, ik_selection_to_core, ik_targets_to_core, located
from ..budget import budget_of, check_ik_cost
from ..deps import RobotRef, catalogue_robot, check_batch_size, inline_robot, settings_of, with_request_frames
from ..ik_encoding import ik_columns, ik_objects
from ..observability import observe_ik
from ..problems import ProblemError, problem_responses
from ..responses import FastJSONResponse
from ..routing import FastJSONRoute, hand_over_unless, small_first
from ..schemas.ik import (IKBatchArraysResponse, IKBatchRequest, IKBatchResponse, IKInlineRequest, IKRequest,
                          IKResponse)
from ..schemas.render import RenderView
from .render import IK_PICTURE_RESPONSE, ik_picture, wants_svg

router = APIRouter(prefix="/v1", route_class=FastJSONRoute, tags=["inverse kinematics"])
#: The most solutions a single IK may answer on the server's loop (:func:`~..routing.small_first`): a closed-form
#: family's solve, then a selection and an encoding of a few milliseconds at most.
SMALL_ANSWER_ROWS = 64
RENDER_QUERY = Query(None, description="answer with an SVG picture of every distinct solution (those that differ "
                                       "only by whole turns share a panel) seen from this view, instead of JSON; "
                                       "the same as Accept: image/svg+xml with the iso view")


def _answer(request: Request, ref: RobotRef, body: IKRequest | IKBatchRequest, form: str) -> IKAnswer:
    """Body → core (units, targets, options), the cost model's check before any solving, then the core's answer."""
    robot, unit, single = ref.robot, body.angle_unit, isinstance(body, IKRequest)
    targets = ik_targets_to_core([body.target] if single else body.targets, unit, "body",
                                 "target" if single else "targets", indexed=not single)
    reference, limits, ordering = ik_selection_to_core(robot, body)
    free = free_joints_to_core(robot, body.free_joints, unit)
    hand_over_unless(plans_are_kept(robot, targets.kinds, reference))  # deriving a plan takes milliseconds
    with located("body"):
        most, numeric = solutions_per_target(robot, targets.kinds, free, refined=reference is not None)
    worst_rows = check_ik_cost(settings_of(request), robot, limits, targets=len(targets.kinds),
                               solutions_per_target=max(most, body.numeric.starts if numeric else 0),
                               max_equivalents=body.max_equivalents, max_solutions=body.max_solutions, form=form,
                               numeric_starts=body.numeric.starts if numeric else None,
                               kept_asked=bool({"max_equivalents", "max_solutions"} & body.model_fields_set))
    hand_over_unless(not numeric and free is None and robot.dof <= 6 and worst_rows <= SMALL_ANSWER_ROWS)
    # the numeric search's time cap: time_budget_ms per target, at most KIN_MAX_IK_TIME_MS per request
    cap_ms = settings_of(request).max_ik_time_ms
    if body.numeric.time_budget_ms is not None:
        cap_ms = min(body.numeric.time_budget_ms * len(targets.kinds), cap_ms)
    search = IKOptions(NumericOptions(starts=body.numeric.starts, max_iterations=body.numeric.iterations),
                       budget=budget_of(request).within(cap_ms / 1000.0))
    options = AnswerOptions(reference, limits, body.filter_limits, ordering, body.max_equivalents, search, free,
                            budget_of(request))
    try:
        with located("body"):
            answer = answer_ik(robot, targets, options)
    except UnsupportedTargetError:
        raise ProblemError(422, "unsupported-target", "Target kind not solved for this arm",
                           "No closed-form family covers position + tool direction targets of this arm with "
                           "this tool axis; give a full pose or the position only.") from None
    for timing in answer.timings:
        observe_ik(timing.method, timing.structure, timing.seconds, timing.solutions_per_target)
    return answer


@router.post("/robots/{robot_id}/ik", operation_id="inverse_kinematics", response_model=IKResponse,
             responses={200: IK_PICTURE_RESPONSE, **problem_responses(404, 422)})
@small_first
def inverse_kinematics(request: Request, body: IKRequest, ref: RobotRef = Depends(catalogue_robot),
                       render: RenderView | None = RENDER_QUERY):
    """Every joint vector that reaches the target pose, each checked by forward kinematics."""
    return _answer_or_picture(request, ref, body, render)


@router.post("/ik", operation_id="inverse_kinematics_inline", response_model=IKResponse,
             responses={200: IK_PICTURE_RESPONSE, **problem_responses(422)})
@small_first
def inverse_kinematics_inline(request: Request, body: IKInlineRequest, render: RenderView | None = RENDER_QUERY):
    """Inverse kinematics for a robot described in the request body."""
    return _answer_or_picture(request, inline_robot(request, body.robot), body, render)


def _answer_or_picture(request: Request, ref: RobotRef, body: IKRequest, render: RenderView | None):
    picture = render is not None or wants_svg(request)
    hand_over_unless(not picture)
    ref = with_request_frames(ref, body)
    answer = ik_objects(ref.id, ref.robot, _answer(request, ref, body, "objects"), body.angle_unit,
                        budget_of(request))[0]
    if not picture:
        return FastJSONResponse(answer)  # built to IKResponse field by field (a test validates it), as it stands
    return ik_picture(ref.robot, ref.id, answer, body.angle_unit, render or "iso", body.reference is not None)


@router.post("/robots/{robot_id}/ik/batch", operation_id="inverse_kinematics_batch",
             response_model=IKBatchResponse | IKBatchArraysResponse, responses=problem_responses(404, 413, 422))
def inverse_kinematics_batch(request: Request, body: IKBatchRequest, ref: RobotRef = Depends(catalogue_robot)):
    """Every solution for each target; the analytic solvers run vectorised over the targets."""
    check_batch_size(request, len(body.targets), "targets")
    ref = with_request_frames(ref, body)
    encode = ik_columns if body.format == "arrays" else ik_objects
    encoded = encode(ref.id, ref.robot, _answer(request, ref, body, body.format), body.angle_unit, budget_of(request))
    # built field by field to the response models (a test validates them), so encoded as they stand: validating
    # tens of thousands of solution objects again would cost more than solving them
    return FastJSONResponse(encoded if body.format == "arrays" else {"robot_id": ref.id, "results": encoded})
