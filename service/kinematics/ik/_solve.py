"""The core as a Python library: IK of one pose or many, as records or padded arrays.

These are views of the one answer (:func:`~._answer.answer_ik`), made for Python callers, as the wire's two forms
are made for HTTP clients: no limits are applied (each solution once, revolute joints in (−π, π]) and, with a
reference, the solutions come nearest first (wrap-aware, the largest single joint move).

* :func:`solve_ik` and :func:`solve_ik_batch`: :class:`~._types.IKResult` records, the numeric search answering
  where no closed form covers or promises a target.
* :func:`solve_ik_arrays`: the closed form alone, as arrays padded to the most solutions of any target
  (:class:`IKArrays`), or None when no family covers the arm.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._budget import UNLIMITED, Budget
from .._cache import memo
from .._limits import Limits
from .._robot import Robot
from ._answer import (DIRECTION, AnswerOptions, IKAnswer, IKOptions, IKTargets, SolverReport, answer_ik,
                      redundant_family, unreachable_detail)
from ._closed_form import cached_plan, solve_closed_form
from ._goals import PoseGoal
from ._plan import Plan
from ._select import select
from ._table import SolutionTable
from ._types import IKResult, LabelCodes, SingularFlags, Solution
from ._verify import OnePoseVerified


def unlimited(robot: Robot) -> Limits:
    """No bounds on any joint: each solution once, revolute joints in (−π, π]."""
    return Limits(np.full(robot.dof, -np.inf), np.full(robot.dof, np.inf))


def solve_ik(robot: Robot, world_T_target: np.ndarray, *, constrain_orientation: bool = True,
             reference: np.ndarray | None = None, options: IKOptions | None = None) -> IKResult:
    """Every joint vector that places the tool at ``world_T_target``.

    Parameters
    ----------
    world_T_target : ndarray, shape (4, 4)
        The target pose in the world frame. With ``constrain_orientation`` false only its position counts.
    reference : ndarray, shape (n,), optional
        Radians / length units. Orders the solutions nearest first (wrap-aware, largest single joint move) and
        sets joints that are free at a singularity or under an under-determined target.

    Returns
    -------
    IKResult
        Every distinct solution that FK verifies, with branch labels, residuals and the singularities met.
    """
    target = np.asarray(world_T_target, dtype=float)
    if constrain_orientation and reference is None:
        closed = _closed_form_result(robot, target, options or _SEARCH_DEFAULTS)
        if closed is not None:
            return closed
    return solve_ik_batch(robot, target[None], constrain_orientation=constrain_orientation, reference=reference,
                          options=options)[0]


#: The search's bounds and budget where a caller gives none (a value: nothing changes it).
_SEARCH_DEFAULTS = IKOptions()


def _closed_form_result(robot: Robot, target: np.ndarray, options: IKOptions) -> IKResult | None:
    """:func:`solve_ik` of a pose without a reference where the closed form answers it alone: it covers the arm
    and promises every solution. The answer's selection would then list each solution once, as it stands (no
    limits, no order to impose), and word only an unreachable pose: the same record without building the answer.
    None elsewhere (a redundant arm's family, a target the numeric search completes)."""
    if redundant_family(robot):
        return None
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    if plan is None:
        return None
    goal = PoseGoal(target[None])
    verified = solve_closed_form(robot, plan, goal, None, budget=options.budget)
    if not verified.complete[0]:
        return None
    report = memo(robot, ("ik_report", "pose"),
                  lambda: SolverReport("analytic", plan.structure, True, False, tuple(plan.free_joints)))
    if isinstance(verified, OnePoseVerified) and verified.rows.joints:  # the scalar path's rows, on floats
        rows = verified.rows
        joints = np.array(rows.joints)
        joints += 0.0  # the joints as the selection lists them, q + 2π·0 (a −0.0 becomes 0.0)
        solutions = list(map(Solution, joints, rows.branches(), *zip(*rows.residuals)))
        return _result(solutions, "ok", report, verified.singularities[0], None)
    if not verified.count[0]:
        detail = unreachable_detail(robot, goal, 0, verified)
        return _result([], "unreachable", report, verified.singularities[0], detail)
    table = verified.table  # one target: its rows are the table's
    return _result(_solutions(table, table.joints + 0.0), "ok", report, verified.singularities[0], None)


def solve_ik_batch(robot: Robot, world_T_targets: np.ndarray, *, constrain_orientation: bool = True,
                   reference: np.ndarray | None = None, options: IKOptions | None = None) -> list[IKResult]:
    """:func:`solve_ik` for targets of shape (N, 4, 4); the closed forms run vectorised over N."""
    options = options or _SEARCH_DEFAULTS
    targets = IKTargets.poses(np.asarray(world_T_targets, dtype=float), constrain_orientation=constrain_orientation)
    answer = answer_ik(robot, targets, AnswerOptions(reference=reference, limits=unlimited(robot),
                                                     filter_limits=False, search=options, budget=options.budget))
    return results_of(answer)


def results_of(answer: IKAnswer) -> list[IKResult]:
    """Every target of an answer as an :class:`IKResult` record (its kept solutions, in answer order), in one
    pass over the answer's tables."""
    solutions = _solutions(answer.solutions)
    start, stop = answer.solutions.bounds(len(answer))
    reports = answer.singularity_reports
    return [_result(solutions[first:end], status, answer.solvers[solver],
                    [reports[i] for i in answer.singularities[row]], detail)
            for row, (first, end, status, solver, detail) in enumerate(zip(
                start.tolist(), stop.tolist(), answer.status.tolist(), answer.solver.tolist(), answer.detail_list()))]


def result_of(answer: IKAnswer, row: int) -> IKResult:
    """Target ``row`` of an answer as an :class:`IKResult` record (:func:`results_of` of that target alone)."""
    view = answer.target(row)
    return _result(_solutions(view.solutions), view.status, view.solver, view.singularities, view.detail)


def _solutions(table: SolutionTable, joints: np.ndarray | None = None) -> list[Solution]:
    """Every row of a table as a :class:`Solution`, in table order, its joints a row view of the table's (or of
    ``joints`` (S, n), the same rows' values as listed) and its branch a dict of its own."""
    return list(map(Solution, table.joints if joints is None else joints, table.branches(own=True),
                    table.position.tolist(), table.orientation.tolist()))


def _result(solutions: list[Solution], status: str, solver: SolverReport, singularities: list, detail: str | None
            ) -> IKResult:
    """One target's record: its solutions, the answer's status (``ok`` when it has solutions, ``not_found``
    or ``unreachable`` otherwise), its solver, the conditions met and the words."""
    return IKResult(status="ok" if solutions else ("not_found" if status == "not_found" else "unreachable"),
                    solutions=solutions, method=solver.method, structure=solver.structure, complete=solver.complete,
                    singularities=singularities, free_joints=list(solver.free_joints), detail=detail or "",
                    search_exhausted_budget=solver.time_budget_exhausted)


@dataclass(frozen=True)
class IKArrays:
    """Every verified, distinct closed-form solution of a batch of targets, as arrays padded to the most
    solutions of any target (m).

    Attributes
    ----------
    joints : ndarray, shape (N, m, n)
        Radians (revolute joints wrapped to (−π, π]) and length units; row i holds target i's solutions in its
        first ``count[i]`` slots, nearest the reference first when one is given.
    valid : ndarray of bool, shape (N, m)
        ``valid[i, s]`` is ``s < count[i]``.
    count : ndarray of int, shape (N,)
        Solutions per target.
    position, orientation : ndarrays, shape (N, m)
        FK residuals of each solution: length units and radians.
    labels : dict
        Branch labels: name → (values, codes of shape (N, m)).
    singularities : SingularFlags
        The singular conditions each target meets (N rows).
    structure : str
        The kinematic family that solved it.
    free_joints : list of int
        Joints the target does not determine, set to the reference value (or 0).
    complete : ndarray of bool, shape (N,)
        Whether row i's solutions are known to be all of them (see :func:`~._verify.promised`).
    """

    joints: np.ndarray
    valid: np.ndarray
    count: np.ndarray
    position: np.ndarray
    orientation: np.ndarray
    labels: LabelCodes
    singularities: SingularFlags
    structure: str
    free_joints: list[int]
    complete: np.ndarray


def solve_ik_arrays(robot: Robot, world_T_targets: np.ndarray, *, constrain_orientation: bool = True,
                    reference: np.ndarray | None = None, plan: Plan | None = None, threads: int | None = None,
                    budget: Budget = UNLIMITED) -> IKArrays | None:
    """Every closed-form solution of targets (N, 4, 4), vectorised over the targets, as :class:`IKArrays`; None
    when no family covers the arm. Rows the closed form cannot promise say so in ``complete`` (no fallback)."""
    if plan is None:
        plan = cached_plan(robot, constrain_orientation=constrain_orientation, reference=reference)
        if plan is None:
            return None
    goal = PoseGoal(np.asarray(world_T_targets, dtype=float), constrain_orientation)
    verified = solve_closed_form(robot, plan, goal, reference, threads=threads, budget=budget)
    chosen = select(robot, verified.table, len(goal), unlimited(robot), filter_limits=False, reference=reference,
                    budget=budget).solutions
    return _padded(chosen, len(goal), verified.singularities, plan.structure, list(plan.free_joints),
                   verified.complete)


def solve_direction(robot: Robot, positions: np.ndarray, world_directions: np.ndarray, tool_axis: np.ndarray,
                    reference: np.ndarray | None) -> IKArrays:
    """Every solution of N position + tool direction targets (positions (N, 3), world directions (N, 3), the tool
    axis (3,) in the tool frame) as :class:`IKArrays` (orientation residuals are the direction angles). Raises
    :class:`~._answer.UnsupportedTargetError` when no family covers the arm's direction targets."""
    positions = np.asarray(positions, dtype=float)
    n_targets = len(positions)
    matrices = np.broadcast_to(np.eye(4), (n_targets, 4, 4)).copy()
    matrices[:, :3, 3] = positions
    targets = IKTargets(matrices, np.full(n_targets, DIRECTION), np.broadcast_to(tool_axis, (n_targets, 3)),
                        np.asarray(world_directions, dtype=float))
    answer = answer_ik(robot, targets, AnswerOptions(reference=reference, limits=unlimited(robot),
                                                     filter_limits=False))
    singularities = SingularFlags(n_targets)
    for row in range(n_targets):
        for index in answer.singularities[row]:
            mask = np.zeros(n_targets, dtype=bool)
            mask[row] = True
            singularities.add(mask, answer.singularity_reports[index])
    reports = [answer.solvers[i] for i in answer.solver.tolist()]
    return _padded(answer.solutions, n_targets, singularities, reports[0].structure if reports else "",
                   list(reports[0].free_joints) if reports else [],
                   np.array([report.complete for report in reports], dtype=bool))


def _padded(chosen: SolutionTable, n_targets: int, singularities: SingularFlags, structure: str,
            free_joints: list[int], complete: np.ndarray) -> IKArrays:
    """A table's rows as :class:`IKArrays`, each target's in its first slots."""
    count = chosen.counts(n_targets)
    width = max(int(count.max(initial=0)), 1)
    start, _ = chosen.bounds(n_targets)
    index = (chosen.target, np.arange(len(chosen)) - start[chosen.target])

    def padded(column: np.ndarray, fill) -> np.ndarray:
        out = np.full((n_targets, width) + column.shape[1:], fill, dtype=column.dtype)
        out[index] = column
        return out

    return IKArrays(padded(chosen.joints, 0.0), np.arange(width) < count[:, None], count,
                    padded(chosen.position, np.inf), padded(chosen.orientation, np.inf),
                    {name: (values, padded(codes, -1)) for name, (values, codes) in chosen.labels.items()},
                    singularities, structure, free_joints, complete)
