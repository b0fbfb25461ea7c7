"""Inverse kinematics: every solution, verified by forward kinematics."""

from __future__ import annotations

import time

import numpy as np
from fastapi import APIRouter, Depends, Query, Request

from ...kinematics import Robot
from ...kinematics.ik import (
    IKOptions,
    IKResult,
    NumericOptions,
    beyond_reach,
    free_joints_for,
    no_solution_detail,
    search_position,
    solve_direction,
    solve_free_joint_family,
    Selected,
    Selection,
    SolutionTable,
    results_from_arrays,
    select,
    select_arrays,
    solve_ik_arrays,
    cached_plan,
    solve_ik_batch,
    unreachable_details,
)
from ...kinematics import Budget, violations
from ..boundary import (
    _unit_scale,
    joints_from_core,
    joints_to_core,
    limits_to_core,
    located,
    ordering_to_core,
    target_direction,
    target_matrices,
    target_matrix,
    violation_to_wire,
)
from ..budget import budget_of, check_ik_cost
from ..deps import RobotRef, catalogue_robot, check_batch_size, inline_robot, settings_of, with_request_frames
from ..observability import observe_ik
from ..problems import ProblemError, problem_responses
from ..responses import FastJSONResponse
from ..routing import FastJSONRoute
from ..schemas.ik import (IKBatchArraysResponse, IKBatchRequest, IKBatchResponse, IKInlineRequest, IKRequest,
                          IKResponse)
from ..schemas.render import RenderView
from .render import IK_PICTURE_RESPONSE, ik_picture, wants_svg

router = APIRouter(prefix="/v1", route_class=FastJSONRoute, tags=["inverse kinematics"])
RENDER_QUERY = Query(None, description="answer with an SVG picture of every distinct solution (those that differ "
                                       "only by whole turns share a panel) seen from this view, instead of JSON; "
                                       "the same as Accept: image/svg+xml with the iso view")


def _numeric_options(request: Request, body: IKRequest | IKBatchRequest, targets: int) -> IKOptions:
    """The numeric search's bounds: starts and iterations (deterministic), under the request's deadline narrowed
    to the numeric time cap: the request's time_budget_ms per target, at most KIN_MAX_IK_TIME_MS per request."""
    cap_ms = settings_of(request).max_ik_time_ms
    if body.numeric.time_budget_ms is not None:
        cap_ms = min(body.numeric.time_budget_ms * targets, cap_ms)
    return IKOptions(NumericOptions(starts=body.numeric.starts, max_iterations=body.numeric.iterations),
                     budget=budget_of(request).within(cap_ms / 1000.0))


def _settings(request: Request, robot: Robot, body: IKRequest | IKBatchRequest, matrices: np.ndarray,
              flags: np.ndarray, form: str):
    """Reference, limits, ordering and numeric options of a request, in core units, after the cost model has
    accepted the request's worst-case answer (413/422 before any solving otherwise)."""
    reference = None
    if body.reference is not None:
        with located("body", "reference"):
            reference = joints_to_core(robot, body.reference, body.angle_unit)
    with located("body", "limits"):
        limits = limits_to_core(robot, body.limits, body.angle_unit)
    with located("body"):
        ordering = ordering_to_core(robot, body.ordering, body.max_solutions, body.max_joint_move, reference,
                                    body.angle_unit)
    # the kept plans (a position-only plan holding joints at the reference is rebuilt per request; its count is
    # the same as the kept one's)
    plans = [cached_plan(robot, constrain_orientation=bool(kind), reference=None) for kind in np.unique(flags)]
    numeric = any(plan is None for plan in plans)
    per_target = max(body.numeric.starts if plan is None else plan.generic_count for plan in plans)
    check_ik_cost(settings_of(request), robot, limits, targets=len(matrices), solutions_per_target=per_target,
                  max_equivalents=body.max_equivalents, max_solutions=body.max_solutions, form=form,
                  numeric_starts=body.numeric.starts if numeric else None)
    return reference, limits, ordering, _numeric_options(request, body, len(matrices))


