"""From verified solutions to the answer: joint limits, 2π-equivalents, ordering and trimming.

* A solution fits when every joint has a value within its bounds among its
  2π-equivalents (:func:`.._limits.turn_offsets`). Each combination of those
  values is a solution of its own: a ±360° joint doubles most solutions.
* ``filter_limits`` moves solutions that do not fit to ``rejected``. They are
  shown as close to the limits as whole turns bring them
  (:func:`.._limits.closest_equivalent`), so their violations name exactly the
  joints no turn can fix.
* With a reference, solutions come nearest first. Per joint the distance is
  the actual travel |q_i − r_i| (radians or length units), except for a
  continuous joint, whose distance is taken across the 2π wrap; per-joint
  weights multiply it; the total is the largest (``linf``) or the Euclidean
  norm (``l2``). ``max_joint_move`` keeps the solutions whose every joint
  travels at most its bound; ``max_solutions`` the nearest k.
* Without a reference, each solution first appears as it needs the fewest
  turns; the further equivalents follow, one round per solution at a time.
* ``max_equivalents`` caps the list. The equivalents are generated lazily,
  cheapest first, so the cap keeps the nearest (with a reference) or the
  least-turned (without), however many fit.
"""

from __future__ import annotations

import heapq
import itertools
import math
from dataclasses import dataclass, field
from typing import Callable, Iterable, Iterator, Literal

import numpy as np

from .._budget import COUNT_CAP, UNLIMITED, Budget, capped_product, capped_sum
from .._errors import InvalidInputError
from .._limits import (
    Limits,
    Violation,
    closest_equivalent,
    combinations_by_cost,
    turn_counts,
    turn_offsets,
    violations,
)
from .._robot import Robot
from ._types import IKResult, Solution

Norm = Literal["linf", "l2"]

#: Default cap on the number of solutions after 2π expansion.
MAX_EQUIVALENTS = 1024


@dataclass(frozen=True)
class Selected:
    """A solution as answered: its joints (one equivalent), and whether and how it breaks the limits."""

    solution: Solution
    within_limits: bool
    violations: list[Violation]


@dataclass
class Selection:
    """The answer for one target.

    ``available`` counts the solutions that fit (and, with ``filter_limits``
    false, those that do not) after ``max_joint_move``; ``trimmed`` those that
    ``max_joint_move`` and ``max_solutions`` left out; ``expansion_truncated``
    says the ``max_equivalents`` cap left some out.
    """

    status: Literal["ok", "unreachable", "no_solution_within_limits"]
    solutions: list[Selected]
    rejected: list[Selected]
    expansion_truncated: bool = False
    trimmed: int = 0
    available: int = 0
    notes: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class Ordering:
    """How to rank and trim solutions against a reference.

    ``weights`` (shape (n,), ≥ 0) multiply the per-joint distances, which are
    in radians and length units whatever unit the request speaks, so the order
    never depends on the angle unit. ``max_joint_move`` (shape (n,), radians
    or length units, ``inf`` for no bound) bounds each joint's travel
    separately, whatever the norm and the weights.
    """

    norm: Norm = "linf"
    weights: np.ndarray | None = None
    max_solutions: int | None = None
    max_joint_move: np.ndarray | None = None


