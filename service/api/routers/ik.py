"""Inverse kinematics: every solution, verified by forward kinematics."""

from __future__ import annotations

import time

import numpy as np
from fastapi import APIRouter, Depends, Request

from ...kinematics import Robot
from ...kinematics.ik import IKOptions, IKResult, NumericOptions, Selected, Selection, select, solve_ik_batch
from ..boundary import (
    joints_from_core,
    joints_to_core,
    limits_to_core,
    located,
    ordering_to_core,
    target_matrix,
    violation_to_wire,
)
from ..deps import RobotRef, catalogue_robot, check_batch_size, inline_robot, settings_of
from ..observability import observe_ik
from ..problems import problem_responses
from ..schemas.ik import IKBatchRequest, IKBatchResponse, IKInlineRequest, IKRequest, IKResponse

router = APIRouter(prefix="/v1", tags=["inverse kinematics"])


def _budget_seconds(request: Request, body: IKRequest | IKBatchRequest, targets: int) -> tuple[float, bool]:
    """The numeric search's time per target: the request's, within the server's cap (KIN_MAX_IK_TIME_MS) per
    request, which a batch shares across its targets. Also whether the cap lowered the request's budget."""
    cap_ms = settings_of(request).max_ik_time_ms / targets
    requested_ms = body.numeric.time_budget_ms
    return min(requested_ms, cap_ms) / 1000.0, cap_ms < requested_ms


def _solve(request: Request, ref: RobotRef, body: IKRequest | IKBatchRequest, targets: list) -> list[dict]:
    robot = ref.robot
    single = isinstance(body, IKRequest)
    matrices, orientation_flags = [], []
    for index, target in enumerate(targets):
        with located("body", *(("target",) if single else ("targets", index))):
            matrix, constrained = target_matrix(target, body.angle_unit)
        matrices.append(matrix)
        orientation_flags.append(constrained)
    reference = None
    if body.reference is not None:
        with located("body", "reference"):
            reference = joints_to_core(robot, body.reference, body.angle_unit)
    with located("body", "limits"):
        limits = limits_to_core(robot, body.limits, body.angle_unit)
    with located("body"):
        ordering = ordering_to_core(robot, body.ordering, body.max_solutions, body.max_joint_move, reference,
                                    body.angle_unit)
    budget, capped = _budget_seconds(request, body, len(targets))
    options = IKOptions(NumericOptions(starts=body.numeric.starts, time_budget_seconds=budget))
    results: list[IKResult | None] = [None] * len(targets)
    for constrained in (True, False):
        rows = [i for i, flag in enumerate(orientation_flags) if flag is constrained]
        if rows:
            started = time.perf_counter()
            solved = solve_ik_batch(robot, np.array([matrices[i] for i in rows]), constrain_orientation=constrained,
                                    reference=reference, options=options)
            observe_ik(solved[0].method, solved[0].structure, time.perf_counter() - started,
                       [len(result.solutions) for result in solved])
            for i, result in zip(rows, solved):
                results[i] = result
    wire = [
        _to_wire(ref.id, robot, result, select(robot, result, limits, filter_limits=body.filter_limits,
                                               reference=reference, ordering=ordering,
                                               max_equivalents=body.max_equivalents),
                 body.angle_unit, orientation_flags[i])
        for i, result in enumerate(results)
    ]
    if capped:
        note = (f"The server capped the numeric search at {budget * 1000.0:g} ms per target "
                f"(KIN_MAX_IK_TIME_MS per request), below the requested {body.numeric.time_budget_ms} ms.")
        for entry in wire:
            if entry["solver"]["time_budget_exhausted"]:
                entry["detail"] = f"{entry['detail']} {note}" if entry["detail"] else note
    return wire


def _solution_to_wire(robot: Robot, entry: Selected, unit: str, constrained: bool) -> dict:
    solution = entry.solution
    return {
        "joints": joints_from_core(robot, solution.joints, unit).tolist(),
        "branch": solution.branch,
        "within_limits": entry.within_limits,
        "violations": [violation_to_wire(robot, v, unit) for v in entry.violations],
        "residual": {"position": solution.position_residual,
                     "orientation": solution.orientation_residual if constrained else None},
    }


def _to_wire(robot_id: str, robot: Robot, result: IKResult, selection: Selection, unit: str,
             constrained: bool) -> dict:
    detail = " ".join(filter(None, [result.detail, *selection.notes])) or None
    return {
        "robot_id": robot_id,
        "status": selection.status,
        "detail": detail,
        "solutions": [_solution_to_wire(robot, e, unit, constrained) for e in selection.solutions],
        "rejected": [_solution_to_wire(robot, e, unit, constrained) for e in selection.rejected],
        "solver": {"method": result.method, "structure": result.structure, "complete": result.complete,
                   "time_budget_exhausted": result.search_exhausted_budget},
        "singularities": [{"kind": s.kind, "joints": list(s.joints), "relation": s.relation, "detail": s.detail}
                          for s in result.singularities],
        "free_joints": result.free_joints,
        "truncated": selection.expansion_truncated,
        "trimmed": selection.trimmed,
        "available": selection.available,
    }


@router.post("/robots/{robot_id}/ik", operation_id="inverse_kinematics", response_model=IKResponse,
             responses=problem_responses(404, 422))
def inverse_kinematics(request: Request, body: IKRequest, ref: RobotRef = Depends(catalogue_robot)) -> dict:
    """Every joint vector that reaches the target pose, each checked by forward kinematics."""
    return _solve(request, ref, body, [body.target])[0]


@router.post("/ik", operation_id="inverse_kinematics_inline", response_model=IKResponse,
             responses=problem_responses(422))
def inverse_kinematics_inline(request: Request, body: IKInlineRequest) -> dict:
    """Inverse kinematics for a robot described in the request body."""
    return _solve(request, inline_robot(request, body.robot), body, [body.target])[0]


@router.post("/robots/{robot_id}/ik/batch", operation_id="inverse_kinematics_batch", response_model=IKBatchResponse,
             responses=problem_responses(404, 413, 422))
def inverse_kinematics_batch(request: Request, body: IKBatchRequest,
                             ref: RobotRef = Depends(catalogue_robot)) -> dict:
    """Every solution for each target; the analytic solvers run vectorised over the targets."""
    check_batch_size(request, len(body.targets), "targets")
    return {"robot_id": ref.id, "results": _solve(request, ref, body, body.targets)}