def _targets_to_core(body: IKRequest | IKBatchRequest, targets: list) -> tuple[np.ndarray, np.ndarray, dict]:
    """Matrices (N, 4, 4), which constrain orientation (N,), and the position + direction targets: row →
    (position, tool axis, world direction). A direction row's matrix holds its position; its flag is true."""
    prefix = ("body", "target") if isinstance(body, IKRequest) else ("body", "targets")
    directions = {}
    for index, target in enumerate(targets):
        with located(*prefix) if isinstance(body, IKRequest) else located(*prefix, index):
            direction = target_direction(target)
        if direction is not None:
            directions[index] = direction
    if not directions:
        if isinstance(body, IKRequest):
            with located(*prefix):
                matrix, constrained = target_matrix(targets[0], body.angle_unit)
            return matrix[None], np.array([constrained]), directions
        matrices, flags = target_matrices(targets, body.angle_unit, *prefix)
        return matrices, flags, directions
    matrices, flags = np.tile(np.eye(4), (len(targets), 1, 1)), np.ones(len(targets), dtype=bool)
    for index, target in enumerate(targets):
        if index in directions:
            matrices[index, :3, 3] = directions[index][0]
        else:
            with located(*prefix) if isinstance(body, IKRequest) else located(*prefix, index):
                matrices[index], flags[index] = target_matrix(target, body.angle_unit)
    return matrices, flags, directions


def _solved_by_kind(robot: Robot, matrices: np.ndarray, flags: np.ndarray, reference, budget: Budget, free=None,
                    directions: dict | None = None, incomplete: dict | None = None):
    """Solve full-pose and position-only targets apart: yields (constrained, rows, arrays, started).

    ``arrays`` is None when no analytic family covers the robot, or for the targets where a closed form on rounded
    geometry could not promise every solution (the caller then runs :func:`solve_ik_batch`, whose fallback answers).
    Full poses of a redundant arm with ``free`` joints (see :func:`_free_joints`) are solved as the family over
    the free values: one answer row per target holding every value's solutions.
    """
    directions = directions or {}
    for axis in {tuple(direction[1].tolist()) for direction in directions.values()}:  # position + direction
        rows = np.array([row for row, direction in sorted(directions.items())
                         if tuple(direction[1].tolist()) == axis])
        started = time.perf_counter()
        with located("body"):
            arrays = solve_direction(robot, np.array([directions[row][0] for row in rows]),
                                     np.array([directions[row][2] for row in rows]), np.array(axis), reference)
        if arrays is None:
            raise ProblemError(422, "unsupported-target", "Target kind not solved for this arm",
                               "No closed-form family covers position + tool direction targets of this arm with "
                               "this tool axis; give a full pose or the position only.")
        yield True, rows, arrays, started
    flags = flags.copy()
    flags[list(directions)] = 2  # solved above
    for constrained in (True, False):
        rows = np.flatnonzero(flags == constrained)
        if len(rows):
            started = time.perf_counter()
            if constrained and free is not None:
                with located("body"):
                    family = solve_free_joint_family(robot, matrices[rows], free, reference)
                if family is not None and incomplete is not None:
                    for row, missing in zip(rows.tolist(), family.missing.tolist()):
                        if missing:
                            incomplete[row] = (f"At {missing} of the free values the locked arm falls outside the "
                                               f"closed-form family, so no solution is listed there.")
                yield constrained, rows, None if family is None else family.arrays, started
                continue
            arrays = solve_ik_arrays(robot, matrices[rows], constrain_orientation=constrained, reference=reference,
                                     budget=budget)
            if arrays is None or arrays.complete.all():
                yield constrained, rows, arrays, started
                continue
            # a closed form on rounded geometry that cannot promise every solution for some targets: those go to
            # the fallback solver (through solve_ik_batch), the others keep the closed form's answer
            complete = np.flatnonzero(arrays.complete)
            if len(complete):
                yield constrained, rows[complete], arrays.take(complete), started
            yield constrained, rows[~arrays.complete], None, started


# --- redundant arms: free joints (issue 14) ---------------------------------------------------------------
def _free_joints(robot: Robot, body: IKRequest | IKBatchRequest):
    """The free joints of a redundant arm's full-pose targets, in core units, or None (not redundant, or no
    locking leaves a family: the numeric search then answers, as before)."""
    if body.free_joints is None and robot.dof <= 6:
        return None
    requested = None
    if body.free_joints is not None:
        requested = []
        for index, choice in enumerate(body.free_joints):
            values = choice.values
            if values is not None and 0 <= choice.joint < robot.dof:
                values = (np.asarray(values, dtype=float) * _unit_scale(robot, body.angle_unit)[choice.joint]).tolist()
            requested.append((choice.joint, values, choice.samples))
    with located("body"):
        return free_joints_for(robot, requested)


