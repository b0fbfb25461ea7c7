"""A trajectory request in core terms and its answer on the wire: units converted once, here (the route only
calls these and the core's :func:`~service.kinematics.follow_trajectory`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from fastapi import Request

from ..kinematics import Budget, InvalidInputError, TrajectoryOptions, TrajectoryResult
from ..kinematics.ik import AnswerOptions, IKOptions, IKTargets, estimate
from ..units import radians_per
from .boundary import (collisions_to_core, free_joints_to_core, joints_from_core, joints_to_core, located,
                       target_matrix, violation_to_wire, _unit_scale)
from .budget import budget_of, check_collision_cost
from .deps import RobotRef, check_batch_size, settings_of, with_request_frames
from .schemas.trajectory import TrajectoryRequest


@dataclass(frozen=True)
class AskedTrajectory:
    """A trajectory request in core terms: the robot (with the request's frames), sample times (N,), target poses
    (N, 4, 4) ``world_T_tool``, whether they constrain the orientation, twists and accelerations (N, 6) in
    radians and length units (NaN where not given), and the options."""

    ref: RobotRef
    times: list[float]
    world_T_targets: np.ndarray
    constrain_orientation: bool
    twists: np.ndarray
    accelerations: np.ndarray
    options: TrajectoryOptions
    budget: Budget


def _cartesian(parts, angle: float) -> list[float]:
    """One twist or acceleration as 6 numbers in core units; NaN for a part not given."""
    if parts is None:
        return [math.nan] * 6
    linear = parts.linear if parts.linear is not None else [math.nan] * 3
    angular = [v * angle for v in parts.angular] if parts.angular is not None else [math.nan] * 3
    return [*linear, *angular]


def trajectory_in_core(request: Request, ref: RobotRef, body: TrajectoryRequest) -> AskedTrajectory:
    """Body → core: every sample's pose a matrix (all of one kind), rates and joint values in radians, the
    options (``free_joints`` as single IK takes them)."""
    check_batch_size(request, len(body.samples), "samples")
    ref = with_request_frames(ref, body)
    robot, unit = ref.robot, body.angle_unit
    matrices, constrained = [], []
    budget = budget_of(request)
    for k, sample in enumerate(body.samples):
        if k % 256 == 255:
            budget.check("reading the samples")
        with located("body", "samples", k, "pose"):
            matrix, flag = target_matrix(sample.pose, unit)
        matrices.append(matrix)
        constrained.append(flag)
        if flag != constrained[0]:
            raise InvalidInputError("every sample's pose must be the same kind: all with an orientation, or all "
                                    "position-only", location=("body", "samples", k, "pose"))
    angle = radians_per(unit)
    reference = None
    if body.reference is not None:
        with located("body", "reference"):
            reference = joints_to_core(robot, body.reference, unit)
    free_joints = free_joints_to_core(robot, body.free_joints, unit)
    world_T_targets = np.array(matrices)
    collisions = collisions_to_core(robot, body.collisions, unit)
    if collisions is not None:  # the distances of every sample's solutions, counted as single IK counts them
        with located("body"):
            cost = estimate(robot, IKTargets.poses(world_T_targets, constrain_orientation=constrained[0]),
                            AnswerOptions(reference=reference, free_joints=free_joints, collisions=collisions))
        check_collision_cost(settings_of(request), cost)
    options = TrajectoryOptions(
        branch=None if body.branch is None else body.branch.model_dump(), reference=reference,
        singularity_tolerance=body.singularity_tolerance, damping=body.damping, ik=IKOptions(budget=budget),
        free_joints=free_joints, collisions=collisions)
    return AskedTrajectory(ref, [s.time for s in body.samples], world_T_targets, constrained[0],
                           np.array([_cartesian(s.twist, angle) for s in body.samples]),
                           np.array([_cartesian(s.acceleration, angle) for s in body.samples]), options, budget)


def _vector(values: np.ndarray | None, scale: np.ndarray) -> list | None:
    """Joint values (n,) from the core's units to the request's (``scale``, :func:`~.boundary._unit_scale`), or
    None where there are none."""
    if values is None or np.isnan(values).any():
        return None
    return (values / scale).tolist()


def trajectory_to_wire(asked: AskedTrajectory, result: TrajectoryResult, body: TrajectoryRequest) -> dict:
    """The answer as TrajectoryResponse's fields, built field by field (a test validates it against the model)."""
    robot, unit, budget = asked.ref.robot, body.angle_unit, asked.budget
    scale = _unit_scale(robot, unit)  # the paper's joints too: only an RRP arm has them
    samples = []
    for k, s in enumerate(result.samples):
        if k % 256 == 0:
            budget.check("encoding")
        sample = {
            "time": s.time,
            "status": s.status,
            "joints": _vector(s.joints, scale),
            "velocities": _vector(s.velocities, scale),
            "accelerations": _vector(s.accelerations, scale),
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
                "joints": _vector(s.paper.joints, scale),
                "velocities": _vector(s.paper.velocities, scale),
                "accelerations": _vector(s.paper.accelerations, scale),
                "case": s.paper.case},
        }
        if asked.options.collisions is not None:
            checked = s.clearance
            sample["clearance"] = None if checked is None else checked.clearance
            sample["collisions"] = None if checked is None else [{"a": a, "b": b, "distance": distance}
                                                                 for a, b, distance in checked.contacts]
            sample["collision_forced"] = s.collision_forced
        samples.append(sample)
    summary = result.summary
    collision_summary = {} if asked.options.collisions is None else {
        "colliding_samples": summary.colliding_samples,
        "collision_branch_changes": summary.collision_branch_changes,
        "smallest_clearance": {"value": summary.smallest_clearance, "sample": summary.smallest_clearance_at},
    }
    step = joints_from_core(robot, summary.largest_joint_step, unit)
    return {
        "robot_id": asked.ref.id,
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
            **collision_summary,
        },
        "solver": {"positions": result.method, "structure": result.structure, "complete": result.complete,
                   "rates": result.rates, "task_rows": list(result.task.names), "solve": result.task.solve,
                   "singularity_tolerance": body.singularity_tolerance, "damping": body.damping},
    }
