"""Inverse kinematics: plan, solve, verify by FK, merge, label and order."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._budget import UNLIMITED, Budget
from .._robot import Robot
from ._numeric import NumericOptions, solve_numeric
from ._arrays import IKArrays, OnePoseAnswer, cached_plan, solve_ik_arrays, solve_one_pose
from ._coaxial import coaxial_pair, coaxial_report, held_split
from ._plan import geometry_of
from ._types import IKResult, Solution
from ._verify import accepted, distance_to_reference, first_of_each, polish, residuals, wrap_revolute


@dataclass(frozen=True)
class IKOptions:
    """How to search: the numeric fallback's bounds, and the request's budget (deadline, cancellation)."""

    numeric: NumericOptions = field(default_factory=NumericOptions)
    budget: Budget = UNLIMITED


def solve_ik(robot: Robot, world_T_target: np.ndarray, *, constrain_orientation: bool = True,
             reference: np.ndarray | None = None, options: IKOptions | None = None) -> IKResult:
    """Every joint vector that places the tool at ``world_T_target``.

    Parameters
    ----------
    world_T_target : ndarray, shape (4, 4)
        The target pose in the world frame. With ``constrain_orientation``
        false only its position counts.
    reference : ndarray, shape (n,), optional
        Radians / length units. Orders the solutions nearest first (wrap-aware,
        largest single joint move) and sets joints that are free at a
        singularity or under an under-determined target.

    Returns
    -------
    IKResult
        Every distinct solution that FK verifies, with branch labels, residuals
        and the singularities met.
    """
    target = np.asarray(world_T_target, dtype=float)
    if constrain_orientation:  # the families with a scalar path for one pose solve pose targets
        plan = cached_plan(robot, constrain_orientation=True, reference=None)
        if plan is not None:
            (options or _DEFAULT_OPTIONS).budget.check("the analytic solve")
            answer = solve_one_pose(robot, target, True, reference, plan)
            if answer is not None and answer.count:  # (an unreachable target takes the path that says why)
                return _one_pose_result(answer)
    return solve_ik_batch(robot, target[None], constrain_orientation=constrain_orientation,
                          reference=reference, options=options)[0]


_DEFAULT_OPTIONS = IKOptions()


def _one_pose_result(answer: OnePoseAnswer) -> IKResult:
    """:func:`results_from_arrays` of a :class:`OnePoseAnswer` with solutions, read from its lists."""
    joints = np.array(answer.rows[:answer.count])
    labels = list(zip(answer.names, answer.values, answer.codes))
    solutions = [Solution(joints[s], {name: values[codes[s]] for name, values, codes in labels if codes[s] >= 0},
                          answer.position[s], answer.orientation[s]) for s in range(answer.count)]
    plan = answer.plan
    return IKResult(status="ok", solutions=solutions, method="analytic", structure=plan.structure, complete=True,
                    singularities=answer.singularities[0], free_joints=list(plan.free_joints))


def solve_ik_batch(robot: Robot, world_T_targets: np.ndarray, *, constrain_orientation: bool = True,
                   reference: np.ndarray | None = None, options: IKOptions | None = None) -> list[IKResult]:
    """:func:`solve_ik` for targets of shape (N, 4, 4); the analytic families run vectorised over N.

    The work is :func:`solve_ik_arrays`; this only turns its rows into records.
    """
    options = options or _DEFAULT_OPTIONS
    targets = np.asarray(world_T_targets, dtype=float)
    arrays = solve_ik_arrays(robot, targets, constrain_orientation=constrain_orientation, reference=reference,
                             budget=options.budget)
    if arrays is None:
        return [_numeric(robot, target, constrain_orientation, reference, options) for target in targets]
    return results_from_arrays(robot, arrays, targets, constrain_orientation, reference, options)


#: The solver for any 6R arm, for the targets where a closed form on rounded geometry cannot promise every
#: solution (see :mod:`._idealised`): a callable ``(robot, world_T_target, constrain_orientation, reference, known)
#: -> IKResult | None``, None when it does not apply. Until the general solver is plugged in here, the numeric
#: search answers those targets with ``complete: false``.
GENERAL_SOLVER = None


def results_from_arrays(robot: Robot, arrays: IKArrays, targets: np.ndarray, constrain_orientation: bool,
                        reference: np.ndarray | None, options: IKOptions | None = None) -> list[IKResult]:
    """One :class:`IKResult` per row of :func:`solve_ik_arrays`' answer.

    Rows the closed form could not promise complete (:attr:`IKArrays.complete`: rounded geometry, or a singular
    condition it met, see ``_promised`` in :mod:`._arrays`) are answered by the fallback, keeping the closed
    form's verified solutions (:func:`_incomplete_row`) and reporting the conditions it met.
    """
    results = _closed_form_results(robot, arrays, targets, constrain_orientation, reference)
    for row in np.flatnonzero(~arrays.complete).tolist():
        known = arrays.joints[row, :arrays.count[row]]
        results[row] = _incomplete_row(robot, targets[row], known, arrays.structure, constrain_orientation,
                                       reference, options or IKOptions())
        # the conditions the closed form met there are why it could not promise the answer: they are reported
        met = results[row].singularities
        met.extend(flag for flag in arrays.singularities[row] if flag not in met)
    return results


def _incomplete_row(robot: Robot, target: np.ndarray, known: np.ndarray, structure: str,
                    constrain_orientation: bool, reference: np.ndarray | None, options: IKOptions) -> IKResult:
    """The general solver's answer (when plugged in), else the numeric search's, merged with ``known`` (k, n)."""
    if GENERAL_SOLVER is not None:
        answer = GENERAL_SOLVER(robot, target, constrain_orientation, reference, known)
        if answer is not None:
            return answer
    result = _numeric(robot, target, constrain_orientation, reference, options, seeds=known)
    if structure == "general_6r":
        note = ("The general 6R solver cannot promise every solution for this target (an ill-conditioned "
                "eigenproblem or a near-double root), so the numeric search completed its answer.")
    else:
        note = (f"The arm is within rounding of the {structure} family but not exactly of it; its closed form, "
                f"refined on the arm as given, cannot promise every solution for this target (a pair of solutions "
                f"may appear or vanish between the two), so the numeric search completed it.")
    result.detail = f"{note} {result.detail}".strip() if result.detail else note
    return result


def _closed_form_results(robot: Robot, arrays: IKArrays, targets: np.ndarray, constrain_orientation: bool,
                         reference: np.ndarray | None) -> list[IKResult]:
    counts = arrays.count.tolist()
    details = unreachable_details(robot, arrays, targets, constrain_orientation, reference) if 0 in counts else {}
    joints, position, orientation = arrays.joints, arrays.position.tolist(), arrays.orientation.tolist()
    labels = [(name, values, codes.tolist()) for name, (values, codes) in arrays.labels.items()]
    free_joints = arrays.free_joints
    complete = arrays.complete.tolist()
    results = []
    for row, count in enumerate(counts):
        if count:
            solutions = [Solution(joints[row, s], {name: values[codes[row][s]] for name, values, codes in labels
                                                   if codes[row][s] >= 0},
                                  position[row][s], orientation[row][s]) for s in range(count)]
            results.append(IKResult(status="ok", solutions=solutions, method="analytic",
                                    structure=arrays.structure, complete=complete[row],
                                    singularities=arrays.singularities[row], free_joints=list(free_joints)))
        else:
            results.append(IKResult(status="unreachable", solutions=[], method="analytic",
                                    structure=arrays.structure, complete=complete[row], singularities=[],
                                    free_joints=list(free_joints), detail=details[row]))
    return results


def unreachable_details(robot: Robot, arrays: IKArrays, targets: np.ndarray, constrain_orientation: bool,
                         reference: np.ndarray | None, budget: Budget = UNLIMITED) -> dict[int, str]:
    """For each unreachable target: whether the position or only the orientation is out of reach (or only with
    the free joints held)."""
    rows = np.flatnonzero(arrays.count == 0)
    details = {int(row): "The target position is outside the workspace." for row in rows}
    if arrays.free_joints and not constrain_orientation:
        names = ", ".join(f"q{i + 1}" for i in arrays.free_joints)
        return {int(row): (f"The target position is out of reach with the free joints {names} held at the reference "
                           f"values (or 0); other values of those joints may reach it.") for row in rows}
    if constrain_orientation and len(rows):
        position_only = solve_ik_arrays(robot, targets[rows], constrain_orientation=False, reference=reference,
                                        budget=budget)
        if position_only is not None:
            reachable = position_only.count > 0
        else:  # no analytic family for the position alone: the numeric search decides, as for any target
            reachable = np.array([bool(result.solutions) for result in solve_ik_batch(
                robot, targets[rows], constrain_orientation=False, reference=reference,
                options=IKOptions(budget=budget))])
        if reachable.any():
            for row in rows[reachable]:
                details[int(row)] = ("The position is reachable but the orientation is not: " +
                                     _orientation_freedom(robot) +
                                     " No joint vector gives the requested orientation at that position.")
    for row in rows[~arrays.complete[rows]]:  # the general 6R solver could not vouch for this answer
        details[int(row)] = ("No solution was found, but the solver cannot promise that none exists: the target "
                             "is near a singular or ill-conditioned case of the elimination (complete: false).")
    return details


def _orientation_freedom(robot: Robot) -> str:
    """What orientations an arm with fewer than six joints can give the tool, in words."""
    geometry = geometry_of(robot)
    revolute = [i for i in range(robot.dof) if robot.is_revolute[i]]
    if revolute and all(geometry.parallel(revolute[0], i) for i in revolute):
        axis = np.round(geometry.direction(revolute[0]), 6).tolist()
        return (f"every revolute axis of this arm is parallel to {axis} (world frame), so the tool can only turn "
                f"about that direction from its home orientation (for a SCARA, Spong eq. 4.56).")
    return f"an arm with {robot.dof} joints cannot set every orientation independently of the position."


def _ordered(robot: Robot, solutions: list[Solution], reference: np.ndarray | None) -> list[Solution]:
    if reference is None or not solutions:
        return solutions
    distances = distance_to_reference(robot, np.array([s.joints for s in solutions]), reference)
    return [solutions[i] for i in np.argsort(distances, kind="stable")]


def _numeric(robot: Robot, target: np.ndarray, constrain_orientation: bool, reference: np.ndarray | None,
             options: IKOptions, seeds: np.ndarray | None = None) -> IKResult:
    """The numeric search's answer; ``seeds`` (k, n), solutions already verified, are kept among it."""
    outcome = solve_numeric(robot, target, constrain_orientation=constrain_orientation, options=options.numeric,
                            reference=reference, budget=options.budget)
    joints = wrap_revolute(robot, outcome.joints)
    if seeds is not None and len(seeds):
        joints = np.concatenate([seeds, joints.reshape(-1, robot.dof)])
    solutions: list[Solution] = []
    coaxial = coaxial_pair(geometry_of(robot))
    if len(joints):
        targets = np.broadcast_to(target, (len(joints), 4, 4))
        joints = wrap_revolute(robot, polish(robot, joints, targets, constrain_orientation))
        if coaxial is not None:  # one representative per sum (difference) of the coaxial pair: see _coaxial
            joints = wrap_revolute(robot, held_split(joints, coaxial, reference))
        position, orientation = residuals(robot, joints, target)
        ok = np.flatnonzero(accepted(robot, position, orientation, constrain_orientation))
        options.budget.check("polishing the numeric solutions")
        kept = ok[first_of_each(robot, joints[ok][None], np.ones((1, len(ok)), dtype=bool))[0]]
        solutions = [Solution(joints[i], {}, float(position[i]), float(orientation[i])) for i in kept]
    detail = "" if solutions else (
        "No solution was found by the numeric search; the target may be outside the workspace "
        "(the numeric search cannot prove it).")
    if outcome.budget_exhausted:
        detail = (detail + " " if detail else "") + (
            f"The iteration cap ({options.numeric.max_iterations}) stopped some starts before they converged.")
    return IKResult(status="ok" if solutions else "unreachable", solutions=_ordered(robot, solutions, reference),
                    method="numeric", structure="general", complete=False, detail=detail,
                    singularities=[coaxial_report(coaxial)] if coaxial is not None and solutions else [],
                    free_joints=[coaxial[1]] if coaxial is not None else [],
                    search_exhausted_budget=outcome.budget_exhausted)