def _with_free_values(wire: dict, free, robot: Robot, position: np.ndarray) -> dict:
    """Each solution's ``free_values`` (its own values of the answer's free joints, in the request's unit), and
    the family's meaning of an empty answer."""
    for key in ("solutions", "rejected"):
        for solution in wire[key]:
            solution["free_values"] = {str(j): solution["joints"][j] for j in wire["free_joints"]}
    if free is not None and wire["status"] == "unreachable" and wire["solver"]["method"] == "analytic":
        wire["detail"] = no_solution_detail(robot, free, position)
    if free is not None and wire["solver"]["method"] == "numeric":
        names = ", ".join(f"q{f.joint + 1}" for f in free)
        note = (f"No closed-form family covers this arm with {names} locked, so the free joints were not applied: "
                f"a numeric search over every joint answered.")
        wire["detail"] = f"{wire['detail']} {note}" if wire["detail"] else note
    return wire
# --- end of redundant arms ----------------------------------------------------------------------------------


def _numeric_answers(ref: RobotRef, body: IKRequest | IKBatchRequest, matrices: np.ndarray, rows: np.ndarray,
                     constrained: bool, reference, limits, ordering, options: IKOptions, budget: Budget,
                     started: float):
    """Wire answers (row, dict) from the numeric search, for structures no analytic family covers."""
    robot = ref.robot
    solved = solve_ik_batch(robot, matrices[rows], constrain_orientation=constrained, reference=reference,
                            options=options)
    observe_ik(solved[0].method, solved[0].structure, time.perf_counter() - started,
               [len(result.solutions) for result in solved])
    for row, result in zip(rows.tolist(), solved):
        selection = select(robot, result, limits, filter_limits=body.filter_limits, reference=reference,
                           ordering=ordering, max_equivalents=body.max_equivalents, budget=budget)
        yield row, _to_wire(ref.id, robot, result, selection, body.angle_unit, constrained)


def _solve(request: Request, ref: RobotRef, body: IKRequest | IKBatchRequest, targets: list) -> list[dict]:
    ref = with_request_frames(ref, body)
    robot = ref.robot
    matrices, flags, directions = _targets_to_core(body, targets)
    reference, limits, ordering, options = _settings(request, robot, body, matrices, flags, "objects")
    budget = budget_of(request)
    free = _free_joints(robot, body)
    answers: list[dict | None] = [None] * len(targets)
    incomplete: dict[int, str] = {}
    for constrained, rows, arrays, started in _solved_by_kind(robot, matrices, flags.astype(int), reference, budget,
                                                              free, directions, incomplete):
        if arrays is None:  # no analytic family: the numeric search, one target at a time
            for row, wire in _numeric_answers(ref, body, matrices, rows, constrained, reference, limits, ordering,
                                              options, budget, started):
                answers[row] = wire
            continue
        observe_ik("analytic", arrays.structure, time.perf_counter() - started, arrays.count.tolist())
        results = results_from_arrays(robot, arrays, matrices[rows], constrained and rows[0] not in directions,
                                      reference)
        chosen = select_arrays(robot, arrays, limits, filter_limits=body.filter_limits, reference=reference,
                               ordering=ordering, max_equivalents=body.max_equivalents, budget=budget)
        budget.check("encoding")
        kept, dropped = (_rows_to_wire(robot, table, limits, body.angle_unit, constrained)
                         for table in (chosen.solutions, chosen.rejected))
        kept_starts, dropped_starts = (np.searchsorted(table.target, np.arange(len(rows) + 1)).tolist()
                                       for table in (chosen.solutions, chosen.rejected))
        for local, (row, result) in enumerate(zip(rows.tolist(), results)):
            answers[row] = _wire(ref.id, result, str(chosen.status[local]),
                                 kept[kept_starts[local]:kept_starts[local + 1]],
                                 dropped[dropped_starts[local]:dropped_starts[local + 1]],
                                 chosen.notes.get(local, []), bool(chosen.truncated[local]),
                                 int(chosen.trimmed[local]), int(chosen.available[local]))
    for row, why in incomplete.items():  # a free value whose locked arm no family covered
        answers[row]["solver"]["complete"] = False
        answers[row]["detail"] = " ".join(filter(None, [answers[row]["detail"], why]))
    for row in directions:
        if answers[row]["status"] == "unreachable":
            answers[row]["detail"] = _direction_detail(robot, matrices[row, :3, 3])
    for row, wire in enumerate(answers):  # position-only: held joints must not make a reachable point unreachable
        if not flags[row] and wire["status"] == "unreachable" and wire["free_joints"]:
            result = search_position(robot, matrices[row], wire["free_joints"], reference, options)
            selection = select(robot, result, limits, filter_limits=body.filter_limits, reference=reference,
                               ordering=ordering, max_equivalents=body.max_equivalents, budget=budget)
            answers[row] = _to_wire(ref.id, robot, result, selection, body.angle_unit, False)
    answers = [_with_free_values(wire, free if flag and row not in directions else None, robot, matrix[:3, 3])
               for row, (wire, flag, matrix) in enumerate(zip(answers, flags.tolist(), matrices))]
    for answer in answers:
        answer["joint_names"] = robot.joint_names
    return answers


