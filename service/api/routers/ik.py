"""Inverse kinematics: every solution, verified by forward kinematics."""

from __future__ import annotations

import time

import numpy as np
from fastapi import APIRouter, Depends, Request

from ...kinematics import Robot
from ...kinematics.ik import (
    IKOptions,
    IKResult,
    NumericOptions,
    Selected,
    Selection,
    SolutionTable,
    results_from_arrays,
    select,
    select_arrays,
    solve_ik_arrays,
    solve_ik_batch,
    unreachable_details,
)
from ..boundary import (
    _unit_scale,
    joints_from_core,
    joints_to_core,
    limits_to_core,
    located,
    ordering_to_core,
    target_matrices,
    target_matrix,
    violation_to_wire,
)
from ..deps import RobotRef, catalogue_robot, check_batch_size, inline_robot, settings_of
from ..observability import observe_ik
from ..problems import problem_responses
from ..responses import FastJSONResponse
from ..routing import FastJSONRoute
from ..schemas.ik import (IKBatchArraysResponse, IKBatchRequest, IKBatchResponse, IKInlineRequest, IKRequest,
                          IKResponse)

router = APIRouter(prefix="/v1", route_class=FastJSONRoute, tags=["inverse kinematics"])


def _budget_seconds(request: Request, body: IKRequest | IKBatchRequest, targets: int) -> tuple[float, bool]:
    """The numeric search's time per target: the request's, within the server's cap (KIN_MAX_IK_TIME_MS) per
    request, which a batch shares across its targets. Also whether the cap lowered the request's budget."""
    cap_ms = settings_of(request).max_ik_time_ms / targets
    requested_ms = body.numeric.time_budget_ms
    return min(requested_ms, cap_ms) / 1000.0, cap_ms < requested_ms


def _settings(request: Request, robot: Robot, body: IKRequest | IKBatchRequest, targets: int):
    """Reference, limits, ordering and numeric options of a request, in core units, and the numeric cap note."""
    reference = None
    if body.reference is not None:
        with located("body", "reference"):
            reference = joints_to_core(robot, body.reference, body.angle_unit)
    with located("body", "limits"):
        limits = limits_to_core(robot, body.limits, body.angle_unit)
    with located("body"):
        ordering = ordering_to_core(robot, body.ordering, body.max_solutions, body.max_joint_move, reference,
                                    body.angle_unit)
    budget, capped = _budget_seconds(request, body, targets)
    options = IKOptions(NumericOptions(starts=body.numeric.starts, time_budget_seconds=budget))
    note = None
    if capped:
        note = (f"The server capped the numeric search at {budget * 1000.0:g} ms per target "
                f"(KIN_MAX_IK_TIME_MS per request), below the requested {body.numeric.time_budget_ms} ms.")
    return reference, limits, ordering, options, note


def _solved_by_kind(robot: Robot, matrices: np.ndarray, flags: np.ndarray, reference):
    """Solve full-pose and position-only targets apart: yields (constrained, rows, arrays, started).

    ``arrays`` is None when no analytic family covers the robot (the caller then runs the numeric search).
    """
    for constrained in (True, False):
        rows = np.flatnonzero(flags == constrained)
        if len(rows):
            started = time.perf_counter()
            yield constrained, rows, solve_ik_arrays(robot, matrices[rows], constrain_orientation=constrained,
                                                     reference=reference), started


def _numeric_answers(ref: RobotRef, body: IKRequest | IKBatchRequest, matrices: np.ndarray, rows: np.ndarray,
                     constrained: bool, reference, limits, ordering, options, note, started: float):
    """Wire answers (row, dict) from the numeric search, for structures no analytic family covers."""
    robot = ref.robot
    solved = solve_ik_batch(robot, matrices[rows], constrain_orientation=constrained, reference=reference,
                            options=options)
    observe_ik(solved[0].method, solved[0].structure, time.perf_counter() - started,
               [len(result.solutions) for result in solved])
    for row, result in zip(rows.tolist(), solved):
        selection = select(robot, result, limits, filter_limits=body.filter_limits, reference=reference,
                           ordering=ordering, max_equivalents=body.max_equivalents)
        yield row, _capped(_to_wire(ref.id, robot, result, selection, body.angle_unit, constrained), note)


