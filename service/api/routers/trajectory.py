"""Trajectory IK: joint positions, velocities and accelerations on one branch along sampled poses."""

from __future__ import annotations

from fastapi import APIRouter, Depends, Request

from ...kinematics import follow_trajectory
from ..boundary import located
from ..deps import RobotRef, catalogue_robot, inline_robot
from ..problems import problem_responses
from ..responses import FastJSONResponse
from ..routing import FastJSONRoute
from ..schemas.trajectory import TrajectoryInlineRequest, TrajectoryRequest, TrajectoryResponse
from ..trajectory_requests import trajectory_in_core, trajectory_to_wire

router = APIRouter(prefix="/v1", route_class=FastJSONRoute, tags=["trajectories"])


def _follow(request: Request, ref: RobotRef, body: TrajectoryRequest) -> dict:
    """Units in, one core call, the answer encoded."""
    asked = trajectory_in_core(request, ref, body)
    with located("body"):
        result = follow_trajectory(asked.ref.robot, asked.times, asked.world_T_targets,
                                   constrain_orientation=asked.constrain_orientation, twists=asked.twists,
                                   accelerations=asked.accelerations, options=asked.options)
    return trajectory_to_wire(asked, result, body)


@router.post("/robots/{robot_id}/ik/trajectory", operation_id="inverse_kinematics_trajectory",
             response_model=TrajectoryResponse, responses=problem_responses(404, 413, 422))
def inverse_kinematics_trajectory(request: Request, body: TrajectoryRequest,
                                  ref: RobotRef = Depends(catalogue_robot)) -> FastJSONResponse:
    """Joint positions, velocities and accelerations on one branch along sampled poses, with singularity flags."""
    return FastJSONResponse(_follow(request, ref, body))


@router.post("/ik/trajectory", operation_id="inverse_kinematics_trajectory_inline",
             response_model=TrajectoryResponse, responses=problem_responses(413, 422))
def inverse_kinematics_trajectory_inline(request: Request, body: TrajectoryInlineRequest) -> FastJSONResponse:
    """Trajectory IK for a robot described in the request body."""
    return FastJSONResponse(_follow(request, inline_robot(request, body.robot), body))