def _direction_detail(robot: Robot, position: np.ndarray) -> str:
    if bool(beyond_reach(robot, position)):
        return "The target position is outside the workspace (farther from the base than the arm can reach)."
    return ("No joint vector puts the tool at this position with its axis along the direction (every solution of "
            "the closed form was checked).")


def _solve_arrays(request: Request, ref: RobotRef, body: IKBatchRequest) -> FastJSONResponse:
    """The batch answer as columns: solve, select and encode with array operations, no loop over targets."""
    ref = with_request_frames(ref, body)
    robot = ref.robot
    matrices, flags, directions = _targets_to_core(body, body.targets)
    reference, limits, ordering, options = _settings(request, robot, body, matrices, flags, "arrays")
    budget = budget_of(request)
    free = _free_joints(robot, body)
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
    incomplete: dict[int, str] = {}
    for constrained, rows, arrays, started in _solved_by_kind(robot, matrices, flags.astype(int), reference, budget,
                                                              free, directions, incomplete):
        if arrays is None:  # no analytic family: the numeric search, one target at a time
            for row, wire in _numeric_answers(ref, body, matrices, rows, constrained, reference, limits, ordering,
                                              options, budget, started):
                status[row], detail[row], truncated[row], trimmed[row], available[row] = (
                    wire["status"], wire["detail"], wire["truncated"], wire["trimmed"], wire["available"])
                solver[row] = _index(solvers, {**wire["solver"], "free_joints": wire["free_joints"]})
                singular[row] = [_index(reports, s) for s in wire["singularities"]]
                kept_tables.append(_table_from_wire(row, wire["solutions"], robot.dof))
                rejected_tables.append(_table_from_wire(row, wire["rejected"], robot.dof))
            continue
        observe_ik("analytic", arrays.structure, time.perf_counter() - started, arrays.count.tolist())
        chosen = select_arrays(robot, arrays, limits, filter_limits=body.filter_limits, reference=reference,
                               ordering=ordering, max_equivalents=body.max_equivalents, budget=budget)
        status[rows], truncated[rows] = chosen.status, chosen.truncated
        trimmed[rows], available[rows] = chosen.trimmed, chosen.available
        for promise in (True, False):  # the general 6R solver may not promise every target complete
            part = arrays.complete == promise
            if part.any():
                solver[rows[part]] = _index(solvers, {
                    "method": "analytic", "structure": arrays.structure, "complete": promise,
                    "time_budget_exhausted": False, "free_joints": arrays.free_joints})
        unreachable = unreachable_details(robot, arrays, matrices[rows], constrained, reference, budget)
        if rows[0] in directions:
            unreachable = {local: _direction_detail(robot, matrices[rows[local], :3, 3]) for local in unreachable}
        elif constrained and free is not None:
            unreachable = {local: no_solution_detail(robot, free, matrices[rows[local], :3, 3])
                           for local in unreachable}
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
    for row, why in incomplete.items():  # a free value whose locked arm no family covered
        solver[row] = _index(solvers, {**solvers[solver[row]], "complete": False})
        detail[row] = " ".join(filter(None, [detail[row], why]))
    for row in np.flatnonzero(~flags & (status == "unreachable")).tolist():  # held joints: search every joint
        entry = solvers[solver[row]]
        if not entry["free_joints"] or entry["method"] != "analytic":
            continue
        result = search_position(robot, matrices[row], entry["free_joints"], reference, options)
        selection = select(robot, result, limits, filter_limits=body.filter_limits, reference=reference,
                           ordering=ordering, max_equivalents=body.max_equivalents, budget=budget)
        wire = _to_wire(ref.id, robot, result, selection, body.angle_unit, False)
        status[row], detail[row], truncated[row], trimmed[row], available[row] = (
            wire["status"], wire["detail"], wire["truncated"], wire["trimmed"], wire["available"])
        solver[row] = _index(solvers, {**wire["solver"], "free_joints": wire["free_joints"]})
        singular[row] = [_index(reports, s) for s in wire["singularities"]]
        kept_tables.append(_table_from_wire(row, wire["solutions"], robot.dof))  # wire joints: request units
        rejected_tables.append(_table_from_wire(row, wire["rejected"], robot.dof))
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
    budget.check("encoding")
    return FastJSONResponse({
        "robot_id": ref.id,
        "joint_names": robot.joint_names,
        "format": "arrays",
        "solvers": solvers,
        "singularity_reports": reports,
        "targets": {"status": status.tolist(), "detail": detail, "solver": solver, "singularities": singular,
                    "truncated": truncated, "trimmed": trimmed, "available": available,
                    "solution_count": np.bincount(kept.target, minlength=n_targets),
                    "rejected_count": np.bincount(rejected.target, minlength=n_targets)},
        "solutions": _with_free_columns(_columns(kept), kept, solvers, solver),
        "rejected": _with_free_columns(_columns(rejected), rejected, solvers, solver),
    })


