"""Numeric fallback: damped least squares (Levenberg–Marquardt) from many starts.

Used for structures no analytic family covers. It cannot promise that every
solution was found (``complete`` is false), so it is bounded: a number of
starts and an iteration cap, each configurable. The budget is counted in
iterations, never read off a clock, so the answer is the same under any load;
the request's :class:`.._budget.Budget` (its deadline, a cancellation) is
checked between iterations and stops the search with
:class:`.._budget.BudgetExhausted` rather than with a partial answer. All
starts run together as one batch: each iteration is one batched FK and one
batched Jacobian.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._budget import UNLIMITED, Budget
from .._forward import forward_kinematics, geometric_jacobian
from .._robot import Robot


@dataclass(frozen=True)
class NumericOptions:
    """Bounds on the numeric search."""

    starts: int = 48
    max_iterations: int = 200
    seed: int = 0


@dataclass(frozen=True)
class NumericOutcome:
    joints: np.ndarray  # (k, n) converged joint vectors (not yet deduplicated or verified)
    budget_exhausted: bool  # the iteration cap stopped some starts before they converged or gave up
    iterations: int


def pose_error(world_T_tool: np.ndarray, world_T_target: np.ndarray, length_scale: float) -> np.ndarray:
    """Twist-like error from the current tool pose to the target, shape (..., 6).

    Rows 0–2: position error divided by ``length_scale``; rows 3–5: rotation
    error ``½ Σ_i r_i × r*_i`` (columns of the current and target rotations),
    which is sin(angle)·axis near the solution.
    """
    position = (world_T_target[..., :3, 3] - world_T_tool[..., :3, 3]) / length_scale
    rotation = 0.5 * np.sum(np.cross(world_T_tool[..., :3, :3], world_T_target[..., :3, :3], axis=-2), axis=-1)
    return np.concatenate([position, rotation], axis=-1)


def initial_guesses(robot: Robot, count: int, rng: np.random.Generator, reference: np.ndarray | None) -> np.ndarray:
    """Spread starts over the joint ranges (±π, or ±scale for unlimited prismatic joints), shape (count, n)."""
    scale = robot.characteristic_length
    default_lower = np.where(robot.is_revolute, -np.pi, -scale)
    default_upper = np.where(robot.is_revolute, np.pi, scale)
    lower = np.where(np.isfinite(robot.lower), np.maximum(robot.lower, default_lower - 2 * np.pi), default_lower)
    upper = np.where(np.isfinite(robot.upper), np.minimum(robot.upper, default_upper + 2 * np.pi), default_upper)
    # A joint whose whole range lies outside that window (e.g. limits [10, 10] rad) gets one window's width of
    # its own range instead; without this, upper < lower and the draw fails.
    empty = upper < lower
    if empty.any():
        width = default_upper - default_lower
        own_lower = np.where(np.isfinite(robot.lower), robot.lower, robot.upper - width)
        lower = np.where(empty, own_lower, lower)
        upper = np.where(empty, np.minimum(own_lower + width, robot.upper), upper)
    starts = rng.uniform(lower, upper, (count, robot.dof))
    starts[0] = np.clip(0.0, lower, upper)
    if reference is not None and count > 1:
        starts[1] = reference
    return starts


def solve_numeric(
    robot: Robot,
    world_T_target: np.ndarray,
    *,
    constrain_orientation: bool,
    options: NumericOptions,
    reference: np.ndarray | None = None,
    accept: float = 1e-20,
    budget: Budget = UNLIMITED,
) -> NumericOutcome:
    """Run Levenberg–Marquardt from ``options.starts`` starts at once.

    Parameters
    ----------
    world_T_target : ndarray, shape (4, 4)
    constrain_orientation : bool
        False for position-only targets: only the three position rows are solved.
    accept : float
        Squared-error threshold (normalised units) at which a start has converged.
    """
    rng = np.random.default_rng(options.seed)
    scale = robot.characteristic_length
    rows = slice(0, 6) if constrain_orientation else slice(0, 3)
    q = initial_guesses(robot, options.starts, rng, reference)
    damping = np.full(len(q), 1e-3)

    def residual(joints: np.ndarray) -> np.ndarray:
        return pose_error(forward_kinematics(robot, joints), world_T_target, scale)[:, rows]

    error = residual(q)
    cost = np.einsum("si,si->s", error, error)
    active = cost > accept
    iterations = 0
    while active.any() and iterations < options.max_iterations:
        budget.check("the numeric search")
        iterations += 1
        J = geometric_jacobian(robot, q[active])
        J[:, :3, :] /= scale
        J = J[:, rows, :]
        JtJ = np.einsum("sij,sik->sjk", J, J)
        gradient = np.einsum("sij,si->sj", J, error[active])
        # Levenberg–Marquardt: damp the diagonal, scaled by the size of JᵀJ.
        diagonal = np.arange(robot.dof)
        JtJ[:, diagonal, diagonal] += (damping[active] * np.maximum(1.0, np.trace(JtJ, axis1=1, axis2=2)))[:, None]
        with np.errstate(over="ignore", invalid="ignore"):
            step = np.linalg.solve(JtJ, gradient[..., None])[..., 0]
            trial = q[active] + step
            trial_error = residual(trial)
            trial_cost = np.einsum("si,si->s", trial_error, trial_error)
        improved = np.isfinite(trial_cost) & (trial_cost < cost[active])  # an overflowing step is a failed step
        indices = np.flatnonzero(active)
        better = indices[improved]
        q[better] = trial[improved]
        error[better] = trial_error[improved]
        cost[better] = trial_cost[improved]
        damping[better] = np.maximum(damping[better] * 0.3, 1e-12)
        worse = indices[~improved]
        damping[worse] = damping[worse] * 10.0
        active = (cost > accept) & (damping < 1e8)
    converged = cost <= 1e-10  # polished and FK-checked by the caller
    budget_exhausted = bool(active.any())  # starts still improving when the iterations ran out
    return NumericOutcome(q[converged], budget_exhausted, iterations)
