"""Inverse kinematics: plan, solve, verify by FK, merge, label and order."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._robot import Robot
from ._numeric import NumericOptions, solve_numeric
from ._plan import geometry_of, plan_for
from ._types import IKResult, Solution
from .._tolerances import ACCEPT_RESIDUAL, POLISH_RESIDUAL
from ._verify import accepted, distance_to_reference, distinct, polish, residuals, wrap_revolute


@dataclass(frozen=True)
class IKOptions:
    """How to search: the numeric fallback's bounds."""

    numeric: NumericOptions = field(default_factory=NumericOptions)


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
    return solve_ik_batch(robot, np.asarray(world_T_target)[None], constrain_orientation=constrain_orientation,
                          reference=reference, options=options)[0]


def solve_ik_batch(robot: Robot, world_T_targets: np.ndarray, *, constrain_orientation: bool = True,
                   reference: np.ndarray | None = None, options: IKOptions | None = None) -> list[IKResult]:
    """:func:`solve_ik` for targets of shape (N, 4, 4); the analytic families run vectorised over N."""
    options = options or IKOptions()
    targets = np.asarray(world_T_targets, dtype=float)
    plan = plan_for(robot, constrain_orientation=constrain_orientation, reference=reference)
    if plan is None:
        return [_numeric(robot, target, constrain_orientation, reference, options) for target in targets]
    candidates = plan.solve(targets, reference)
    n_targets, m, n = candidates.joints.shape
    joints = wrap_revolute(robot, np.nan_to_num(candidates.joints.reshape(-1, n)))
    repeated_targets = np.repeat(targets, m, axis=0)
    position, orientation = residuals(robot, joints, repeated_targets)
    joints, position, orientation = _polished(robot, joints, repeated_targets, position, orientation,
                                              candidates.valid.reshape(-1), constrain_orientation)
    position, orientation = position.reshape(n_targets, m), orientation.reshape(n_targets, m)
    ok = candidates.valid & accepted(robot, position, orientation, constrain_orientation)
    joints = joints.reshape(n_targets, m, n)
    results = []
    for row in range(n_targets):
        slots = np.flatnonzero(ok[row])
        kept = slots[distinct(robot, joints[row, slots])] if len(slots) else slots
        labels = plan.labels(joints[row, kept]) if len(kept) else []
        solutions = [Solution(joints[row, s], label, float(position[row, s]), float(orientation[row, s]))
                     for s, label in zip(kept, labels)]
        detail = "" if solutions else _unreachable_detail(robot, targets[row], constrain_orientation, reference,
                                                          plan.free_joints)
        results.append(IKResult(
            status="ok" if solutions else "unreachable",
            solutions=_ordered(robot, solutions, reference),
            method="analytic", structure=plan.structure, complete=True,
            singularities=candidates.singularities[row] if solutions else [],
            free_joints=list(plan.free_joints), detail=detail))
    return results


def _polished(robot: Robot, joints: np.ndarray, targets: np.ndarray, position: np.ndarray, orientation: np.ndarray,
              valid: np.ndarray, constrain_orientation: bool):
    """Refine the candidates that are close to the target but not within the acceptance tolerance."""
    scale = robot.characteristic_length
    size = np.maximum(position / scale, orientation if constrain_orientation else 0.0)
    near = valid & (size > ACCEPT_RESIDUAL * 1e-3) & (size <= POLISH_RESIDUAL)
    if near.any():
        joints = joints.copy()
        joints[near] = wrap_revolute(robot, polish(robot, joints[near], targets[near], constrain_orientation))
        position, orientation = position.copy(), orientation.copy()
        position[near], orientation[near] = residuals(robot, joints[near], targets[near])
    return joints, position, orientation


def _unreachable_detail(robot: Robot, target: np.ndarray, constrain_orientation: bool,
                        reference: np.ndarray | None, free_joints: list[int] = ()) -> str:
    """Say whether the position or only the orientation is out of reach (or only with the free joints held)."""
    if free_joints and not constrain_orientation:
        names = ", ".join(f"q{i + 1}" for i in free_joints)
        return (f"The target position is out of reach with the free joints {names} held at the reference values "
                f"(or 0); other values of those joints may reach it.")
    if constrain_orientation:
        position_only = solve_ik_batch(robot, target[None], constrain_orientation=False, reference=reference)[0]
        if position_only.solutions:
            return ("The position is reachable but the orientation is not: " + _orientation_freedom(robot) +
                    " No joint vector gives the requested orientation at that position.")
    return "The target position is outside the workspace."


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
             options: IKOptions) -> IKResult:
    outcome = solve_numeric(robot, target, constrain_orientation=constrain_orientation, options=options.numeric,
                            reference=reference)
    joints = wrap_revolute(robot, outcome.joints)
    solutions: list[Solution] = []
    if len(joints):
        targets = np.broadcast_to(target, (len(joints), 4, 4))
        joints = wrap_revolute(robot, polish(robot, joints, targets, constrain_orientation))
        position, orientation = residuals(robot, joints, target)
        ok = np.flatnonzero(accepted(robot, position, orientation, constrain_orientation))
        kept = ok[distinct(robot, joints[ok])] if len(ok) else ok
        solutions = [Solution(joints[i], {}, float(position[i]), float(orientation[i])) for i in kept]
    detail = "" if solutions else (
        "No solution was found by the numeric search; the target may be outside the workspace "
        "(the numeric search cannot prove it).")
    if outcome.budget_exhausted:
        detail = (detail + " " if detail else "") + "The time budget stopped the search before every start converged."
    return IKResult(status="ok" if solutions else "unreachable", solutions=_ordered(robot, solutions, reference),
                    method="numeric", structure="general", complete=False, detail=detail,
                    search_exhausted_budget=outcome.budget_exhausted)
