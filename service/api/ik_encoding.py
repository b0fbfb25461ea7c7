"""The core's :class:`IKAnswer` on the wire, in the request's units: the objects form and the arrays form.

Objects: one dict per target (``status``, ``detail``, ``solutions``,
``rejected``, ``solver``, …), each solution a dict with its ``violations`` and
``free_values`` (a direction target's roll about the tool axis under ``"roll"``). Arrays: the per-target fields and the two solution tables as
columns, solvers and singularity reports listed once and referred to by index.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..kinematics import Budget, Robot
from ..kinematics.ik import IKAnswer, SolutionTable
from ..units import radians_per
from .boundary import WIRE_NOTES, _unit_scale, violations_to_wire


def ik_objects(robot_id: str, robot: Robot, answer: IKAnswer, unit: str, budget: Budget) -> list[dict]:
    """The objects form: one dict per target, in target order."""
    budget.check("encoding")
    scale = _unit_scale(robot, unit)
    solvers = [{"method": s.method, "structure": s.structure, "complete": s.complete,
                "time_budget_exhausted": s.time_budget_exhausted} for s in answer.solvers]
    reports = [_report(report) for report in answer.singularity_reports]
    free_of_target = [list(answer.solvers[index].free_joints) for index in answer.solver.tolist()]
    angle = radians_per(unit)
    kept = _solution_dicts(answer.solutions, answer.solution_violations, answer, scale, free_of_target, angle)
    rejected = _solution_dicts(answer.rejected, answer.rejected_violations, answer, scale, free_of_target, angle)
    status, truncated, detail = answer.status.tolist(), answer.truncated.tolist(), answer.detail_list(WIRE_NOTES)
    trimmed, available = answer.trimmed.tolist(), answer.available.tolist()
    answers = []
    for row, solver in enumerate(answer.solver.tolist()):
        if row % 256 == 255:
            budget.check("encoding")
        answers.append({
            "robot_id": robot_id, "status": status[row], "detail": detail[row],
            "solutions": kept[row], "rejected": rejected[row], "solver": dict(solvers[solver]),
            "singularities": [dict(reports[i]) for i in answer.singularities[row]],
            "free_joints": list(free_of_target[row]), "truncated": truncated[row], "trimmed": trimmed[row],
            "available": available[row], "joint_names": robot.joint_names})
    return answers


def _solution_dicts(table: SolutionTable, outside: np.ndarray, answer: IKAnswer, scale: np.ndarray,
                    free_of_target: list[list[int]], angle: float) -> list[list[dict]]:
    """Each target's rows of ``table`` as solution dicts; ``outside`` (S, n) marks the joints a row violates;
    ``angle``: radians per unit of the request's angles (for the roll)."""
    if not len(table.target):  # the usual rejected table: none of the columns' conversions below is needed
        return [[] for _ in free_of_target]
    joints = (table.joints / scale).tolist()
    position = table.position.tolist()
    orientation = _listed(table.orientation, np.isnan)
    within = table.within_limits.tolist()
    branches = table.branches()
    violations = violations_to_wire(answer.limits, scale, outside, table.joints)
    targets = table.target.tolist()
    row_violations = [violations.get(k, ()) for k in range(len(targets))] if violations else [()] * len(targets)
    if any(free_of_target) or table.roll is not None:
        free_values = [{str(j): q[j] for j in free_of_target[target]} for q, target in zip(joints, targets)]
        if table.roll is not None:
            for free, roll in zip(free_values, _rolls(table, angle)):
                if roll is not None:
                    free["roll"] = roll
    else:
        free_values = [{}] * len(targets)  # one empty dict, read-only as the branches' dicts are
    solutions = [{"joints": q, "branch": branch, "within_limits": fits, "violations": violated,
                  "residual": {"position": position_error, "orientation": orientation_error}, "free_values": free}
                 for q, branch, fits, violated, position_error, orientation_error, free
                 in zip(joints, branches, within, row_violations, position, orientation, free_values)]
    if table.clearance is not None:
        for solution, clearance, contacts in zip(solutions, _listed(table.clearance, np.isinf), _contacts(table)):
            solution["clearance"], solution["collisions"] = clearance, contacts
    if len(free_of_target) == 1:
        return [solutions]
    starts, stops = table.bounds(len(free_of_target))  # grouped by target: each target's solutions are one slice
    return [solutions[start:stop] for start, stop in zip(starts.tolist(), stops.tolist())]


def _rolls(table: SolutionTable, angle: float) -> list[float | None]:
    """Each row's roll about the tool axis in the request's angle unit; None where the row has none."""
    return _listed(table.roll / angle, np.isnan)


