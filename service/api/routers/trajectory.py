"""Trajectory IK: joint positions, velocities and accelerations on one branch along sampled poses."""

from __future__ import annotations

import math

import numpy as np
from fastapi import APIRouter, Depends, Request

from ...kinematics import Budget, InvalidInputError, Robot
from ...kinematics import TrajectoryOptions, TrajectoryResult, follow_trajectory
from ...kinematics.ik import IKOptions
from ..budget import budget_of
from ..boundary import joints_from_core, joints_to_core, located, target_matrix, violation_to_wire
from ..deps import RobotRef, catalogue_robot, check_batch_size, inline_robot, with_request_frames
from ..problems import problem_responses
from ..responses import FastJSONResponse
from ..routing import FastJSONRoute
from ..schemas.trajectory import TrajectoryInlineRequest, TrajectoryRequest, TrajectoryResponse

router = APIRouter(prefix="/v1", route_class=FastJSONRoute, tags=["trajectories"])


def _cartesian(parts, angle: float) -> list[float]:
    """One twist or acceleration as 6 numbers in core units; NaN for a part not given."""
    if parts is None:
        return [math.nan] * 6
    linear = parts.linear if parts.linear is not None else [math.nan] * 3
    angular = [v * angle for v in parts.angular] if parts.angular is not None else [math.nan] * 3
    return [*linear, *angular]


def _follow(request: Request, ref: RobotRef, body: TrajectoryRequest) -> dict:
    check_batch_size(request, len(body.samples), "samples")
    ref = with_request_frames(ref, body)
    robot = ref.robot
    matrices, constrained = [], []
    budget = budget_of(request)
    for k, sample in enumerate(body.samples):
        if k % 256 == 255:
            budget.check("reading the samples")
        with located("body", "samples", k, "pose"):
            matrix, flag = target_matrix(sample.pose, body.angle_unit)
        matrices.append(matrix)
        constrained.append(flag)
        if flag != constrained[0]:
            raise InvalidInputError("every sample's pose must be the same kind: all with an orientation, or all "
                                    "position-only", location=("body", "samples", k, "pose"))
    angle = math.pi / 180.0 if body.angle_unit == "deg" else 1.0
    reference = None
    if body.reference is not None:
        with located("body", "reference"):
            reference = joints_to_core(robot, body.reference, body.angle_unit)
    options = TrajectoryOptions(
        branch=None if body.branch is None else body.branch.model_dump(), reference=reference,
        singularity_tolerance=body.singularity_tolerance, damping=body.damping,
        ik=IKOptions(budget=budget))
    with located("body"):
        result = follow_trajectory(
            robot, [s.time for s in body.samples], np.array(matrices), constrain_orientation=constrained[0],
            twists=np.array([_cartesian(s.twist, angle) for s in body.samples]),
            accelerations=np.array([_cartesian(s.acceleration, angle) for s in body.samples]),
            options=options)
    return _to_wire(ref.id, robot, result, body, budget)


def _vector(robot: Robot, values: np.ndarray | None, unit: str, scale: np.ndarray | None = None) -> list | None:
    if values is None or np.isnan(values).any():
        return None
    return (joints_from_core(robot, values, unit) if scale is None else values / scale).tolist()


def _to_wire(robot_id: str, robot: Robot, result: TrajectoryResult, body: TrajectoryRequest,
             budget: Budget) -> dict:
    """The answer as TrajectoryResponse's fields, built field by field (a test validates it against the model)."""
    unit = body.angle_unit
    paper_scale = np.array([math.pi / 180.0, math.pi / 180.0, 1.0]) if unit == "deg" else np.ones(3)
    samples = []
    for k, s in enumerate(result.samples):
        if k % 256 == 0:
            budget.check("encoding")
        samples.append({
            "time": s.time,
            "status": s.status,
            "joints": _vector(robot, s.joints, unit),
            "velocities": _vector(robot, s.velocities, unit),
            "accelerations": _vector(robot, s.accelerations, unit),
            "branch": s.branch,
            "branch_changed": s.branch_changed,
            "singularities": [{"kind": x.kind, "joints": list(x.joints), "relation": x.relation, "detail": x.detail}
                              for x in s.singularities],
            "distance_to_singularity": s.distance_to_singularity,
            "damped": s.damped,
            "within_limits": None if not s.reached else not s.violations,
            "violations": [violation_to_wire(robot, v, unit) for v in s.violations],
            "residual": None if not s.reached else {"velocity": s.velocity_residual,
                                                    "acceleration": s.acceleration_residual},
            "paper": None if s.paper is None else {
                "joints": _vector(robot, s.paper.joints, unit, paper_scale),
                "velocities": _vector(robot, s.paper.velocities, unit, paper_scale),
                "accelerations": _vector(robot, s.paper.accelerations, unit, paper_scale),
                "case": s.paper.case},
        })
    summary = result.summary
    step = joints_from_core(robot, summary.largest_joint_step, unit)
    return {
        "robot_id": robot_id,
        "joint_names": robot.joint_names,
        "samples": samples,
        "summary": {
            "largest_joint_step": {"values": [None if np.isnan(v) else float(v) for v in step],
                                   "samples": summary.largest_joint_step_at},
            "smallest_distance_to_singularity": {"value": summary.smallest_distance_to_singularity,
                                                 "sample": summary.smallest_distance_at},
            "limit_violations": [{"sample": k, **violation_to_wire(robot, v, unit)}
                                 for k, v in summary.limit_violations],
            "singular_samples": summary.singular_samples,
            "branch_changes": summary.branch_changes,
            "unreachable_samples": summary.unreachable_samples,
        },
        "solver": {"positions": result.method, "structure": result.structure, "complete": result.complete,
                   "rates": result.rates, "task_rows": list(result.task.names), "solve": result.task.solve,
                   "singularity_tolerance": body.singularity_tolerance, "damping": body.damping},
    }


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
