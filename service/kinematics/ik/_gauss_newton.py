"""The one damped Gauss–Newton loop of the core: polishing closed-form candidates, refining an idealised family's
solutions on the true arm, following a redundant arm's branch, and the numeric search.

Each step solves the damped least-squares problem for the goal's normalised error e and Jacobian J
(:mod:`._goals`), K rows at once:

    Δq = Jᵀ (J Jᵀ + μ I)⁻¹ e,

the minimum-norm step when J is wide (a redundant arm, a position target) and the Levenberg–Marquardt step
(JᵀJ + μI)⁻¹ Jᵀ e in every case (the two are equal). The system is r × r (r = 3 or 6 rows), whatever the
number of joints.

* **Newton** (``adaptive`` false): μ stays at :data:`NEWTON_DAMPING` and every step that does not raise the error
  is taken; a row stops when its error is below ``tolerance``, when a step would raise it (the row stays where
  it was: near a singularity a Newton step along the near-singular direction can throw a candidate 1e-7 off its
  target 1e-3 off), or (``contraction`` given) when a step shrinks it by less than that factor: off the
  branch's reach, Newton's quadratic convergence is lost.
* **Levenberg–Marquardt** (``adaptive`` true): μ = λ · max(1, tr J Jᵀ); a step is taken only if it lowers ‖e‖²;
  λ is divided by 3.3 after a success and multiplied by 10 after a failure, and a row stops below ``tolerance``
  or once λ passes :data:`GIVE_UP_DAMPING`.

Only the joints of ``moving`` move (all when None): a redundant arm's free joint stays at its value.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._budget import UNLIMITED, Budget
from .._linear import solve_each
from .._robot import Robot
from ._goals import Goal

#: λ of a Newton step: a regulariser against an exactly singular J Jᵀ, far below any real curvature.
NEWTON_DAMPING = 1e-12
#: λ of the first Levenberg–Marquardt step, and the range it moves in.
START_DAMPING = 1e-3
LEAST_DAMPING = 1e-12
GIVE_UP_DAMPING = 1e8


@dataclass(frozen=True)
class Refined:
    """What the loop reached: joint vectors (K, n), each row's final error size ‖e‖∞ (K,), and which rows were
    still improving when the step count ran out (K,)."""

    joints: np.ndarray
    error: np.ndarray
    unfinished: np.ndarray


def gauss_newton(robot: Robot, goal: Goal, q: np.ndarray, rows: np.ndarray, *, steps: int, tolerance: float,
                 adaptive: bool = False, contraction: float | None = None, moving: np.ndarray | None = None,
                 budget: Budget = UNLIMITED, stage: str = "refinement") -> Refined:
    """Damped Gauss–Newton from joint vectors q (K, n) towards the goal's targets ``rows`` (K,) (see the module
    docstring). ``budget`` is checked before every step."""
    q = np.array(q, dtype=float)
    rows = np.asarray(rows)
    error = goal.error(robot, q, rows)
    size = np.abs(error).max(axis=1, initial=0.0)
    cost = np.einsum("ki,ki->k", error, error)
    damping = np.full(len(q), START_DAMPING if adaptive else NEWTON_DAMPING)
    active = size > tolerance
    columns = np.arange(robot.dof) if moving is None else np.flatnonzero(moving)
    step_count = 0
    while active.any() and step_count < steps:
        budget.check(stage)
        step_count += 1
        index = np.flatnonzero(active)
        J = goal.jacobian(robot, q[index], rows[index])[..., columns]
        JJt = J @ np.swapaxes(J, -1, -2)
        mu = damping[index] * np.maximum(1.0, np.trace(JJt, axis1=-2, axis2=-1)) if adaptive else damping[index]
        JJt[:, np.arange(JJt.shape[1]), np.arange(JJt.shape[1])] += mu[:, None]
        with np.errstate(all="ignore"):
            solved = solve_each(JJt, error[index][..., None])[..., 0]
            trial = q[index]
            trial[:, columns] += np.einsum("kji,kj->ki", J, solved)
            trial_error = goal.error(robot, trial, rows[index])
        trial_size = np.abs(trial_error).max(axis=1)
        trial_cost = np.einsum("ki,ki->k", trial_error, trial_error)
        if adaptive:  # Levenberg–Marquardt: keep a step only if it lowers the cost (an overflow is a failure)
            taken = np.isfinite(trial_cost) & (trial_cost < cost[index])
            damping[index] = np.where(taken, np.maximum(damping[index] * 0.3, LEAST_DAMPING), damping[index] * 10.0)
        else:  # Newton: a step that raises the error has left the root's reach; the row stops before it
            taken = np.isfinite(trial_cost) & (trial_size <= size[index])
        better = index[taken]
        previous = size[better]
        q[better], error[better] = trial[taken], trial_error[taken]
        size[better], cost[better] = trial_size[taken], trial_cost[taken]
        active[index] = size[index] > tolerance
        if adaptive:
            active[index] &= damping[index] < GIVE_UP_DAMPING
        elif contraction is not None:
            active[better] &= size[better] < contraction * previous
        if not adaptive:
            active[index[~taken]] = False
    return Refined(q, size, active)