def joint_travel(robot: Robot, limits: Limits, q: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Per-joint distance of each row of q (shape (..., n)) from the reference, shape (..., n).

    Actual travel |q_i − r_i|, except across the 2π wrap for continuous joints.

    Examples
    --------
    A continuous joint at −3.1 rad is 0.083 rad from a reference at 3.1 rad;
    a ±360° joint at −3.1 rad is 6.2 rad from it (its equivalent 3.18 rad is
    another solution, 0.083 rad away).
    """
    return _travel(np.abs(np.asarray(q, dtype=float) - reference), limits.continuous(robot))


def _travel(difference: np.ndarray, continuous: np.ndarray | bool) -> np.ndarray:
    """|q − r| made wrap-aware where ``continuous``."""
    return np.where(continuous, np.abs(np.pi - np.mod(np.pi - difference, 2.0 * np.pi)), difference)


def travel(robot: Robot, limits: Limits, q: np.ndarray, reference: np.ndarray, ordering: Ordering) -> np.ndarray:
    """Distance of each row of q (shape (k, n)) from the reference under ``ordering``, shape (k,)."""
    distance = joint_travel(robot, limits, q, reference)
    if ordering.weights is not None:
        distance = distance * ordering.weights
    return distance.max(axis=-1) if ordering.norm == "linf" else np.sqrt(np.sum(distance ** 2, axis=-1))


def check_ordering(robot: Robot, ordering: Ordering, reference: np.ndarray | None) -> None:
    """Raise :class:`InvalidInputError` for options that are malformed or need a reference that is missing.

    Locations are the field names of :class:`Ordering` (and ``reference``).
    """
    if reference is None:
        for name in ("max_solutions", "max_joint_move", "weights"):
            if getattr(ordering, name) is not None:
                raise InvalidInputError(f"{name} needs a reference: distances are measured from it",
                                        location=(name,))
    if ordering.norm not in ("linf", "l2"):
        raise InvalidInputError(f"norm must be linf or l2, not {ordering.norm!r}", location=("norm",))
    for name, allow_infinite in (("weights", False), ("max_joint_move", True)):
        values = getattr(ordering, name)
        if values is None:
            continue
        if np.shape(values) != (robot.dof,):
            raise InvalidInputError(f"expected {robot.dof} values of {name}, one per joint, got {np.size(values)}",
                                    location=(name,))
        values = np.asarray(values, dtype=float)
        bad = np.flatnonzero(np.isnan(values) | (values < 0) | (np.isinf(values) & (not allow_infinite)))
        if len(bad):
            raise InvalidInputError(f"{name} must be finite numbers ≥ 0, not {values[bad[0]]}",
                                    location=(name, int(bad[0])))
    if ordering.max_solutions is not None and ordering.max_solutions < 0:
        raise InvalidInputError("max_solutions must be ≥ 0", location=("max_solutions",))


@dataclass
class _Candidate:
    """One IK solution on its way out: the per-joint values it may take, cheapest first, and their costs."""

    index: int
    solution: Solution
    fits: bool
    options: list[np.ndarray]  # at most the values that can be picked: the cheapest few when a joint has many
    costs: list[np.ndarray]
    counts: list[int]  # how many values each joint has in all (≥ len(options[j]))


def select(robot: Robot, result: IKResult, limits: Limits, *, filter_limits: bool = True,
           reference: np.ndarray | None = None, ordering: Ordering = Ordering(),
           max_equivalents: int = MAX_EQUIVALENTS, budget: Budget = UNLIMITED) -> Selection:
    """Apply limits, expand 2π-equivalents, order and trim the solutions of one IK result.

    Parameters
    ----------
    limits : Limits
        The bounds to apply (the robot's, or a request's override).
    filter_limits : bool
        Move solutions that no whole turn brings within the limits to
        ``rejected``; when false they stay among the solutions, flagged.
    reference : ndarray, shape (n,), optional
        Radians / length units. Orders nearest first; required by
        ``ordering.max_solutions``, ``ordering.max_joint_move`` and
        ``ordering.weights``.
    max_equivalents : int
        Most solutions returned after expansion (≥ 1). Only the values that
        can be among them are generated (at most this many per joint); the
        counts (``available``, ``trimmed``) are computed without generating
        the rest and stop at :data:`.._budget.COUNT_CAP`.
    budget : Budget
        Checked between solutions and every few hundred picks.
    """
    check_ordering(robot, ordering, reference)
    if max_equivalents < 1:
        raise InvalidInputError("max_equivalents must be ≥ 1", location=("max_equivalents",))
    if result.status == "unreachable":
        return Selection("unreachable", [], [])
    limit = max_equivalents if ordering.max_solutions is None else min(max_equivalents, ordering.max_solutions)
    all_counts = [turn_counts(robot, limits, solution.joints) for solution in result.solutions]
    # Values each joint may need: with a reference any one solution may give all `limit` answers; without, the
    # answers go round the solutions one at a time, so none gives more than the rounds needed to reach `limit`.
    combinations = [capped_product(counts) if all(counts) else 1 for counts in all_counts
                    if all(counts) or not filter_limits]
    keep = limit if reference is not None else _rounds_needed(combinations, limit)
    candidates, rejected = [], []
    for index, (solution, counts) in enumerate(zip(result.solutions, all_counts)):
        budget.check("selection")
        fits = all(counts)
        if not fits:
            closest = closest_equivalent(robot, limits, solution.joints)
            if filter_limits:
                rejected.append(Selected(_with_joints(solution, closest), False, violations(robot, limits, closest)))
                continue
            options, counts = [np.array([value]) for value in closest], [1] * robot.dof
        else:
            options = turn_offsets(robot, limits, solution.joints, keep=keep, around=reference)
        candidates.append(_costed(robot, limits, index, solution, fits, options, counts, reference, ordering))
    with_all_moves = capped_sum(capped_product(c.counts) for c in candidates)
    if reference is not None and ordering.max_joint_move is not None:
        candidates = [_within_move(robot, limits, c, reference, ordering.max_joint_move) for c in candidates]
    available = capped_sum(capped_product(c.counts) for c in candidates)

    picked = []
    for pick in itertools.islice(_merged(candidates, reference, ordering), limit):
        picked.append(pick)
        if len(picked) % 256 == 0:
            budget.check("selection")
    kept = [_selected(robot, limits, candidates[c], indices) for c, indices in picked]
    capped_by_max_solutions = ordering.max_solutions is not None and ordering.max_solutions <= max_equivalents
    truncated = available > len(kept) and not capped_by_max_solutions
    trimmed = min(with_all_moves - available + (available - len(kept) if capped_by_max_solutions else 0), COUNT_CAP)

    if reference is not None and rejected:
        distance = travel(robot, limits, np.array([e.solution.joints for e in rejected]), reference, ordering)
        rejected = [rejected[i] for i in np.argsort(distance, kind="stable")]
    status = "no_solution_within_limits" if filter_limits and not candidates and rejected else "ok"
    selection = Selection(status, kept, rejected, truncated, trimmed, available)
    selection.notes.extend(_notes(selection, with_all_moves, max_equivalents, reference is not None))
    return selection


def _rounds_needed(combinations: list[int], limit: int) -> int:
    """Rounds of a round robin over streams of these lengths that yield ``limit`` items (all, if fewer), ≥ 1.

    >>> _rounds_needed([1, 1, 1, 10**30], 1024)   # three streams end after round 1: the fourth gives 1,021
    1021
    """
    remaining, previous, streams = limit, 0, len(combinations)
    for position, length in enumerate(sorted(combinations)):
        active = streams - position
        if (length - previous) * active >= remaining:
            return max(1, previous + -(-remaining // active))
        remaining -= (length - previous) * active
        previous = length
    return max(1, previous)


def _costed(robot: Robot, limits: Limits, index: int, solution: Solution, fits: bool, options: list[np.ndarray],
            counts: list[int], reference: np.ndarray | None, ordering: Ordering) -> _Candidate:
    """Sort each joint's options by cost: weighted travel from the reference, or turning from the solution."""
    costs = []
    for j, values in enumerate(options):
        if reference is None:
            cost = np.abs(values - solution.joints[j])
        else:
            cost = _joint_travel(robot, limits, j, values, reference[j])
            if ordering.weights is not None:
                cost = cost * ordering.weights[j]
        order = np.argsort(cost, kind="stable")
        options[j], cost = values[order], cost[order]
        costs.append(cost)
    return _Candidate(index, solution, fits, options, costs, counts)


def _joint_travel(robot: Robot, limits: Limits, joint: int, values: np.ndarray, reference: float) -> np.ndarray:
    """:func:`joint_travel` for the options of one joint, shape (m,)."""
    return _travel(np.abs(values - reference), limits.continuous(robot)[joint])


def _within_move(robot: Robot, limits: Limits, candidate: _Candidate, reference: np.ndarray,
                 max_joint_move: np.ndarray) -> _Candidate:
    """Drop the per-joint options that travel further than the joint's bound (tolerance included).

    A joint whose options were cut to the cheapest few is counted again over the bounds narrowed to
    reference ± bound (its travel is |q − r| there: a joint with both bounds finite is never continuous).
    """
    tolerance = limits.tolerance(robot)
    options, costs, counts = [], [], []
    for j, (values, cost, count) in enumerate(zip(candidate.options, candidate.costs, candidate.counts)):
        near = _joint_travel(robot, limits, j, values, reference[j]) <= max_joint_move[j] + tolerance[j]
        options.append(values[near])
        costs.append(cost[near])
        if count > len(values):
            narrowed = Limits(limits.lower.copy(), limits.upper.copy())
            narrowed.lower[j] = max(limits.lower[j], reference[j] - max_joint_move[j])
            narrowed.upper[j] = min(limits.upper[j], reference[j] + max_joint_move[j])
            count = turn_counts(robot, narrowed, candidate.solution.joints)[j] if narrowed.lower[j] <= \
                narrowed.upper[j] else 0
        else:
            count = int(near.sum())
        counts.append(count)
    return _Candidate(candidate.index, candidate.solution, candidate.fits, options, costs, counts)


def _merged(candidates: list[_Candidate], reference: np.ndarray | None,
            ordering: Ordering) -> Iterator[tuple[int, tuple[int, ...]]]:
    """(candidate position, option indices) in answer order, generated lazily."""
    if reference is None:
        return _round_robin([_stream(c, candidate.costs, math.fsum) for c, candidate in enumerate(candidates)])
    combine: Callable[[list[float]], float] = max if ordering.norm == "linf" else _euclidean
    merged = heapq.merge(*[_stream(c, candidate.costs, combine) for c, candidate in enumerate(candidates)])
    return ((c, indices) for _, c, indices in merged)


def _stream(position: int, costs: list[np.ndarray],
            combine: Callable[[list[float]], float]) -> Iterator[tuple[float, int, tuple[int, ...]]]:
    """One candidate's combinations, cheapest first, tagged with its position: (cost, position, indices)."""
    for cost, indices in combinations_by_cost(costs, combine):
        yield cost, position, indices


def _euclidean(costs: list[float]) -> float:
    return math.sqrt(math.fsum(c * c for c in costs))


def _round_robin(streams: Iterable[Iterator]) -> Iterator[tuple[int, tuple[int, ...]]]:
    """The first item of each stream, then the second of each, and so on: (position, indices)."""
    active = list(streams)
    while active:
        still = []
        for stream in active:
            item = next(stream, None)
            if item is not None:
                yield item[1], item[2]
                still.append(stream)
        active = still


def _selected(robot: Robot, limits: Limits, candidate: _Candidate, indices: tuple[int, ...]) -> Selected:
    q = np.array([candidate.options[j][k] for j, k in enumerate(indices)])
    if candidate.fits:
        return Selected(_with_joints(candidate.solution, q), True, [])
    return Selected(_with_joints(candidate.solution, q), False, violations(robot, limits, q))


def _with_joints(solution: Solution, q: np.ndarray) -> Solution:
    return Solution(q, solution.branch, solution.position_residual, solution.orientation_residual, solution.singular)


def _notes(selection: Selection, with_all_moves: int, max_equivalents: int, has_reference: bool) -> list[str]:
    notes = []
    if selection.status == "no_solution_within_limits":
        notes.append(f"All {len(selection.rejected)} solutions violate a joint limit, whatever whole turns the "
                     f"revolute joints make; they are listed in 'rejected'.")
    outside = sum(not e.within_limits for e in selection.solutions)
    if outside:
        notes.append(f"{outside} of the solutions violate a joint limit (filter_limits is false); "
                     f"each is flagged with its violations.")
    if selection.expansion_truncated:
        which = "nearest" if has_reference else "least-turned"
        fit = (f"At least {COUNT_CAP} (2**53 − 1, the count's cap)" if selection.available >= COUNT_CAP
               else f"{selection.available}")
        notes.append(f"{fit} solutions fit; max_equivalents = {max_equivalents} kept the "
                     f"{which} {len(selection.solutions)}.")
    if selection.status == "ok" and not selection.solutions and with_all_moves:
        notes.append(f"{with_all_moves} solutions fit the limits, but none is within max_joint_move / "
                     f"max_solutions of the reference.")
    return notes