def _listed(values: np.ndarray, missing: np.ufunc) -> list[float | None]:
    """A column (S,) as a list, None where ``missing`` (``np.isnan`` or ``np.isinf``) holds."""
    return _with_none(values, missing(values))


def _nulled(values: np.ndarray, missing: np.ufunc) -> np.ndarray | list[float | None]:
    """A column (S,) as it stands (orjson writes the array) when no value is ``missing``, else :func:`_listed`."""
    gaps = missing(values)
    return _with_none(values, gaps) if gaps.any() else values


def _with_none(values: np.ndarray, gaps: np.ndarray) -> list[float | None]:
    """``values`` (S,) as a list, None where ``gaps`` (S,) is true."""
    gap_list = gaps.tolist()
    if True not in gap_list:  # the usual column: as it stands
        return values.tolist()
    return [None if gap else value for value, gap in zip(values.tolist(), gap_list)]


def _contacts(table: SolutionTable) -> list[Sequence[dict]]:
    """Each row's pairs closer than the margin, as the wire names them (worded once, from the columns); a row
    without one gets the empty tuple (an empty array on the wire), shared."""
    contacts = table.contacts
    listed = contacts.pairs >= 0
    entries = [{"a": a, "b": b, "distance": distance} for (a, b), distance in
               zip(map(contacts.names.__getitem__, contacts.pairs[listed].tolist()),
                   contacts.distances[listed].tolist())]
    counts = listed.sum(axis=1)
    ends = np.cumsum(counts)
    rows: list[Sequence[dict]] = [()] * len(counts)
    close = np.flatnonzero(counts)
    for row, start, end in zip(close.tolist(), (ends - counts)[close].tolist(), ends[close].tolist()):
        rows[row] = entries[start:end]
    return rows


def ik_columns(robot_id: str, robot: Robot, answer: IKAnswer, unit: str, budget: Budget) -> dict:
    """The arrays form: per-target columns, the two solution tables as columns (numpy arrays, encoded as
    they stand)."""
    budget.check("encoding")
    scale, angle = _unit_scale(robot, unit), radians_per(unit)
    solvers = [{"method": s.method, "structure": s.structure, "complete": s.complete,
                "time_budget_exhausted": s.time_budget_exhausted, "free_joints": list(s.free_joints)}
               for s in answer.solvers]
    n_targets = len(answer)
    return {
        "robot_id": robot_id,
        "joint_names": robot.joint_names,
        "format": "arrays",
        "solvers": solvers,
        "singularity_reports": [_report(report) for report in answer.singularity_reports],
        "targets": {"status": answer.status.tolist(), "detail": answer.detail_list(WIRE_NOTES),
                    "solver": answer.solver,
                    "singularities": list(answer.singularities), "truncated": answer.truncated,
                    "trimmed": answer.trimmed, "available": answer.available,
                    "solution_count": np.bincount(answer.solutions.target, minlength=n_targets),
                    "rejected_count": np.bincount(answer.rejected.target, minlength=n_targets)},
        "solutions": _columns(answer.solutions, scale, answer, angle),
        "rejected": _columns(answer.rejected, scale, answer, angle),
    }


def _columns(table: SolutionTable, scale: np.ndarray, answer: IKAnswer, angle: float) -> dict:
    """One table as columns; ``free_values``: per free joint, each row's value of it, or None where the row's
    target has no such free joint; ``"roll"``: each row's roll about the tool axis (``angle``: radians per unit),
    or None."""
    joints = table.joints / scale
    orientation = _nulled(table.orientation, np.isnan)
    branch = {name: np.array([*values, None], dtype=object)[codes].tolist()
              for name, (values, codes) in table.labels.items()}
    free_values = {}
    if any(solver.free_joints for solver in answer.solvers):
        free_of_row = [answer.solvers[index].free_joints for index in answer.solver[table.target].tolist()]
        rows = joints.tolist()
        free_values = {str(j): [row[j] if j in free else None for row, free in zip(rows, free_of_row)]
                       for j in sorted({j for free in free_of_row for j in free})}
    if table.roll is not None:
        free_values["roll"] = _rolls(table, angle)
    columns = {"target": table.target, "joints": joints, "within_limits": table.within_limits,
               "residual_position": table.position, "residual_orientation": orientation, "branch": branch,
               "free_values": free_values}
    if table.clearance is not None:
        # null where no pair was checked (+inf)
        columns["clearance"], columns["collisions"] = _nulled(table.clearance, np.isinf), _contacts(table)
    return columns


def _report(singularity) -> dict:
    return {"kind": singularity.kind, "joints": list(singularity.joints), "relation": singularity.relation,
            "detail": singularity.detail}