def _solve(request: Request, ref: RobotRef, body: IKRequest | IKBatchRequest, targets: list) -> list[dict]:
    robot = ref.robot
    if isinstance(body, IKRequest):
        with located("body", "target"):
            matrix, constrained = target_matrix(targets[0], body.angle_unit)
        matrices, flags = matrix[None], np.array([constrained])
    else:
        matrices, flags = target_matrices(targets, body.angle_unit, "body", "targets")
    reference, limits, ordering, options, note = _settings(request, robot, body, len(targets))
    answers: list[dict | None] = [None] * len(targets)
    for constrained, rows, arrays, started in _solved_by_kind(robot, matrices, flags, reference):
        if arrays is None:  # no analytic family: the numeric search, one target at a time
            for row, wire in _numeric_answers(ref, body, matrices, rows, constrained, reference, limits, ordering,
                                              options, note, started):
                answers[row] = wire
            continue
        observe_ik("analytic", arrays.structure, time.perf_counter() - started, arrays.count.tolist())
        results = results_from_arrays(robot, arrays, matrices[rows], constrained, reference)
        chosen = select_arrays(robot, arrays, limits, filter_limits=body.filter_limits, reference=reference,
                               ordering=ordering, max_equivalents=body.max_equivalents)
        kept = chosen.solutions
        joints = (kept.joints / _unit_scale(robot, body.angle_unit)).tolist()
        position = kept.position.tolist()
        orientation = kept.orientation.tolist() if constrained else [None] * len(position)
        branch = [(name, np.array([*values, None], dtype=object)[codes].tolist())
                  for name, (values, codes) in kept.labels.items()]
        starts = np.searchsorted(kept.target, np.arange(len(rows) + 1)).tolist()
        for local, (row, result) in enumerate(zip(rows.tolist(), results)):
            selection = chosen.selections.get(local)
            if selection is not None:
                answers[row] = _to_wire(ref.id, robot, result, selection, body.angle_unit, constrained)
                continue
            solutions = [{"joints": joints[k], "branch": {name: column[k] for name, column in branch
                                                          if column[k] is not None},
                          "within_limits": True, "violations": [],
                          "residual": {"position": position[k], "orientation": orientation[k]}}
                         for k in range(starts[local], starts[local + 1])]
            answers[row] = _wire(ref.id, result, str(chosen.status[local]), solutions, [],
                                 chosen.notes.get(local, []), bool(chosen.truncated[local]),
                                 int(chosen.trimmed[local]), int(chosen.available[local]))
    return answers