def _with_free_columns(columns: dict, table: SolutionTable, solvers: list[dict], solver: np.ndarray) -> dict:
    """The arrays form's ``free_values``: per free joint, each row's value of it (request units), or None where
    the row's target has no such free joint."""
    free_of_row = [solvers[index]["free_joints"] for index in np.asarray(solver)[table.target].tolist()]
    joints = np.asarray(table.joints).tolist()
    columns["free_values"] = {str(j): [row[j] if j in free else None for row, free in zip(joints, free_of_row)]
                              for j in sorted({j for free in free_of_row for j in free})}
    return columns


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


def _rows_to_wire(robot: Robot, table: SolutionTable, limits, unit: str, constrained: bool) -> list[dict]:
    """The wire form of each row of a solution table (core units), violations included."""
    joints = (table.joints / _unit_scale(robot, unit)).tolist()
    position = table.position.tolist()
    orientation = table.orientation.tolist() if constrained else [None] * len(position)
    branch = [(name, np.array([*values, None], dtype=object)[codes].tolist())
              for name, (values, codes) in table.labels.items()]
    within = table.within_limits.tolist()
    return [{"joints": joints[k], "branch": {name: column[k] for name, column in branch if column[k] is not None},
             "within_limits": within[k],
             "violations": [] if within[k] else [violation_to_wire(robot, v, unit)
                                                 for v in violations(robot, limits, table.joints[k])],
             "residual": {"position": position[k], "orientation": orientation[k]}}
            for k in range(len(position))]


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
             responses={200: IK_PICTURE_RESPONSE, **problem_responses(404, 422)})
def inverse_kinematics(request: Request, body: IKRequest, ref: RobotRef = Depends(catalogue_robot),
                       render: RenderView | None = RENDER_QUERY):
    """Every joint vector that reaches the target pose, each checked by forward kinematics."""
    return _answer_or_picture(request, ref, body, render)


@router.post("/ik", operation_id="inverse_kinematics_inline", response_model=IKResponse,
             responses={200: IK_PICTURE_RESPONSE, **problem_responses(422)})
def inverse_kinematics_inline(request: Request, body: IKInlineRequest, render: RenderView | None = RENDER_QUERY):
    """Inverse kinematics for a robot described in the request body."""
    return _answer_or_picture(request, inline_robot(request, body.robot), body, render)


# --- the answer as a picture (issue 15): ?render=VIEW or Accept: image/svg+xml --------------------------------
def _answer_or_picture(request: Request, ref: RobotRef, body: IKRequest, render: RenderView | None):
    answer = _solve(request, ref, body, [body.target])[0]
    if render is None and not wants_svg(request):
        return answer
    return ik_picture(ref.robot, ref.id, answer, body.angle_unit, render or "iso", body.reference is not None)
# ---------------------------------------------------------------------------------------------------------------


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
