"""From verified solutions to the answer: joint limits, 2π-equivalents, ordering and trimming, for N targets at once.

* A solution fits when every joint has a value within its bounds among its
  2π-equivalents (:func:`.._limits.turn_ranges`). Each combination of those
  values is a solution of its own: a ±360° joint doubles most solutions.
* ``filter_limits`` moves solutions that do not fit to ``rejected``. They are
  shown as close to the limits as whole turns bring them
  (:func:`.._limits.closest_equivalent`), so their violations name exactly the
  joints no turn can fix. With ``filter_limits`` false they stay among the
  solutions at that closest equivalent, flagged.
* With a reference, solutions come nearest first. Per joint the distance is
  the actual travel |q_i − r_i| (radians or length units), except for a
  continuous joint, whose distance is taken across the 2π wrap; per-joint
  weights multiply it; the total is the largest (``linf``) or the Euclidean
  norm (``l2``). ``max_joint_move`` keeps the solutions whose every joint
  travels at most its bound; ``max_solutions`` the nearest k.
* Without a reference, each solution first appears as it needs the fewest
  whole turns (Σ|k_i| for the equivalent q_i + 2k_iπ, an exact count); the
  further equivalents follow, one round per solution at a time.
* ``max_equivalents`` caps the list: it keeps the nearest (with a reference)
  or the least-turned (without), however many fit.
* Ties: equal costs keep the solution order; within one solution, the
  combination whose per-joint ranks come first lexicographically, a joint's
  values being ranked by cost and, at equal cost, by value (the lower first).
  Distances are float64 (the l2 norm summed in joint order), so two values
  equally far from the reference in exact arithmetic may differ in the last bit.

* A reference outside a joint's limits is taken at its own 2π-equivalent within them, where it has one: the
  arm cannot be at the value given, and a solution equal to it up to whole turns is then at no distance
  (:func:`effective_reference`).

How the work stays bounded: only the rank tuples of :mod:`._equivalents` are enumerated and costed, in chunks
of whole solutions of at most about :data:`_CHUNK_ROWS` combinations (one target's may span several), with
``budget`` checked between chunks; the counts (``available``, ``trimmed``) are products of interval lengths,
capped at :data:`.._budget.COUNT_CAP`. One target without a collision filter, of at most
:data:`_ONE_TARGET_COMBINATIONS` combinations, is selected row by row instead (:func:`_one_target`: a single
pose's answer, where the chunks' fixed costs outweigh the work), with or without a reference.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .._budget import COUNT_CAP, UNLIMITED, Budget
from .._errors import InvalidInputError
from .._limits import MULTI_VALUED, Limits, closest_turns, turn_ranges, turns_of_row
from .._robot import Robot
from ._equivalents import (MAX_COMBINATIONS_PER_SOLUTION, capped_products, capped_sums, combination_turns,
                           down_set_size, enumerable_limit, position_in_group, rounds_needed)
from ._table import SolutionTable
from ._types import every

Norm = Literal["linf", "l2"]

#: Default cap on the number of solutions after 2π expansion.
MAX_EQUIVALENTS = 1024

#: How the selection's notes read, in the core's terms, by kind. A boundary that names the options otherwise
#: words them itself: :meth:`TargetNotes.worded` and :meth:`.IKAnswer.details` take a mapping with these keys,
#: whose texts use the same fields.
NOTE_WORDING = {
    "no_fit": "All {rejected} solutions violate a joint limit, whatever whole turns the revolute joints make; they "
              "are listed in 'rejected'.",
    "flagged": "{outside} of the solutions violate a joint limit (the limits flag rather than filter them); each is "
               "flagged with its violations.",
    "capped": "{fit} solutions fit; the cap of {cap} on 2π-equivalents kept the {which} {kept}.",
    "none_near": "{fit} solutions fit the limits, but none is within the joint move or among the solutions allowed "
                 "near the reference.",
    "lowered": "At most {limit} are listed for a {dof}-joint arm whatever cap on 2π-equivalents is asked: ranking "
               "more of so many equivalents would take more work than one answer may.",
    "collide": "{collided} solutions collide (a pair of shapes closer than the margin); they are listed in "
               "'rejected' with their collisions.",
}

#: One target's answer without a collision filter, of up to this many rows, this many
#: combinations in all and this many in a row, is selected row by row (:func:`_one_target`), where the array
#: path's few dozen steps cost more than the arithmetic: a PUMA 560 with its catalogue limits has 8 … 40
#: combinations per pose, a UR5 with ±2π about 512 (64 a row). A row's combinations in answer order are worked
#: out once per turn ranges and kept (:func:`_stream`, for this many ranges: at most 512 × 256 rows of n floats,
#: 6 MB for six joints); past these sizes the array path ranks only the combinations it keeps, and wins.
_ONE_TARGET_ROWS, _ONE_TARGET_COMBINATIONS, _ROW_COMBINATIONS, _KEPT_STREAMS = 64, 1024, 256, 512
#: Up to this many combinations in all, :func:`_in_turn` takes the rounds on Python lists, and one target's
#: combinations nearest a reference are ranked on floats (:func:`_nearest_on_floats`): numpy's fixed costs
#: outweigh the work.
_FEW_IN_TURN = _FEW_NEAREST = 64

#: About the most combinations (one value per joint of one solution) costed at once, for the memory of a chunk.
_CHUNK_ROWS = 1 << 18
_TWO_PI = 2.0 * np.pi


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
    if not np.any(continuous):
        return difference
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


def check_options(robot: Robot, ordering: Ordering, reference: np.ndarray | None, max_equivalents: int) -> None:
    """:func:`check_ordering`, and ``max_equivalents`` ≥ 1 (location ``max_equivalents``)."""
    check_ordering(robot, ordering, reference)
    if max_equivalents < 1:
        raise InvalidInputError("max_equivalents must be ≥ 1", location=("max_equivalents",))


@dataclass(frozen=True)
class Selection:
    """The selection for N targets: per-target fields (N,) and the two tables.

    ``status`` (N,) object: "ok", "no_solution_within_limits", or "unreachable" where the table had no row;
    ``available`` counts the solutions that fit (and, with ``filter_limits`` false, those that do not) after
    ``max_joint_move``; ``trimmed`` those that ``max_joint_move`` and ``max_solutions`` left out; ``truncated``
    says the ``max_equivalents`` cap left some out. ``solutions`` and ``rejected`` are the kept and the rejected
    rows, grouped by target in answer order, each at the 2π-equivalent listed.
    """

    status: np.ndarray
    truncated: np.ndarray
    trimmed: np.ndarray
    available: np.ndarray
    notes: "TargetNotes"
    solutions: SolutionTable
    rejected: SolutionTable


def effective_reference(robot: Robot, limits: Limits, reference: np.ndarray) -> np.ndarray:
    """The reference, shape (n,), with each joint outside its limits moved by whole turns to the equivalent
    within them nearest its value, where one exists (a joint with both bounds finite; tolerance included).

    The arm cannot be at a value outside its limits: a reference there (a controller's unwrapped reading, or
    limits narrower than the arm's) speaks of the same angle, and a solution equal to it up to whole turns is
    at no distance from it.

    >>> import numpy as np
    >>> from service.kinematics import Joint, Limits, Robot
    >>> arm = Robot([Joint("q1", "revolute", 1.0, 0, 0, 0, -np.pi, np.pi)])
    >>> effective_reference(arm, Limits.of(arm), np.array([4.0])).round(4).tolist()
    [-2.2832]
    """
    bounds = limits.widened(robot)
    values = reference.tolist()  # one vector of a few joints: on floats, without an array operation a rule
    # (a value that is not finite stays as it is: no whole turn brings it within)
    outside = [joint for joint, (value, (kind, lower, upper, *_)) in enumerate(zip(values, bounds.rules))
               if kind == MULTI_VALUED and (value < lower or value > upper) and math.isfinite(value)]
    if not outside:
        return reference
    tolerance = limits.tolerance(robot)
    for joint in outside:
        _, lower, upper, _, _, _, stated_upper = bounds.rules[joint]
        value = values[joint]
        # whole turns towards the nearer bound, the fewest that cross it
        turns = (-math.ceil((value - stated_upper - float(tolerance[joint])) / _TWO_PI) if value > stated_upper
                 else math.ceil((lower - value) / _TWO_PI))
        moved = value + _TWO_PI * turns
        if lower <= moved <= upper:
            values[joint] = moved
    return np.array(values)


def select(robot: Robot, table: SolutionTable, n_targets: int, limits: Limits, *, filter_limits: bool = True,
           reference: np.ndarray | None = None, ordering: Ordering = Ordering(),
           max_equivalents: int = MAX_EQUIVALENTS, excluded: np.ndarray | None = None,
           budget: Budget = UNLIMITED) -> Selection:
    """Apply limits, expand 2π-equivalents, order and trim the verified solutions of N targets (``table``,
    grouped by target; see the module docstring).

    Parameters
    ----------
    limits : Limits
        The bounds to apply (the robot's, or a request's override).
    filter_limits : bool
        Move solutions that no whole turn brings within the limits to ``rejected``; when false they stay among
        the solutions, flagged.
    reference : ndarray, shape (n,), optional
        Radians / length units. Orders nearest first; required by ``ordering.max_solutions``,
        ``ordering.max_joint_move`` and ``ordering.weights``.
    max_equivalents : int
        Most solutions returned per target after expansion (≥ 1). The counts (``available``, ``trimmed``) are
        computed without generating the rest and stop at :data:`.._budget.COUNT_CAP`.
    excluded : ndarray of bool, shape (S,), optional
        Rows that may not be kept whatever the limits (they collide, and the request filters collisions): they
        are rejected at their closest equivalent, and the order and the caps apply to the others.
    budget : Budget
        Checked between chunks of the work.
    """
    check_options(robot, ordering, reference, max_equivalents)
    if reference is not None:
        reference = effective_reference(robot, limits, reference)
    budget.check("selection")
    if n_targets == 1 and excluded is None and len(table) <= _ONE_TARGET_ROWS:
        chosen = _one_target(robot, limits, table, filter_limits, max_equivalents, reference, ordering)
        if chosen is not None:
            return chosen
    n = robot.dof
    target, q = table.target, table.joints
    first, last = turn_ranges(robot, limits, q)
    unordered = reference is None and excluded is None
    if unordered and every(first == last):  # every row fits at one equivalent (one flat comparison: a batch's)
        return _each_once(robot, limits, table, n_targets, first, last, np.ones(len(q), dtype=bool), filter_limits,
                          max_equivalents)
    fits = (last >= first).all(axis=1)
    if unordered and every((first == last).all(axis=1) | ~fits):  # and the others at none
        return _each_once(robot, limits, table, n_targets, first, last, fits, filter_limits, max_equivalents)
    keepable = fits if filter_limits else np.ones(len(q), dtype=bool)
    if excluded is not None:
        keepable = keepable & ~excluded
    dropped = (~keepable).nonzero()[0]  # rejected at their closest equivalent
    misfits = (~fits).nonzero()[0]
    misfit_q = q.take(misfits, axis=0)
    misfit_turns = (closest_turns(robot, limits, misfit_q, first.take(misfits, axis=0), last.take(misfits, axis=0))
                    if len(misfits) else misfit_q)
    if not len(misfits) and not len(dropped):
        candidates = np.arange(len(target))
        c_target, c_q, c_first, c_last = target, q, first, last
    else:  # a solution that does not fit and stays (limits flag it) has one value: its closest equivalent
        if not filter_limits and len(misfits):
            first[misfits], last[misfits] = misfit_turns, misfit_turns
        candidates = keepable.nonzero()[0]
        c_target, c_q, c_first, c_last = (a.take(candidates, axis=0) for a in (target, q, first, last))
    counts = c_last - c_first + 1.0  # ≥ 1: every candidate has a usable turn per joint
    combinations = capped_products(counts)  # (C,) each candidate's usable combinations
    with_all_moves = available = capped_sums(c_target, combinations, n_targets)
    if reference is not None and ordering.max_joint_move is not None:
        c_first, c_last = _within_move(robot, limits, c_q, c_first, c_last, reference, ordering.max_joint_move)
        counts = np.maximum(c_last - c_first + 1.0, 0.0)
        combinations = capped_products(counts)
        available = capped_sums(c_target, combinations, n_targets)

    limit = max_equivalents if ordering.max_solutions is None else min(max_equivalents, ordering.max_solutions)
    lowered = limit > enumerable_limit(n) and bool((combinations > MAX_COMBINATIONS_PER_SOLUTION).any())
    if lowered:
        limit = enumerable_limit(n)
    if reference is not None:
        row_limit = np.full(len(c_target), limit, dtype=np.int64)
    else:  # round robin: no solution gives more than the rounds needed to reach the limit
        row_limit = rounds_needed(c_target, combinations, n_targets, limit)[c_target]
    kept_rows, kept_values = _nearest(robot, limits, c_target, c_q, c_first, c_last, counts, row_limit, limit,
                                      reference, ordering, budget)
    kept_rows = candidates[kept_rows]
    kept = table.take(kept_rows, joints=kept_values, within_limits=fits[kept_rows])

    if filter_limits and excluded is None:  # the dropped rows are the misfits, their closest turns known
        dropped_values = misfit_q + _TWO_PI * misfit_turns
    else:
        dropped_values = q[dropped] + _TWO_PI * closest_turns(robot, limits, q[dropped], first[dropped],
                                                              last[dropped])
    if reference is not None and len(dropped):
        order = np.lexsort((travel(robot, limits, dropped_values, reference, ordering), target[dropped]))
        dropped, dropped_values = dropped[order], dropped_values[order]
    rejected = table.take(dropped, joints=dropped_values, within_limits=fits[dropped])

    collided = np.zeros(n_targets, dtype=np.int64)  # rejected for a collision alone (within the limits, or flagged)
    if excluded is not None:
        collided = np.bincount(target[excluded & (fits | (not filter_limits))], minlength=n_targets)
    capped = ordering.max_solutions is not None and ordering.max_solutions <= max_equivalents
    return _outcome(table.counts(n_targets), kept, kept.counts(n_targets), rejected,
                    np.bincount(c_target, minlength=n_targets), available, with_all_moves, collided, capped,
                    max_equivalents, reference is not None, limit if lowered else None, n)


def _outcome(rows: np.ndarray, kept: SolutionTable, n_kept: np.ndarray, rejected: SolutionTable,
             candidates: np.ndarray, available: np.ndarray, with_all_moves: np.ndarray, collided: np.ndarray,
             capped: bool, max_equivalents: int, has_reference: bool, lowered_to: int | None, n: int) -> Selection:
    """The selection of :func:`select` from its kept and rejected tables, with each target's status, counts and
    notes. Per target, shape (N,) each: ``rows`` the verified solutions, ``n_kept`` the kept rows,
    ``candidates`` the rows that may be kept (they fit, or the limits flag them, and no collision excludes them),
    ``available`` and ``with_all_moves`` their combinations after and before ``max_joint_move``, ``collided`` the
    rows rejected for a collision alone; ``capped`` says ``max_solutions`` set the number kept, and
    ``lowered_to`` the limit :func:`enumerable_limit` imposed, if any.
    """
    n_targets = len(rows)
    nothing, none = np.zeros(n_targets, dtype=np.int64), np.zeros(n_targets, dtype=bool)
    # each column worked out only where it can be other than nothing: one target's answer is a handful of rows,
    # and each array operation costs far more than its arithmetic there
    n_rejected = rejected.counts(n_targets) if len(rejected) else nothing
    flagged = np.count_nonzero(kept.within_limits) < len(kept)
    outside = np.bincount(kept.target[~kept.within_limits], minlength=n_targets) if flagged else nothing
    status = _all_ok(n_targets)
    none_kept = no_fit = none
    if len(rejected):
        none_kept = (candidates == 0) & (n_rejected > 0)  # a target with no row at all rejects none either
        no_fit = none_kept & (collided == 0)
        status[no_fit] = "no_solution_within_limits"
        status[none_kept & (collided > 0)] = "no_collision_free_solution"
    unreached = rows == 0
    if np.count_nonzero(unreached):
        status[unreached] = "unreachable"
    truncated = np.zeros(n_targets, dtype=bool) if capped else available > n_kept  # its own: the answer holds it
    trimmed = with_all_moves - available
    if capped:
        trimmed += available - n_kept
    np.minimum(trimmed, COUNT_CAP, out=trimmed)
    noted = no_fit | truncated
    if flagged:
        noted |= outside > 0
    if np.count_nonzero(collided):
        noted |= collided > 0
    if np.count_nonzero(n_kept) < n_targets:  # a reached target with none kept, though some fit before the move
        noted |= ~unreached & ~none_kept & (n_kept == 0) & (with_all_moves > 0)
    notes = TargetNotes(noted.nonzero()[0], status, n_rejected, outside, truncated, available, n_kept,
                        with_all_moves, collided, max_equivalents, has_reference, lowered_to, n)
    return Selection(status, truncated, trimmed, available, notes, kept, rejected)


def _one_outcome(rows: int, kept: SolutionTable, rejected: SolutionTable, candidates: int, available: int,
                 with_all_moves: int, capped: bool, max_equivalents: int, has_reference: bool, n: int) -> Selection:
    """:func:`_outcome` of one target (:func:`_one_target`: no row excluded, no limit lowered) from its counts as
    Python integers: the same rules and the same columns (arrays (1,) of the same dtypes), without an array
    operation per rule, each of which costs more than its arithmetic for one target. ``kept`` and ``rejected``
    are its two tables (their lengths are ``n_kept`` and ``n_rejected`` there)."""
    n_kept, n_rejected = len(kept), len(rejected)
    outside = n_kept - np.count_nonzero(kept.within_limits)  # kept but flagged: outside the limits
    none_kept = candidates == 0 and n_rejected > 0  # (a target with no row at all rejects none either)
    status = "unreachable" if rows == 0 else "no_solution_within_limits" if none_kept else "ok"
    truncated = not capped and available > n_kept
    trimmed = min(with_all_moves - available + (available - n_kept if capped else 0), COUNT_CAP)
    # (no collision excludes a row here, so every target with none kept is noted: _outcome's no_fit is none_kept)
    noted = none_kept or truncated or outside > 0 or (rows > 0 and n_kept == 0 and with_all_moves > 0)
    status_column = np.empty(1, dtype=object)
    status_column[0] = status
    truncated_column = np.array([truncated])
    available_column = np.array([available], dtype=np.int64)
    notes = TargetNotes(np.array([0] if noted else [], dtype=np.int64), status_column,
                        np.array([n_rejected], dtype=np.int64), np.array([outside], dtype=np.int64),
                        truncated_column, available_column, np.array([n_kept], dtype=np.int64),
                        np.array([with_all_moves], dtype=np.int64), np.zeros(1, dtype=np.int64), max_equivalents,
                        has_reference, None, n)
    return Selection(status_column, truncated_column, np.array([trimmed], dtype=np.int64), available_column, notes,
                     kept, rejected)


def _each_once(robot: Robot, limits: Limits, table: SolutionTable, n_targets: int, first: np.ndarray,
               last: np.ndarray, fits: np.ndarray, filter_limits: bool, max_equivalents: int) -> Selection:
    """:func:`select` where every row that fits the limits does so at exactly one 2π-equivalent (limits within a
    whole turn, or none; ``first``, ``last`` (S, n) its turn ranges, ``fits`` (S,)) and nothing orders or
    excludes rows: each target's first ``max_equivalents`` rows that may be kept, in table order, and the others
    rejected at their closest equivalent, in table order, with the counts the general path gives for them (each
    row one combination), in a few array operations."""
    target, q = table.target, table.joints
    turns = first
    misfits = (~fits).nonzero()[0]
    if len(misfits):  # each at its closest equivalent: rejected, or kept and flagged
        turns = first.copy()
        turns[misfits] = closest_turns(robot, limits, q[misfits], first[misfits], last[misfits])
    values = q + _TWO_PI * turns
    dropped = misfits if filter_limits else misfits[:0]
    rows = table.counts(n_targets)
    candidates = rows if not len(dropped) else np.bincount(np.delete(target, dropped), minlength=n_targets)
    if not len(misfits) and candidates.max(initial=0) <= max_equivalents:  # every row kept as it stands
        kept, n_kept = table.listed_at(values, fits), rows
    else:
        keep = np.delete(np.arange(len(target)), dropped)
        if candidates.max(initial=0) > max_equivalents:  # the cap: each target's first rows
            keep = keep[position_in_group(target[keep]) < max_equivalents]
        kept = table.take(keep, joints=values[keep], within_limits=fits[keep])
        n_kept = kept.counts(n_targets)
    rejected = table.take(dropped, joints=values[dropped], within_limits=fits[dropped])
    nothing = np.zeros(n_targets, dtype=np.int64)
    return _outcome(rows, kept, n_kept, rejected, candidates, candidates, candidates, nothing, False,
                    max_equivalents, False, None, robot.dof)


def _all_ok(n_targets: int) -> np.ndarray:
    """A status column (N,) of objects, every entry "ok" (``np.full`` of a str goes through a str array and a
    cast: ten times slower on a batch)."""
    status = np.empty(n_targets, dtype=object)
    status.fill("ok")
    return status


def _within_move(robot: Robot, limits: Limits, q: np.ndarray, first: np.ndarray, last: np.ndarray,
                 reference: np.ndarray, max_joint_move: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The turns (first, last), shape (S, n) each, narrowed to values within reference ± max_joint_move.

    A joint with both bounds finite is never continuous: its travel is |q + 2kπ − r|, so its turns stay an
    interval. Every other joint has one value, kept if its travel is within the bound (tolerance included).
    """
    reach = max_joint_move + limits.tolerance(robot)
    low, high = reference - reach, reference + reach
    with np.errstate(invalid="ignore"):
        near_first = np.ceil((low - q) / _TWO_PI)
        near_last = np.floor((high - q) / _TWO_PI)
        near_first = near_first + (q + _TWO_PI * near_first < low)
        near_last = near_last - (q + _TWO_PI * near_last > high)
    single_near = _travel(np.abs(q + _TWO_PI * first - reference), limits.continuous(robot)) <= reach
    multi = limits.multi_valued(robot)
    return (np.where(multi, np.maximum(first, near_first), first),
            np.where(multi, np.minimum(last, near_last), np.where(single_near, last, first - 1.0)))


def _nearest(robot: Robot, limits: Limits, target: np.ndarray, q: np.ndarray, first: np.ndarray, last: np.ndarray,
             counts: np.ndarray, row_limit: np.ndarray, limit: int, reference: np.ndarray | None,
             ordering: Ordering, budget: Budget) -> tuple[np.ndarray, np.ndarray]:
    """The kept combinations of the candidate rows, in answer order: (row (K,), joint values (K, n)).

    ``target`` (S,) is non-decreasing; ``q``, ``first``, ``last``, ``counts`` (S, n) are the rows' values,
    usable turns and their numbers; ``row_limit`` (S,) the most combinations a row may give.
    """
    n = q.shape[1]
    if not len(target):  # no candidate row (none fits the limits)
        return np.zeros(0, dtype=np.int64), np.zeros((0, n))
    weights = np.ones(n) if reference is None or ordering.weights is None else np.asarray(ordering.weights, float)
    ranks_cap = np.minimum(counts, row_limit[:, None]).astype(np.int64)
    if len(row_limit) and (row_limit == row_limit[0]).all():  # one limit: one target, or a reference
        down_sets = min(down_set_size(n, int(row_limit[0])), COUNT_CAP)
    else:
        limits_met, which = np.unique(row_limit, return_inverse=True)
        down_sets = np.array([min(down_set_size(n, int(b)), COUNT_CAP) for b in limits_met.tolist()],
                             dtype=np.int64)[which.ravel()]
    bound = np.minimum(capped_products(ranks_cap), down_sets).astype(float)
    # chunks of whole rows: a row's combinations are at most MAX_COMBINATIONS_PER_SOLUTION, but one target's rows
    # (16 solutions, or 32 samples of a free joint times 8) may hold millions, so a target may span chunks
    before = np.cumsum(bound) - bound
    chunk = before // _CHUNK_ROWS
    if chunk[-1] == 0:  # one chunk
        edges = np.array([0, len(target)])
    else:
        edges = _target_edges(target, before, bound,
                              np.flatnonzero(np.concatenate(([True], chunk[1:] != chunk[:-1], [True]))))
    spanning = bool((target[edges[1:-1]] == target[edges[1:-1] - 1]).any())
    if not spanning:  # each chunk's kept rows go straight to their place: per target, at most the limit or them all
        most = int(np.minimum(np.bincount(target, weights=bound), limit).sum())
        rows_out, values_out, filled = np.empty(most, dtype=np.int64), np.empty((most, n)), 0
    kept_rows, kept_values, kept_keys = [], [], []  # of each chunk, where a target spans chunks
    for start, stop in zip(edges[:-1].tolist(), edges[1:].tolist()):
        budget.check("selection")
        owner, turns = combination_turns(q[start:stop], first[start:stop], last[start:stop], ranks_cap[start:stop],
                                          row_limit[start:stop], reference, weights)
        owner += start
        # the combinations are put in answer order and cut by an index into them (C,), so the joint values
        # (C, n) are gathered once, at the end
        if reference is None:
            cost = _turn_sums(turns)
            pick = _grouped_order(owner, cost)  # each row's combinations cheapest first, ties by rank tuple
            key = position_in_group(owner[pick])  # the row's stream position: the targets take turns between rows
            early = key < row_limit[owner[pick]]
            pick, key = pick[early], key[early]
            # rows ascend here and give one combination per stream position: ties of (target, key) are in row order
            order = _grouped_order(target[owner[pick]], key)
            pick, key = pick[order], key[order]
            values = None
        else:
            values = q[owner] + _TWO_PI * turns
            distance = _travel(np.abs(values - reference), limits.continuous(robot)) * weights
            cost = distance.max(axis=1) if ordering.norm == "linf" else np.sqrt(np.sum(distance ** 2, axis=1))
            pick = np.lexsort((cost, target[owner]))  # stable: ties by row, then rank tuple
            key = cost[pick]
        first_few = position_in_group(target[owner[pick]]) < limit
        pick, key = pick[first_few], key[first_few]
        picked = owner[pick]
        if spanning:
            kept_rows.append(picked)
            kept_values.append(q[picked] + _TWO_PI * turns[pick] if values is None else values[pick])
            kept_keys.append(key)
            continue
        block = slice(filled, filled + len(pick))
        rows_out[block] = picked
        if values is None:  # q + 2πk, as 2πk + q (the same sum); take: a plain gather, faster than indexing
            np.multiply(turns.take(pick, axis=0), _TWO_PI, out=values_out[block])
            values_out[block] += q.take(picked, axis=0)
        else:
            values_out[block] = values[pick]
        filled = block.stop
    if not spanning:
        if filled < most // 2:  # far fewer than the most: not kept in the larger arrays
            return rows_out[:filled].copy(), values_out[:filled].copy()
        return rows_out[:filled], values_out[:filled]
    # a target over several chunks: its kept combinations from each, ordered again as one chunk orders them
    # (each chunk's come in row order, so the stable sorts break ties as one chunk would)
    rows, values, keys = np.concatenate(kept_rows), np.concatenate(kept_values), np.concatenate(kept_keys)
    order = np.lexsort((rows, keys, target[rows])) if reference is None else np.lexsort((keys, target[rows]))
    rows, values = rows[order], values[order]
    first_few = position_in_group(target[rows]) < limit
    return rows[first_few], values[first_few]


def _one_target(robot: Robot, limits: Limits, table: SolutionTable, filter_limits: bool, max_equivalents: int,
                reference: np.ndarray | None = None, ordering: Ordering = Ordering()) -> Selection | None:
    """:func:`select` of one target's rows (``table``) without excluded rows, in a few steps on Python floats and
    integers, or on arrays of that target's few combinations: the same selection, field by field. None where its
    rows have more combinations than :data:`_ONE_TARGET_COMBINATIONS` in all or :data:`_ROW_COMBINATIONS` in one,
    or a value that is not finite meets a quotient (the array path then selects them).

    Every row that fits (or, with ``filter_limits`` false, every row) may be kept, with its combinations (one, at
    its closest equivalent, for a row that does not fit); a row that does not fit and is filtered is rejected at
    its closest equivalent. Without a reference each row's combinations form a stream and the streams take turns
    (:func:`_in_turn`); with one (``reference`` effective already, :func:`effective_reference`) every combination
    is costed and the nearest kept (:func:`_nearest_of_one`, within the joint-move bound if any). Rows whose every
    value has the turns [0, 0] alone (the usual answer: limits within a turn) are found in one comparison."""
    bounds = limits.widened(robot)
    q = table.joints
    n_rows, n = q.shape
    limit = max_equivalents if ordering.max_solutions is None else min(max_equivalents, ordering.max_solutions)
    capped = ordering.max_solutions is not None and ordering.max_solutions <= max_equivalents
    at_zero = ((q > bounds.zero_turn_low) & (q < bounds.zero_turn_high)).all(axis=1).tolist()
    if all(at_zero) and n_rows <= limit and ordering.max_joint_move is None:
        # every row kept, at q + 2π·0 as the arrays list it (nearest first with a reference)
        order = slice(None) if reference is None else np.argsort(travel(robot, limits, q, reference, ordering),
                                                                  kind="stable")
        kept = table.listed_at(q + 0.0, np.ones(n_rows, dtype=bool)) if reference is None else table.take(
            order, joints=q[order] + 0.0, within_limits=np.ones(n_rows, dtype=bool))
        return _one_outcome(n_rows, kept, table.take(slice(0, 0)), n_rows, n_rows, n_rows, capped, max_equivalents,
                            reference is not None, n)
    zero = [0.0] * n
    fits, firsts, lasts, candidates, dropped, dropped_turns, combinations = [], [], [], [], [], [], 0
    for row, (simple, values) in enumerate(zip(at_zero, q.tolist())):
        if simple:
            fits.append(True)
            candidates.append(row)
            firsts.append(zero)
            lasts.append(zero)
            combinations += 1
            continue
        turns = turns_of_row(bounds, values)
        if turns is None:
            return None
        first, last, row_fits = turns
        fits.append(row_fits)
        if not row_fits and filter_limits:  # rejected at its closest equivalent (first, last)
            dropped.append(row)
            dropped_turns.append(first)
            continue
        candidates.append(row)  # kept, and flagged if it does not fit, at its closest equivalent
        firsts.append(first)
        lasts.append(last)
        if first != last:
            row_combinations = math.prod(int(high - low) + 1 for low, high in zip(first, last))
            if row_combinations > _ROW_COMBINATIONS:
                return None
            combinations += row_combinations - 1
        combinations += 1
        if combinations > _ONE_TARGET_COMBINATIONS:
            return None
    available = combinations
    if reference is None:
        kept_of, turns = _in_turn(firsts, lasts, max_equivalents, n)
    else:
        kept_of, turns, available = _nearest_of_one(robot, limits, q.take(candidates, axis=0), firsts, lasts, limit,
                                                    reference, ordering)
    kept_rows = np.array(candidates, dtype=np.int64)[kept_of]
    fits = np.array(fits, dtype=bool)
    # q + 2πk as the arrays list them: 2πk first, then q added (the same sum either way round)
    kept = table.take(kept_rows, joints=turns * _TWO_PI + q.take(kept_rows, axis=0), within_limits=fits[kept_rows])
    dropped = np.array(dropped, dtype=np.int64)
    dropped_values = (np.array(dropped_turns, dtype=float).reshape(len(dropped), n) * _TWO_PI
                      + q.take(dropped, axis=0))
    if reference is not None and len(dropped) > 1:  # nearest first, as the kept ones
        order = np.argsort(travel(robot, limits, dropped_values, reference, ordering), kind="stable")
        dropped, dropped_values = dropped[order], dropped_values[order]
    rejected = table.take(dropped, joints=dropped_values, within_limits=fits[dropped])
    return _one_outcome(n_rows, kept, rejected, len(candidates), available, combinations, capped, max_equivalents,
                        reference is not None, n)


def _nearest_of_one(robot: Robot, limits: Limits, q: np.ndarray, firsts: list[list[float]],
                    lasts: list[list[float]], limit: int, reference: np.ndarray, ordering: Ordering
                    ) -> tuple[np.ndarray, np.ndarray, int]:
    """:func:`_nearest` of one target's candidate rows q (C, n) with a reference: the kept rows (K,) (indices
    into q), each one's turns (K, n), nearest first, and the combinations within the joint-move bound (all of
    them without one). ``firsts``, ``lasts`` are the rows' usable turns (n whole floats each, ``last ≥ first``),
    their combinations few (:data:`_ONE_TARGET_COMBINATIONS`): the bound narrows them (:func:`_within_move`), and
    each combination left is costed, in the order :func:`~._equivalents.combination_turns` gives them (rows in
    order, each one's rank tuples lexicographically), and a stable sort keeps the array path's ties."""
    n = q.shape[1]
    first = np.array(firsts, dtype=float).reshape(len(firsts), n)
    if firsts == lasts and ordering.max_joint_move is None:  # one combination each: the rows themselves
        owner, turns, available = np.arange(len(firsts)), first, len(firsts)
    else:
        last = np.array(lasts, dtype=float).reshape(first.shape)
        if ordering.max_joint_move is not None:
            first, last = _within_move(robot, limits, q, first, last, reference, ordering.max_joint_move)
        counts = np.maximum(last - first + 1.0, 0.0)  # 0 for a joint no value of which is near enough
        combinations = np.prod(counts, axis=1)
        available = int(combinations.sum())  # whole numbers within _ONE_TARGET_COMBINATIONS: exact
        near = np.flatnonzero(combinations)  # the rows with a combination left (each one's come alone)
        if (combinations[near] == 1.0).all():
            owner, turns = near, first[near]
        elif available <= _FEW_NEAREST and (ordering.norm == "linf" or n < 8):  # (numpy sums 8 terms pairwise)
            return (*_nearest_on_floats(robot, limits, q[near].tolist(), first[near].tolist(), last[near].tolist(),
                                        near.tolist(), limit, reference, ordering), available)
        else:
            weights = np.ones(n) if ordering.weights is None else np.asarray(ordering.weights, dtype=float)
            owner, turns = combination_turns(q[near], first[near], last[near],
                                             np.minimum(counts[near], limit).astype(np.int64),
                                             np.full(len(near), limit, dtype=np.int64), reference, weights)
            owner = near[owner]
    cost = travel(robot, limits, q.take(owner, axis=0) + _TWO_PI * turns, reference, ordering)
    pick = np.argsort(cost, kind="stable")[:limit]
    return owner[pick], turns[pick], available


def _nearest_on_floats(robot: Robot, limits: Limits, q: list[list[float]], firsts: list[list[float]],
                       lasts: list[list[float]], rows: list[int], limit: int, reference: np.ndarray,
                       ordering: Ordering) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_nearest_of_one` of a few combinations (:data:`_FEW_NEAREST`) on Python floats: the rows ``rows``
    (each with q, its usable turns ``firsts`` … ``lasts``, n floats each) give their combinations in the order of
    :func:`~._equivalents.combination_turns` (rows in order, each one's rank tuples lexicographically, a joint's
    turns ranked as :func:`~._equivalents._ranked_turns` and :func:`~._equivalents._rank_offsets` rank them), each
    costed as :func:`travel` costs it, bit for bit, and a stable sort keeps the first ``limit``. Every tuple is
    costed: those the arrays skip (∏(r_j + 1) > ``limit``) have ``limit`` tuples at most as far before them, so
    they are never kept. Returns the kept rows (K,) and their turns (K, n)."""
    at = reference.tolist()
    n = len(at)
    weights = [1.0] * n if ordering.weights is None else np.asarray(ordering.weights, dtype=float).tolist()
    continuous = limits.continuous(robot).tolist()
    l2 = ordering.norm == "l2"
    costed = []
    for row, values, first, last in zip(rows, q, firsts, lasts):
        ranked = [_ranked_turns_of(*joint, limit) for joint in zip(values, first, last, at, weights)]
        for turns in itertools.product(*ranked):
            total = 0.0
            for value, turn, reference_value, weight, wraps in zip(values, turns, at, weights, continuous):
                distance = abs(value + _TWO_PI * turn - reference_value)
                if wraps:
                    distance = abs(math.pi - (math.pi - distance) % _TWO_PI)
                if ordering.weights is not None:
                    distance *= weight
                total = total + distance * distance if l2 else (distance if distance > total else total)
            costed.append((math.sqrt(total) if l2 else total, row, turns))
    costed.sort(key=lambda entry: entry[0])  # stable: ties keep the enumeration's order
    kept = costed[:limit]
    return (np.array([row for _, row, _ in kept], dtype=np.int64),
            np.array([turns for _, _, turns in kept], dtype=float).reshape(len(kept), n))


def _ranked_turns_of(value: float, first: float, last: float, reference: float, weight: float, limit: int
                     ) -> list[float]:
    """One joint's usable turns (``first`` … ``last``) in rank order, at most ``limit`` of them: cheapest
    |value + 2kπ − reference|·weight first, then alternately on either side while both have turns left (the lower
    value first at equal cost), as :func:`~._equivalents._ranked_turns` and :func:`~._equivalents._rank_offsets`
    rank them on arrays."""
    if first == last:  # the usual joint: its one turn
        return [first]

    def cost(turn: float) -> float:
        return abs(value + _TWO_PI * turn - reference) * weight

    below = float(math.floor((reference - value) / _TWO_PI))
    above = below + 1.0
    at_above = cost(above)
    lower_costs_more = at_above < cost(below)
    cheapest = above if lower_costs_more else below
    direction = -1.0 if lower_costs_more or cost(below - 1.0) <= at_above else 1.0
    if weight == 0:  # every value costs 0: ascending values
        cheapest, direction = first, 1.0
    direction = 1.0 if cheapest < first else -1.0 if cheapest > last else direction
    cheapest = min(max(cheapest, first), last)
    ahead = last - cheapest if direction > 0 else cheapest - first
    behind = (last - first) - ahead
    turns = []
    for rank in range(min(int(last - first) + 1, limit)):
        if rank <= 2.0 * min(ahead, behind):
            offset = direction * (rank + 1.0) / 2.0 if rank % 2 == 1 else -direction * rank / 2.0
        else:
            offset = -direction * (rank - ahead) if ahead <= behind else direction * (rank - behind)
        turns.append(cheapest + offset)
    return turns


def _in_turn(firsts: list[list[float]], lasts: list[list[float]], limit: int, n: int
             ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_nearest` of one target's rows without a reference: the kept rows (K,) and each one's turns (K, n),
    in answer order. ``firsts``, ``lasts`` are the rows' usable turns (n whole floats each, ``last ≥ first``).

    Each row's combinations come cheapest first (:func:`_stream`); the rows take turns, one combination each, and
    the first ``limit`` are kept. :func:`_nearest` enumerates only the rank tuples with ∏(r_j + 1) within a row's
    share of the rounds, which holds every combination this order puts among the first ``limit``: the ∏(r_j + 1)
    tuples at or below a tuple cost no more and precede it."""
    if firsts == lasts:  # one combination each (limits within a turn): the rows in order
        return np.arange(min(len(firsts), limit)), np.array(firsts[:limit], dtype=float).reshape(-1, n)
    streams = [_stream(tuple(first), tuple(last)) if first != last else None for first, last in zip(firsts, lasts)]
    lengths = [1 if stream is None else len(stream) for stream in streams]
    if sum(lengths) <= _FEW_IN_TURN:  # the rounds on lists (a PUMA's rows: a few, one or two combinations each)
        lists = [[first] if stream is None else stream.tolist() for first, stream in zip(firsts, streams)]
        rows, turns = [], []
        for position in range(max(lengths)):
            for row, stream in enumerate(lists):
                if position < len(stream):
                    rows.append(row)
                    turns.append(stream[position])
        return np.array(rows[:limit], dtype=np.int64), np.array(turns[:limit], dtype=float).reshape(-1, n)
    streams = [np.array([first]) if stream is None else stream for first, stream in zip(firsts, streams)]
    if min(lengths) == max(lengths):  # streams of one length (a ±2π arm's): round by round as they stand
        every = len(streams) * lengths[0]
        return np.arange(min(every, limit)) % len(streams), np.stack(streams, axis=1).reshape(every, n)[:limit]
    turns = np.concatenate(streams)
    rows = np.repeat(np.arange(len(streams)), lengths)
    position = np.arange(len(rows)) - np.repeat(np.cumsum(lengths) - lengths, lengths)
    order = np.lexsort((rows, position))[:limit]  # round by round, the rows in order within a round
    return rows[order], turns[order]


@functools.lru_cache(maxsize=_KEPT_STREAMS)
def _stream(first: tuple[float, ...], last: tuple[float, ...]) -> np.ndarray:
    """One row's combinations (C, n), cheapest first: the turns k of each joint within [first, last], the
    combinations in order of Σ|k|, equal costs in the lexicographic order of their rank tuples, a joint's turns
    ranked by |k| and the lower first (:func:`._equivalents._ranked_turns` without a reference). A function of the
    ranges alone, kept (read-only): a ±2π arm's rows meet a few dozen ranges. Its callers' rows have at most
    :data:`_ROW_COMBINATIONS`, which bounds what is kept."""
    ranked = [sorted(range(int(low), int(high) + 1), key=lambda k: (abs(k), k)) for low, high in zip(first, last)]
    combinations = sorted(itertools.product(*ranked), key=lambda turns: sum(map(abs, turns)))  # stable
    stream = np.array(combinations, dtype=float).reshape(len(combinations), len(first))
    stream.flags.writeable = False
    return stream


def _target_edges(target: np.ndarray, before: np.ndarray, bound: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """The chunk edges (E,) of :func:`_nearest`, each inside a target of at most :data:`_CHUNK_ROWS` / 8
    combinations moved back to that target's first row: such a target is then ranked in one chunk, and the
    chunks' kept combinations need no ordering again (a chunk grows by at most an eighth). ``before`` and
    ``bound`` (S,) are the combinations before each row and of each row."""
    inner = edges[1:-1]
    split = target[inner] == target[inner - 1]
    if not split.any():
        return edges
    start = np.searchsorted(target, target[inner], side="left")
    stop = np.searchsorted(target, target[inner], side="right")
    size = before[stop - 1] + bound[stop - 1] - before[start]
    moved = np.where(split & (size <= _CHUNK_ROWS // 8), start, inner)
    return np.unique(np.concatenate(([0], moved, [len(target)])))


def _turn_sums(turns: np.ndarray) -> np.ndarray:
    """Σ_j |k_j| per combination of whole turns (C, n), shape (C,): by ``einsum`` (one pass, four times
    ``sum(axis=1)``'s speed on short rows) where every partial sum is a whole number below 2**53, so exact in any
    order of summation; by ``sum`` elsewhere."""
    size = np.abs(turns)
    if size.max(initial=0.0) * turns.shape[1] < 2.0 ** 53:
        return np.einsum("ij->i", size)
    return size.sum(axis=1)


def _grouped_order(groups: np.ndarray, within: np.ndarray) -> np.ndarray:
    """``np.lexsort((within, groups))`` for keys that are whole numbers ≥ 0 (ints, or floats holding them): one
    stable sort of one integer key, groups × (largest within + 1) + within, where that stays below 2**62; the
    lexsort elsewhere. Shape (K,) each."""
    if len(groups):
        span = int(within.max()) + 1
        if (int(groups.max()) + 1) * span < 1 << 62:
            return np.argsort(groups.astype(np.int64) * span + within.astype(np.int64), kind="stable")
    return np.lexsort((within, groups))


class TargetNotes(Mapping):
    """The selection's notes: target index → its notes (list of str), for the targets that have any, each
    worded only when read (a batch has thousands; most readers look at a few).

    ``rows`` (k,) ascending are the noted targets; the other arrays (N,) are the per-target counts the notes
    quote: status, rejected, flagged outside the limits, truncated, available, kept, fitting before
    ``max_joint_move``, and rejected for a collision alone. ``lowered_to`` is the per-target limit
    :func:`enumerable_limit` imposed, if any.
    """

    def __init__(self, rows: np.ndarray, status: np.ndarray, rejected: np.ndarray, outside: np.ndarray,
                 truncated: np.ndarray, available: np.ndarray, kept: np.ndarray, with_all_moves: np.ndarray,
                 collided: np.ndarray, max_equivalents: int, has_reference: bool, lowered_to: int | None,
                 dof: int) -> None:
        self.rows = rows
        self._columns = (status, rejected, outside, truncated, available, kept, with_all_moves, collided)
        self._max_equivalents, self._has_reference = max_equivalents, has_reference
        self._lowered_to, self._dof = lowered_to, dof

    def __len__(self) -> int:
        return len(self.rows)

    def __iter__(self):
        return iter(self.rows.tolist())

    def __contains__(self, row: object) -> bool:
        if not isinstance(row, (int, np.integer)):
            return False
        at = int(np.searchsorted(self.rows, row))
        return at < len(self.rows) and self.rows[at] == row

    def __getitem__(self, row: int) -> list[str]:
        return self.worded(row, NOTE_WORDING)

    def worded(self, row: int, wording: Mapping[str, str]) -> list[str]:
        """Target ``row``'s notes in ``wording`` (the keys and fields of :data:`NOTE_WORDING`)."""
        if row not in self:
            raise KeyError(row)
        return self._words(wording, *(value.item() if isinstance(value, np.generic) else value
                                      for value in (column[row] for column in self._columns)))

    def worded_every(self, wording: Mapping[str, str]) -> dict[int, list[str]]:
        """:meth:`worded` of every target with notes, keyed by target: the columns read once, as lists (a batch
        may have thousands)."""
        columns = [column.tolist() if isinstance(column, np.ndarray) else list(column) for column in self._columns]
        return {row: self._words(wording, *(column[row] for column in columns)) for row in self.rows.tolist()}

    def _words(self, wording: Mapping[str, str], status: str, rejected: int, outside: int, truncated: bool,
               available: int, kept: int, with_all_moves: int, collided: int) -> list[str]:
        notes = []
        if status == "no_solution_within_limits":
            notes.append(wording["no_fit"].format(rejected=rejected))
        if collided:
            notes.append(wording["collide"].format(collided=collided))
        if outside:
            notes.append(wording["flagged"].format(outside=outside))
        if truncated:
            fit = f"At least {COUNT_CAP} (2**53 − 1, the count's cap)" if available >= COUNT_CAP else f"{available}"
            notes.append(wording["capped"].format(fit=fit, cap=self._max_equivalents, kept=kept,
                                                  which="nearest" if self._has_reference else "least-turned"))
        if status == "ok" and not kept and with_all_moves:
            notes.append(wording["none_near"].format(fit=with_all_moves))
        if truncated and self._lowered_to is not None:
            notes.append(wording["lowered"].format(limit=self._lowered_to, dof=self._dof))
        return notes
