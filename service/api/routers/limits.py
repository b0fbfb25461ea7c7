"""Joint-limit checks with reasons, and the 2π-equivalent that fits."""

from __future__ import annotations

from fastapi import APIRouter, Depends, Request

from ...kinematics import LIMIT_TOLERANCE, check_limits
from ..boundary import _unit_scale, joints_from_core, joints_to_core, limits_to_core, located, violations_to_wire
from ..deps import RobotRef, catalogue_robot, check_batch_size, inline_robot, with_request_frames
from ..problems import problem_responses
from ..responses import FastJSONResponse
from ..routing import FastJSONRoute, small_first
from ..schemas.limits import LimitsInlineRequest, LimitsRequest, LimitsResponse

router = APIRouter(prefix="/v1", route_class=FastJSONRoute, tags=["joint limits"])


def _check(request: Request, ref: RobotRef, body: LimitsRequest) -> FastJSONResponse:
    check_batch_size(request, len(body.joints), "joints")
    ref = with_request_frames(ref, body)  # validated; limits do not depend on base or tool
    robot = ref.robot
    with located("body", "joints"):
        rows = joints_to_core(robot, body.joints, body.angle_unit, batch=True)
    with located("body", "limits"):
        limits = limits_to_core(robot, body.limits, body.angle_unit)
    check = check_limits(robot, limits, rows)
    violations = violations_to_wire(limits, _unit_scale(robot, body.angle_unit), check.outside, check.q)
    equivalents = joints_from_core(robot, check.equivalent, body.angle_unit).tolist()
    results = [{"within_limits": inside, "violations": violations.get(row, []),
                "equivalent": equivalents[row] if fits else None}
               for row, (inside, fits) in enumerate(zip(check.inside.tolist(), check.fits.tolist()))]
    # built to LimitsResponse field by field (a test validates it): validated and serialised through the model again,
    # 10,000 rows cost more than their check
    return FastJSONResponse({"robot_id": ref.id, "joint_names": robot.joint_names, "tolerance": LIMIT_TOLERANCE,
                             "results": results})


@router.post("/robots/{robot_id}/limits", operation_id="check_joint_limits", response_model=LimitsResponse,
             responses=problem_responses(404, 413, 422))
@small_first  # a body within SMALL_BODY_BYTES holds a few hundred rows at most: always small
def check_joint_limits(request: Request, body: LimitsRequest, ref: RobotRef = Depends(catalogue_robot)):
    """For each joint vector: within limits or not, each violation, and the 2π-equivalent that fits, if one does."""
    return _check(request, ref, body)


@router.post("/limits", operation_id="check_joint_limits_inline", response_model=LimitsResponse,
             responses=problem_responses(413, 422))
def check_joint_limits_inline(request: Request, body: LimitsInlineRequest):
    """Joint-limit checks for a robot described in the request body."""
    return _check(request, inline_robot(request, body.robot), body)