def _solve_arrays(request: Request, ref: RobotRef, body: IKBatchRequest) -> FastJSONResponse:
    """The batch answer as columns: solve, select and encode with array operations, no loop over targets."""
    robot = ref.robot
    matrices, flags = target_matrices(body.targets, body.angle_unit, "body", "targets")
    reference, limits, ordering, options, note = _settings(request, robot, body, len(matrices))
    n_targets = len(matrices)
    status = np.empty(n_targets, dtype=object)
    detail: list[str | None] = [None] * n_targets
    solver = np.zeros(n_targets, dtype=int)
    singular: list[list[int]] = [[] for _ in range(n_targets)]
    truncated, trimmed = np.zeros(n_targets, dtype=bool), np.zeros(n_targets, dtype=int)
    available = np.zeros(n_targets, dtype=int)
    solvers: list[dict] = []
    reports: list[dict] = []
    kept_tables, rejected_tables = [], []
    scale = _unit_scale(robot, body.angle_unit)
    for constrained, rows, arrays, started in _solved_by_kind(robot, matrices, flags, reference):
        if arrays is None:  # no analytic family: the numeric search, one target at a time
            for row, wire in _numeric_answers(ref, body, matrices, rows, constrained, reference, limits, ordering,
                                              options, note, started):
                status[row], detail[row], truncated[row], trimmed[row], available[row] = (
                    wire["status"], wire["detail"], wire["truncated"], wire["trimmed"], wire["available"])
                solver[row] = _index(solvers, {**wire["solver"], "free_joints": wire["free_joints"]})
                singular[row] = [_index(reports, s) for s in wire["singularities"]]
                kept_tables.append(_table_from_wire(row, wire["solutions"], robot.dof))
                rejected_tables.append(_table_from_wire(row, wire["rejected"], robot.dof))
            continue
        observe_ik("analytic", arrays.structure, time.perf_counter() - started, arrays.count.tolist())
        chosen = select_arrays(robot, arrays, limits, filter_limits=body.filter_limits, reference=reference,
                               ordering=ordering, max_equivalents=body.max_equivalents)
        status[rows], truncated[rows] = chosen.status, chosen.truncated
        trimmed[rows], available[rows] = chosen.trimmed, chosen.available
        for promise in (True, False):  # the general 6R solver may not promise every target complete
            part = arrays.complete == promise
            if part.any():
                solver[rows[part]] = _index(solvers, {
                    "method": "analytic", "structure": arrays.structure, "complete": promise,
                    "time_budget_exhausted": False, "free_joints": arrays.free_joints})
        unreachable = unreachable_details(robot, arrays, matrices[rows], constrained, reference)
        for local in set(unreachable) | set(chosen.notes):
            detail[rows[local]] = " ".join(filter(None, [unreachable.get(local), *chosen.notes.get(local, [])])) or None
        solved = arrays.count > 0
        for mask, flag in arrays.singularities.entries:
            index = _index(reports, {"kind": flag.kind, "joints": list(flag.joints), "relation": flag.relation,
                                     "detail": flag.detail})
            for local in np.flatnonzero(mask & solved).tolist():
                if index not in singular[rows[local]]:
                    singular[rows[local]].append(index)
        for table, into in ((chosen.solutions, kept_tables), (chosen.rejected, rejected_tables)):
            table.target = rows[table.target]
            table.joints = table.joints / scale
            if not constrained:
                table.orientation = np.full(len(table.target), np.nan)
            into.append(table)
    kept, rejected = (_merged(tables, robot.dof) for tables in (kept_tables, rejected_tables))
    # number solvers and singularity reports by first appearance in target order, as a reader meets them
    present, first = np.unique(solver, return_index=True)
    renumber = np.zeros(max(len(solvers), 1), dtype=int)
    renumber[present[np.argsort(first)]] = np.arange(len(present))
    solvers, solver = [solvers[i] for i in present[np.argsort(first)]], renumber[solver]
    order: dict[int, int] = {}
    for flags in singular:
        for index in flags:
            order.setdefault(index, len(order))
    reports = [reports[i] for i in sorted(order, key=order.get)]
    singular = [[order[i] for i in flags] for flags in singular] if order else singular
    return FastJSONResponse({
        "robot_id": ref.id,
        "format": "arrays",
        "solvers": solvers,
        "singularity_reports": reports,
        "targets": {"status": status.tolist(), "detail": detail, "solver": solver, "singularities": singular,
                    "truncated": truncated, "trimmed": trimmed, "available": available,
                    "solution_count": np.bincount(kept.target, minlength=n_targets),
                    "rejected_count": np.bincount(rejected.target, minlength=n_targets)},
        "solutions": _columns(kept),
        "rejected": _columns(rejected),
    })


def _capped(wire: dict, note: str | None) -> dict:
    """Add the server's note on a capped numeric budget to an answer whose search ran out of time."""
    if note and wire["solver"]["time_budget_exhausted"]:
        wire["detail"] = f"{wire['detail']} {note}" if wire["detail"] else note
    return wire


