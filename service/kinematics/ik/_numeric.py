"""The numeric search: Levenberg–Marquardt from many starts, for targets no closed form covers or promises.

It cannot promise that every solution was found (its candidates say ``complete`` false), so it is bounded: a
number of starts and an iteration cap, each configurable. The budget is counted in iterations, never read off a
clock, so the answer is the same under any load; the request's :class:`.._budget.Budget` (its deadline, a
cancellation) is checked between iterations and stops the search with :class:`.._budget.BudgetExhausted` rather
than with a partial answer. The starts of a batch run together, in chunks of at most :func:`chunk_rows` joint
vectors, so that memory is bounded whatever the number of starts, targets and joints.

The search returns :class:`~._types.Candidates` like every family: the converged starts (and the solutions a
caller already knows, first), for :func:`~._verify.verify` to check, merge and label.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._budget import UNLIMITED, Budget
from .._robot import Robot
from ._coaxial import coaxial_pair, coaxial_report, held_split
from ._gauss_newton import gauss_newton
from ._goals import Goal
from ._plan import geometry_of
from ._structure import arm_size
from ._types import Candidates, SingularFlags

#: The normalised error (‖e‖∞, lengths in arm sizes) at which a start has converged; it is then polished and
#: checked by FK like any candidate (:func:`~._verify.verify`).
CONVERGED = 1e-10
#: A start whose error stays above this when the search stops is not a candidate.
CANDIDATE = 1e-5
#: Bytes of working arrays one chunk of the search may use: Jacobians, the chain's frames and their temporaries,
#: about :data:`_FLOATS_PER_JOINT` floats per joint of each joint vector.
WORK_BYTES = 64 << 20
_FLOATS_PER_JOINT = 96


@dataclass(frozen=True)
class NumericOptions:
    """Bounds on the numeric search: starts per target, Levenberg–Marquardt iterations per start, and the seed of
    the starts (the same starts for every target)."""

    starts: int = 48
    max_iterations: int = 200
    seed: int = 0


def chunk_rows(dof: int) -> int:
    """How many joint vectors one chunk of the search iterates at once for an arm of ``dof`` joints."""
    return max(64, WORK_BYTES // (8 * _FLOATS_PER_JOINT * max(dof, 1)))


def initial_guesses(robot: Robot, count: int, rng: np.random.Generator, reference: np.ndarray | None) -> np.ndarray:
    """Starts spread over the joint ranges (±π, or ±size for unlimited prismatic joints), shape (count, n): the
    first at 0 (clipped into the limits), the second at the reference when there is one."""
    scale = arm_size(robot)
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
    starts[:1] = np.clip(0.0, lower, upper)  # none when count is 0
    if reference is not None and count > 1:
        starts[1] = reference
    return starts


@dataclass(frozen=True)
class Searched:
    """The search's candidates for N targets, and which targets' searches the iteration cap stopped before every
    start had converged or given up (N,)."""

    candidates: Candidates
    unfinished: np.ndarray


def search(robot: Robot, goal: Goal, options: NumericOptions, reference: np.ndarray | None, *,
           known: np.ndarray | None = None, seeds: np.ndarray | None = None, held: dict[int, float] | None = None,
           budget: Budget = UNLIMITED) -> Searched:
    """Levenberg–Marquardt from ``options.starts`` starts per target of ``goal`` (N targets), and from its own
    ``seeds``.

    ``known`` (N, k, n), NaN-padded, are solutions a caller already verified; they head each target's candidates.
    ``seeds`` (N, s, n), NaN-padded, are starts of each target's own (a closed form's candidates where it could
    not promise the target: near a fold the roots it missed lie beside them, where the common starts seldom
    lead); their candidates follow the common starts'. ``held`` joints stay at their values (the free joints of a
    redundant arm a request fixed). On an arm with two coaxial joints, each candidate is split with the second at
    the reference (or 0), as the closed form splits it (:mod:`._coaxial`).
    """
    n_targets, n = len(goal), robot.dof
    common = initial_guesses(robot, options.starts, np.random.default_rng(options.seed), reference)
    own = 0 if seeds is None else seeds.shape[1]
    per_target = len(common) + own  # each target's starts: the common ones, then its seeds
    moving = None
    if held:
        moving = np.ones(n, dtype=bool)
        moving[list(held)] = False
    total = n_targets * per_target
    joints = np.empty((total, n))
    error = np.empty(total)
    unfinished = np.zeros(n_targets, dtype=bool)
    chunk = chunk_rows(n)
    for begin in range(0, total, chunk):
        index = np.arange(begin, min(begin + chunk, total))
        rows, slots = np.divmod(index, per_target)
        seeded = slots >= len(common)
        starts = np.empty((len(index), n))
        starts[~seeded] = common[slots[~seeded]]
        if own:
            starts[seeded] = seeds[rows[seeded], slots[seeded] - len(common)]  # not finite: never active
        if held:
            starts[:, list(held)] = list(held.values())
        reached = gauss_newton(robot, goal, starts, rows, steps=options.max_iterations, tolerance=CONVERGED,
                               adaptive=True, moving=moving, budget=budget, stage="the numeric search")
        joints[index], error[index] = reached.joints, reached.error
        unfinished[rows[reached.unfinished]] = True
    joints = joints.reshape(n_targets, per_target, n)
    valid = (error <= CANDIDATE).reshape(n_targets, per_target)
    pair = coaxial_pair(geometry_of(robot))
    if pair is not None:
        joints = held_split(joints, pair, reference)
    singularities = SingularFlags(n_targets)
    if pair is not None:
        singularities.add(valid.any(axis=1), coaxial_report(pair))
    if known is not None and known.shape[1]:
        joints = np.concatenate([np.nan_to_num(known), joints], axis=1)
        valid = np.concatenate([~np.isnan(known).any(axis=-1), valid], axis=1)
    return Searched(Candidates(joints, valid, singularities, complete=np.zeros(n_targets, dtype=bool)), unfinished)
