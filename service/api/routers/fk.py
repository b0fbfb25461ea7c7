"""Forward kinematics."""

from __future__ import annotations

from fastapi import APIRouter, Depends, Request

from ...kinematics import forward_kinematics, link_frames
from ..boundary import (clearance_to_wire, collisions_to_core, joints_to_core, located, pose_from_matrix,
                        poses_from_matrices)
from ..deps import RobotRef, catalogue_robot, check_batch_size, inline_robot, kept_inline_robot, with_request_frames
from ..problems import problem_responses
from ..responses import FastJSONResponse
from ..routing import FastJSONRoute, computed, small_first
from ..schemas.fk import FKBatchRequest, FKBatchResponse, FKInlineRequest, FKRequest, FKResponse

router = APIRouter(prefix="/v1", route_class=FastJSONRoute, tags=["forward kinematics"])


def _forward(ref: RobotRef, body: FKRequest) -> FastJSONResponse:
    ref = with_request_frames(ref, body)
    robot = ref.robot
    with located("body", "joints"):
        q = joints_to_core(robot, body.joints, body.angle_unit)
    frames = None
    if body.frames:
        world_T_frames = link_frames(robot, q)
        world_T_tool = world_T_frames[-1] @ robot.flange_T_tool
        names = ["base", *robot.joint_names, "tool"]
        stack = [*world_T_frames, world_T_tool]
        frames = [{"name": name, **pose} for name, pose in zip(names, poses_from_matrices(stack))]
    else:
        world_T_tool = forward_kinematics(robot, q)
    answer = {"robot_id": ref.id, "joint_names": robot.joint_names, "pose": pose_from_matrix(world_T_tool)}
    if frames is not None:
        answer["frames"] = frames
    if body.collisions is not None:
        answer.update(clearance_to_wire(robot, collisions_to_core(robot, body.collisions, body.angle_unit), q))
    return FastJSONResponse(answer)  # built to FKResponse field by field (a test validates it): not validated again


@router.post("/robots/{robot_id}/fk", operation_id="forward_kinematics", response_model=FKResponse,
             response_model_exclude_none=True, responses=problem_responses(404, 422))
@small_first  # one pose, or the frames of at most KIN_MAX_JOINTS joints: always small
def forward_kinematics_catalogue(body: FKRequest, ref: RobotRef = Depends(catalogue_robot)):
    """Pose of the tool (and optionally of every link frame) at the given joint values."""
    return _forward(ref, body)


@router.post("/fk", operation_id="forward_kinematics_inline", response_model=FKResponse,
             response_model_exclude_none=True, responses=problem_responses(422))
@small_first  # small once the robot is built
async def forward_kinematics_inline(request: Request, body: FKInlineRequest):
    """Forward kinematics for a robot described in the request body."""
    ref = kept_inline_robot(request, body.robot)
    if ref is not None:
        return _forward(ref, body)
    return await computed(lambda: _forward(inline_robot(request, body.robot), body), small=False)


@router.post("/robots/{robot_id}/fk/batch", operation_id="forward_kinematics_batch", response_model=FKBatchResponse,
             responses=problem_responses(404, 413, 422))
@small_first  # a body within SMALL_BODY_BYTES holds a few hundred rows at most: always small
def forward_kinematics_batch(request: Request, body: FKBatchRequest, ref: RobotRef = Depends(catalogue_robot)):
    """One tool pose per row of joint values, computed as one vectorised batch."""
    check_batch_size(request, len(body.joints), "joints")
    ref = with_request_frames(ref, body)
    with located("body", "joints"):
        q = joints_to_core(ref.robot, body.joints, body.angle_unit, batch=True)
    # built to FKBatchResponse field by field (a test validates it): validating and serialising 10,000 poses through
    # the model again cost more than the FK and the encoding together
    return FastJSONResponse({"robot_id": ref.id, "joint_names": ref.robot.joint_names,
                             "poses": poses_from_matrices(forward_kinematics(ref.robot, q))})