def _index(items: list[dict], item: dict) -> int:
    """Position of ``item`` in ``items``, appending it when new."""
    try:
        return items.index(item)
    except ValueError:
        items.append(item)
        return len(items) - 1


def _table_from_wire(row: int, solutions: list[dict], dof: int) -> SolutionTable:
    names = sorted({name for s in solutions for name in s["branch"]})
    labels = {}
    for name in names:
        values = tuple(sorted({s["branch"][name] for s in solutions if name in s["branch"]}, key=str))
        labels[name] = (values, np.array([values.index(s["branch"][name]) if name in s["branch"] else -1
                                          for s in solutions], dtype=np.int8))
    return SolutionTable(np.full(len(solutions), row), np.array([s["joints"] for s in solutions]).reshape(-1, dof),
                         np.array([s["within_limits"] for s in solutions], dtype=bool),
                         np.array([s["residual"]["position"] for s in solutions], dtype=float),
                         np.array([np.nan if s["residual"]["orientation"] is None else s["residual"]["orientation"]
                                   for s in solutions], dtype=float), labels)


def _merged(tables: list[SolutionTable], dof: int) -> SolutionTable:
    table = SolutionTable.concatenate(tables, dof)
    return table.take(np.argsort(table.target, kind="stable")) if len(tables) > 1 else table


def _columns(table: SolutionTable) -> dict:
    orientation = table.orientation
    if np.isnan(orientation).any():
        orientation = [None if np.isnan(value) else value for value in orientation.tolist()]
    branch = {}
    for name, (values, codes) in table.labels.items():
        vocabulary = np.array([*values, None], dtype=object)
        branch[name] = vocabulary[codes].tolist()
    return {"target": table.target, "joints": table.joints, "within_limits": table.within_limits,
            "residual_position": table.position, "residual_orientation": orientation, "branch": branch}


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
    return _wire(robot_id, result, selection.status,
                 [_solution_to_wire(robot, e, unit, constrained) for e in selection.solutions],
                 [_solution_to_wire(robot, e, unit, constrained) for e in selection.rejected],
                 selection.notes, selection.expansion_truncated, selection.trimmed, selection.available)


def _wire(robot_id: str, result: IKResult, status: str, solutions: list[dict], rejected: list[dict],
          notes: list[str], truncated: bool, trimmed: int, available: int) -> dict:
    return {
        "robot_id": robot_id,
        "status": status,
        "detail": " ".join(filter(None, [result.detail, *notes])) or None,
        "solutions": solutions,
        "rejected": rejected,
        "solver": {"method": result.method, "structure": result.structure, "complete": result.complete,
                   "time_budget_exhausted": result.search_exhausted_budget},
        "singularities": [{"kind": s.kind, "joints": list(s.joints), "relation": s.relation, "detail": s.detail}
                          for s in result.singularities],
        "free_joints": result.free_joints,
        "truncated": truncated,
        "trimmed": trimmed,
        "available": available,
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


@router.post("/robots/{robot_id}/ik/batch", operation_id="inverse_kinematics_batch",
             response_model=IKBatchResponse | IKBatchArraysResponse, responses=problem_responses(404, 413, 422))
def inverse_kinematics_batch(request: Request, body: IKBatchRequest,
                             ref: RobotRef = Depends(catalogue_robot)):
    """Every solution for each target; the analytic solvers run vectorised over the targets."""
    check_batch_size(request, len(body.targets), "targets")
    if body.format == "arrays":
        return _solve_arrays(request, ref, body)
    # built field by field to IKBatchResponse (a test validates it against the model), so it is encoded as it
    # stands: validating tens of thousands of solution objects again would cost more than solving them
    return FastJSONResponse({"robot_id": ref.id, "results": _solve(request, ref, body, body.targets)})
