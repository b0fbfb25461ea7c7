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

How the work stays bounded: a joint's usable values are the whole turns k of
an interval (its limits, narrowed by ``max_joint_move``), ranked by cost
outwards from the cheapest. A combination among the first L of a solution
(L = the most that can be returned of it) has ranks (r_1 … r_n) with
∏(r_j + 1) ≤ L, since every combination with smaller or equal ranks costs no
more and comes first. Only those rank tuples are enumerated and costed, in
chunks of whole solutions of at most about :data:`_CHUNK_ROWS` combinations
(one target's may span several), with ``budget`` checked between chunks; the counts (``available``, ``trimmed``) are
products of interval lengths, capped at :data:`.._budget.COUNT_CAP`.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from .._budget import COUNT_CAP, UNLIMITED, Budget
from .._errors import InvalidInputError
from .._limits import Limits, Violation, closest_turns, turn_ranges, violations
from .._robot import Robot
from ._arrays import IKArrays
from ._types import IKResult, Solution

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
}

#: About the most combinations (one value per joint of one solution) costed at once, for the memory of a chunk.
_CHUNK_ROWS = 1 << 18
#: Most rank tuples one solution may enumerate (:func:`_nearest`). Past it the number kept per target is lowered
#: to :func:`enumerable_limit` (said in the target's notes), so the work per solution stays bounded whatever the
#: limits, ``max_equivalents`` and the joint count; the boundary refuses such requests before solving when the
#: client asked for that many. A target's solutions are ranked in one chunk: 16 solutions of 2^15 tuples are
#: about 200 MB of working arrays and a few tenths of a second (2^20 were 1.5 GB and 9 s for 8 UR5 solutions).
MAX_COMBINATIONS_PER_SOLUTION = 1 << 15

_TWO_PI = 2.0 * np.pi
#: Rows (one target's solutions) and rank entries per row (∏ caps × n, bounding the cache's memory) up to which
#: :func:`_rank_tuples` looks rows up one by one rather than enumerating them all at once; up to these rows and
#: entries in all, :func:`_combination_turns` works out each combination's turns directly rather than tabling
#: each joint's ranked turns first.
_FEW_ROWS, _FEW_RANKS = 32, 1 << 13


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


@dataclass
class SolutionTable:
    """Solutions of many targets, one row each, grouped by target in output order.

    ``target`` (S,) is the row's target index (non-decreasing); ``joints``
    (S, n); ``within_limits`` (S,); ``position``, ``orientation`` (S,)
    residuals; ``labels`` name → (values, codes (S,)).
    """

    target: np.ndarray
    joints: np.ndarray
    within_limits: np.ndarray
    position: np.ndarray
    orientation: np.ndarray
    labels: dict[str, tuple[tuple, np.ndarray]]

    def take(self, index: np.ndarray) -> "SolutionTable":
        return SolutionTable(self.target[index], self.joints[index], self.within_limits[index],
                             self.position[index], self.orientation[index],
                             {name: (values, codes[index]) for name, (values, codes) in self.labels.items()})

    @classmethod
    def concatenate(cls, tables: list["SolutionTable"], n: int) -> "SolutionTable":
        names: dict[str, tuple] = {}
        for table in tables:
            for name, (values, _) in table.labels.items():
                names.setdefault(name, values)
        total = sum(len(t.target) for t in tables)
        labels = {}
        for name, values in names.items():
            labels[name] = (values, np.concatenate(
                [t.labels[name][1] if name in t.labels else np.full(len(t.target), -1, dtype=np.int8)
                 for t in tables]) if tables else np.zeros(0, dtype=np.int8))
        if not tables:
            return cls(np.zeros(0, int), np.zeros((0, n)), np.zeros(0, bool), np.zeros(0), np.zeros(0), labels)
        table = cls(np.concatenate([t.target for t in tables]), np.concatenate([t.joints for t in tables]),
                    np.concatenate([t.within_limits for t in tables]), np.concatenate([t.position for t in tables]),
                    np.concatenate([t.orientation for t in tables]), labels)
        assert len(table.target) == total
        return table


@dataclass
class BatchSelection:
    """The selection for N targets: per-target fields (N,) and the two solution tables."""

    status: np.ndarray  # (N,) object: "ok", "unreachable", "no_solution_within_limits"
    truncated: np.ndarray  # (N,) bool
    trimmed: np.ndarray  # (N,) int
    available: np.ndarray  # (N,) int
    notes: "TargetNotes"
    solutions: SolutionTable
    rejected: SolutionTable


def select_arrays(robot: Robot, arrays: IKArrays, limits: Limits, *, filter_limits: bool = True,
                  reference: np.ndarray | None = None, ordering: Ordering = Ordering(),
                  max_equivalents: int = MAX_EQUIVALENTS, budget: Budget = UNLIMITED) -> BatchSelection:
    """Apply limits, expand 2π-equivalents, order and trim every target's solutions (see the module docstring).

    The options are those of :func:`select`; ``budget`` is checked between chunks of targets.
    """
    _check_options(robot, ordering, reference, max_equivalents)
    chosen = _choose(robot, limits, arrays.joints, arrays.valid, arrays.count > 0, filter_limits, reference,
                     ordering, max_equivalents, budget)

    def table(target: np.ndarray, slot: np.ndarray, joints: np.ndarray, within: np.ndarray) -> SolutionTable:
        return SolutionTable(target, joints, within, arrays.position[target, slot], arrays.orientation[target, slot],
                             {name: (values, codes[target, slot]) for name, (values, codes) in arrays.labels.items()})

    return BatchSelection(chosen.status, chosen.truncated, chosen.trimmed, chosen.available, chosen.notes,
                          table(*chosen.kept), table(*chosen.rejected))


def select(robot: Robot, result: IKResult, limits: Limits, *, filter_limits: bool = True,
           reference: np.ndarray | None = None, ordering: Ordering = Ordering(),
           max_equivalents: int = MAX_EQUIVALENTS, budget: Budget = UNLIMITED) -> Selection:
    """Apply limits, expand 2π-equivalents, order and trim the solutions of one IK result (:func:`select_arrays`
    with one target).

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
        Most solutions returned after expansion (≥ 1). The counts
        (``available``, ``trimmed``) are computed without generating the rest
        and stop at :data:`.._budget.COUNT_CAP`.
    budget : Budget
        Checked between chunks of the work.
    """
    _check_options(robot, ordering, reference, max_equivalents)
    solutions = result.solutions if result.status != "unreachable" else []
    joints = np.array([s.joints for s in solutions], dtype=float).reshape(1, len(solutions), robot.dof)
    chosen = _choose(robot, limits, joints, np.ones((1, len(solutions)), dtype=bool),
                     np.array([result.status != "unreachable"]), filter_limits, reference, ordering, max_equivalents,
                     budget)

    def entries(slots: np.ndarray, values: np.ndarray, within: np.ndarray) -> list[Selected]:
        return [Selected(Solution(q, solutions[s].branch, solutions[s].position_residual,
                                  solutions[s].orientation_residual), fits,
                         [] if fits else violations(robot, limits, q))
                for s, q, fits in zip(slots.tolist(), values, within.tolist())]

    return Selection(str(chosen.status[0]), entries(*chosen.kept[1:]), entries(*chosen.rejected[1:]),
                     bool(chosen.truncated[0]), int(chosen.trimmed[0]), int(chosen.available[0]),
                     chosen.notes.get(0, []))


def _check_options(robot: Robot, ordering: Ordering, reference: np.ndarray | None, max_equivalents: int) -> None:
    check_ordering(robot, ordering, reference)
    if max_equivalents < 1:
        raise InvalidInputError("max_equivalents must be ≥ 1", location=("max_equivalents",))


@dataclass
class _Choice:
    """The selection of N targets: per-target fields (N,), and the kept and rejected rows in answer order.

    ``kept`` and ``rejected`` are (target, slot, joints (K, n), within_limits), grouped by target.
    """

    status: np.ndarray
    truncated: np.ndarray
    trimmed: np.ndarray
    available: np.ndarray
    notes: "TargetNotes"
    kept: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]
    rejected: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def _choose(robot: Robot, limits: Limits, joints: np.ndarray, valid: np.ndarray, reachable: np.ndarray,
            filter_limits: bool, reference: np.ndarray | None, ordering: Ordering, max_equivalents: int,
            budget: Budget) -> _Choice:
    """The selection engine: ``joints`` (N, m, n) with ``valid`` (N, m) slots, ``reachable`` (N,)."""
    budget.check("selection")
    n_targets, _, n = joints.shape
    occupied = np.flatnonzero(valid & reachable[:, None])  # (S,) flat (target, slot) indices, grouped by target
    target, slot = np.divmod(occupied, joints.shape[1])
    q = joints.reshape(-1, n).take(occupied, axis=0)
    first, last = turn_ranges(robot, limits, q)
    fits = np.all(last >= first, axis=1)
    misfits = np.flatnonzero(~fits)
    misfit_q = q.take(misfits, axis=0)
    misfit_turns = (closest_turns(robot, limits, misfit_q, first.take(misfits, axis=0), last.take(misfits, axis=0))
                    if len(misfits) else misfit_q)
    if not len(misfits):
        candidates = np.arange(len(target))
        c_target, c_q, c_first, c_last = target, q, first, last
    elif filter_limits:  # the rows that fit are the candidates; the others are rejected at their closest equivalent
        candidates = np.flatnonzero(fits)
        c_target, c_q, c_first, c_last = (a.take(candidates, axis=0) for a in (target, q, first, last))
    else:  # a solution that does not fit stays among the candidates with one value: its closest equivalent
        candidates = np.arange(len(target))
        first[misfits], last[misfits] = misfit_turns, misfit_turns
        c_target, c_q, c_first, c_last = target, q, first, last
    counts = c_last - c_first + 1.0  # ≥ 1: every candidate has a usable turn per joint
    combinations = _capped_products(counts)  # (C,) each candidate's usable combinations
    with_all_moves = available = _capped_sums(c_target, combinations, n_targets)
    if reference is not None and ordering.max_joint_move is not None:
        c_first, c_last = _within_move(robot, limits, c_q, c_first, c_last, reference, ordering.max_joint_move)
        counts = np.maximum(c_last - c_first + 1.0, 0.0)
        combinations = _capped_products(counts)
        available = _capped_sums(c_target, combinations, n_targets)

    limit = max_equivalents if ordering.max_solutions is None else min(max_equivalents, ordering.max_solutions)
    lowered = limit > enumerable_limit(n) and bool(np.any(combinations > MAX_COMBINATIONS_PER_SOLUTION))
    if lowered:
        limit = enumerable_limit(n)
    if reference is not None:
        row_limit = np.full(len(c_target), limit, dtype=np.int64)
    else:  # round robin: no solution gives more than the rounds needed to reach the limit
        row_limit = _rounds_needed(c_target, combinations, n_targets, limit)[c_target]
    kept_rows, kept_values = _nearest(robot, limits, c_target, c_q, c_first, c_last, counts, row_limit, limit,
                                      reference, ordering, budget)
    rows = candidates[kept_rows]
    kept = (target[rows], slot[rows], kept_values, fits[rows])

    dropped, dropped_values = (misfits, misfit_q + _TWO_PI * misfit_turns) if filter_limits else (misfits[:0], q[:0])
    if reference is not None and len(dropped):
        order = np.lexsort((travel(robot, limits, dropped_values, reference, ordering), target[dropped]))
        dropped, dropped_values = dropped[order], dropped_values[order]
    rejected = (target[dropped], slot[dropped], dropped_values, np.zeros(len(dropped), dtype=bool))

    n_kept = np.bincount(kept[0], minlength=n_targets)
    n_rejected = np.bincount(rejected[0], minlength=n_targets)
    outside = np.bincount(kept[0][~kept[3]], minlength=n_targets)
    no_fit = filter_limits & (np.bincount(c_target, minlength=n_targets) == 0) & (n_rejected > 0)
    status = np.full(n_targets, "ok", dtype=object)
    status[no_fit], status[~reachable] = "no_solution_within_limits", "unreachable"
    capped = ordering.max_solutions is not None and ordering.max_solutions <= max_equivalents
    truncated = (available > n_kept) & (not capped)
    trimmed = np.minimum(with_all_moves - available + ((available - n_kept) if capped else 0), COUNT_CAP)
    noted = no_fit | (outside > 0) | truncated | ((status == "ok") & (n_kept == 0) & (with_all_moves > 0))
    notes = TargetNotes(np.flatnonzero(noted), status, n_rejected, outside, truncated, available, n_kept,
                        with_all_moves, max_equivalents, reference is not None, limit if lowered else None, n)
    return _Choice(status, truncated, trimmed, available, notes, kept, rejected)


def combinations_to_rank(n: int, limit: int, equivalents: int) -> int:
    """The most rank tuples one solution of an n-joint arm with ``equivalents`` 2π-equivalents enumerates to keep
    ``limit`` (see :func:`_nearest`): min(equivalents, |{r : ∏(r_j + 1) ≤ min(limit, equivalents)}|)."""
    return min(equivalents, _down_set_size(n, min(limit, equivalents)))


@functools.lru_cache(maxsize=None)
def enumerable_limit(n: int) -> int:
    """The largest number kept per target whose rank tuples for n joints fit MAX_COMBINATIONS_PER_SOLUTION."""
    low, high = 1, MAX_COMBINATIONS_PER_SOLUTION  # _down_set_size(n, 1) = 1 fits; the high end never does for n ≥ 2
    while low < high:
        middle = (low + high + 1) // 2
        if _down_set_size(n, middle) <= MAX_COMBINATIONS_PER_SOLUTION:
            low = middle
        else:
            high = middle - 1
    return low


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
    weights = np.ones(n) if reference is None or ordering.weights is None else np.asarray(ordering.weights, float)
    ranks_cap = np.minimum(counts, row_limit[:, None]).astype(np.int64)
    if len(row_limit) and (row_limit == row_limit[0]).all():  # one limit: one target, or a reference
        down_sets = min(_down_set_size(n, int(row_limit[0])), COUNT_CAP)
    else:
        limits_met, which = np.unique(row_limit, return_inverse=True)
        down_sets = np.array([min(_down_set_size(n, int(b)), COUNT_CAP) for b in limits_met.tolist()],
                             dtype=np.int64)[which.ravel()]
    bound = np.minimum(_capped_products(ranks_cap), down_sets).astype(float)
    # chunks of whole rows: a row's combinations are at most MAX_COMBINATIONS_PER_SOLUTION, but one target's rows
    # (16 solutions, or 32 samples of a free joint times 8) may hold millions, so a target may span chunks
    chunk = (np.cumsum(bound) - bound) // _CHUNK_ROWS
    if not len(target):
        edges = np.zeros(1, int)
    elif chunk[-1] == 0:  # one chunk
        edges = np.array([0, len(target)])
    else:
        edges = np.flatnonzero(np.concatenate(([True], chunk[1:] != chunk[:-1], [True])))
    kept_rows, kept_values, kept_keys = [np.zeros(0, dtype=np.int64)], [np.zeros((0, n))], [np.zeros(0)]
    for start, stop in zip(edges[:-1].tolist(), edges[1:].tolist()):
        budget.check("selection")
        owner, turns = _combination_turns(q[start:stop], first[start:stop], last[start:stop], ranks_cap[start:stop],
                                          row_limit[start:stop], reference, weights)
        owner += start
        # the combinations are put in answer order and cut by an index into them (C,), so the joint values
        # (C, n) are gathered once, at the end
        if reference is None:
            cost = np.sum(np.abs(turns), axis=1)
            pick = np.lexsort((cost, owner))  # each row's combinations cheapest first, ties by rank tuple
            key = _position_in_group(owner[pick])  # the row's stream position: the targets take turns between rows
            early = key < row_limit[owner[pick]]
            pick, key = pick[early], key[early]
            picked = owner[pick]
            order = np.lexsort((picked, key, target[picked]))
            pick, key = pick[order], key[order]
            values = None
        else:
            values = q[owner] + _TWO_PI * turns
            distance = _travel(np.abs(values - reference), limits.continuous(robot)) * weights
            cost = distance.max(axis=1) if ordering.norm == "linf" else np.sqrt(np.sum(distance ** 2, axis=1))
            pick = np.lexsort((cost, target[owner]))  # stable: ties by row, then rank tuple
            key = cost[pick]
        first_few = _position_in_group(target[owner[pick]]) < limit
        pick, key = pick[first_few], key[first_few]
        kept_rows.append(owner[pick])
        kept_values.append(q[owner[pick]] + _TWO_PI * turns[pick] if values is None else values[pick])
        kept_keys.append(key)
    if len(kept_rows) == 2:  # one chunk: no copy
        return kept_rows[1], kept_values[1]
    rows, values, keys = np.concatenate(kept_rows), np.concatenate(kept_values), np.concatenate(kept_keys)
    if (target[edges[1:-1]] == target[edges[1:-1] - 1]).any():
        # a target over several chunks: its kept combinations from each, ordered again as one chunk orders them
        # (each chunk's come in row order, so the stable sorts break ties as one chunk would)
        order = np.lexsort((rows, keys, target[rows])) if reference is None else np.lexsort((keys, target[rows]))
        rows, values = rows[order], values[order]
        first_few = _position_in_group(target[rows]) < limit
        rows, values = rows[first_few], values[first_few]
    return rows, values


def _combination_turns(q: np.ndarray, first: np.ndarray, last: np.ndarray, ranks_cap: np.ndarray,
                       row_limit: np.ndarray, reference: np.ndarray | None,
                       weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The turns of the combinations of rows (S,) worth costing: those whose rank tuples r (r_j < ``ranks_cap``)
    have ∏(r_j + 1) ≤ ``row_limit`` (:func:`_rank_tuples`). Returns (row (C,) ascending, turns (C, n)), each
    row's combinations in lexicographic order of their rank tuples.

    ``q``, ``first``, ``last`` (S, n) are the rows' values and usable turns, ``ranks_cap`` (S, n) the most
    ranks of each joint worth enumerating. A row with one usable turn per joint (limits under a whole turn,
    the usual case) has one combination, its ``first`` turns (when every row is such, none is ranked).
    """
    single = np.all(first == last, axis=1) & (row_limit > 0)
    if single.all():
        return np.arange(len(q)), first
    if len(q) <= _FEW_ROWS:  # few rows: all ranked, the single ones keeping their ``first`` turns
        owner, ranks = _rank_tuples(ranks_cap, row_limit)
        if ranks.size <= _FEW_RANKS:  # and few combinations: each one's turns worked out directly
            cheapest, direction, ahead, behind = _ranked_turns(q, first, last, reference, weights)
            turns = cheapest[owner] + _rank_offsets(ranks, direction[owner], ahead[owner], behind[owner])
            return owner, np.where(single[owner, None], first[owner], turns)
    multi = np.flatnonzero(~single)
    caps = ranks_cap[multi]
    cheapest, direction, ahead, behind = _ranked_turns(q[multi], first[multi], last[multi], reference, weights)
    owner, ranks = _rank_tuples(caps, row_limit[multi])
    multi_turns = _tabled_turns(caps, owner, ranks, cheapest, direction, ahead, behind)
    if len(multi) == len(q):
        return owner, multi_turns
    per_row = np.ones(len(q), dtype=np.int64)  # each row's combinations, placed in row order
    per_row[multi] = np.bincount(owner, minlength=len(multi))
    offset = np.cumsum(per_row) - per_row
    turns = np.empty((int(per_row.sum()), q.shape[1]))
    singles = np.flatnonzero(single)
    turns[offset[singles]] = first[singles]
    turns[offset[multi][owner] + _position_in_group(owner)] = multi_turns
    return np.repeat(np.arange(len(q)), per_row), turns


def _tabled_turns(caps: np.ndarray, owner: np.ndarray, ranks: np.ndarray, cheapest: np.ndarray,
                  direction: np.ndarray, ahead: np.ndarray, behind: np.ndarray) -> np.ndarray:
    """The turns (C, n) of the combinations ``ranks`` (C, n) of rows ``owner`` (C,), from the rows' ranked turns
    (S, n each, :func:`_ranked_turns`) and ``caps`` (S, n): as ``cheapest[owner] + _rank_offsets(ranks, …)``, but
    each (row, joint, rank) turn is worked out once (no more of them than combinations), then looked up."""
    table_start = (np.cumsum(caps.ravel()) - caps.ravel()).reshape(caps.shape)
    entry = np.repeat(np.arange(caps.size), caps.ravel())
    rank = np.arange(len(entry)) - table_start.ravel()[entry]
    table = [a.ravel()[entry] for a in (cheapest, direction, ahead, behind)]
    table = table[0] + _rank_offsets(rank, *table[1:])
    return table[table_start[owner] + ranks]


def _ranked_turns(q: np.ndarray, first: np.ndarray, last: np.ndarray, reference: np.ndarray | None,
                  weights: np.ndarray) -> tuple[np.ndarray, ...]:
    """How each joint's usable turns rank by cost |q + 2kπ − r|·w for the reference r (shape (n,)); without
    one, by |k| itself (exact, so equal turning ties exactly). Ties: the lower value first.

    Returns, shape (S, n) each: the cheapest turn, the direction (±1) of the second cheapest, and how many
    turns lie beyond the cheapest in that direction and in the other. The cost grows outwards from the
    cheapest, so the ranks alternate between the two sides until one runs out (:func:`_rank_offsets`).
    """
    if reference is None:
        q = centre = np.zeros(first.shape)
    else:
        centre = reference

    def cost(k):
        return np.abs(q + _TWO_PI * k - centre) * weights

    below = np.floor((centre - q) / _TWO_PI)
    above = below + 1.0
    at_above = cost(above)
    lower_costs_more = at_above < cost(below)
    cheapest = np.where(lower_costs_more, above, below)
    direction = np.where(lower_costs_more | (cost(below - 1.0) <= at_above), -1.0, 1.0)
    indifferent = weights == 0  # every value costs 0: ascending values
    if indifferent.any():
        cheapest, direction = np.where(indifferent, first, cheapest), np.where(indifferent, 1.0, direction)
    direction = np.where(cheapest < first, 1.0, np.where(cheapest > last, -1.0, direction))
    cheapest = np.minimum(np.maximum(cheapest, first), last)
    ahead = np.where(direction > 0, last - cheapest, cheapest - first)
    return cheapest, direction, ahead, (last - first) - ahead


def _rank_offsets(ranks: np.ndarray, direction: np.ndarray, ahead: np.ndarray, behind: np.ndarray) -> np.ndarray:
    """The turn, relative to the cheapest, of a joint's value of rank r (arrays of one shape, see :func:`_ranked_turns`).

    Ranks 1, 2, 3, 4, … go +1, −1, +2, −2, … in ``direction`` while both sides have turns left, then on along the
    side that has.
    """
    r = ranks.astype(float)
    alternating = np.where(np.mod(r, 2.0) == 1.0, direction * (r + 1.0) / 2.0, -direction * r / 2.0)
    one_side = np.where(ahead <= behind, -direction * (r - ahead), direction * (r - behind))
    return np.where(r <= 2.0 * np.minimum(ahead, behind), alternating, one_side)


def _rank_tuples(ranks_cap: np.ndarray, row_limit: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every rank tuple r of each row with r_j < ranks_cap[row, j] and ∏(r_j + 1) ≤ row_limit[row].

    Returns (row (C,), ranks (C, n)), rows ascending and each row's tuples in lexicographic order. A few rows
    of few tuples each (one target's) are looked up row by row (:func:`_row_rank_tuples`).
    """
    if len(ranks_cap) <= _FEW_ROWS:
        caps, limits = ranks_cap.tolist(), row_limit.tolist()
        if all(math.prod(row) * len(row) <= _FEW_RANKS for row in caps):
            per_row = [_row_rank_tuples(tuple(row), limit) for row, limit in zip(caps, limits)]
            owner = np.repeat(np.arange(len(per_row)), [len(ranks) for ranks in per_row])
            return owner, np.concatenate(per_row) if per_row else np.zeros(ranks_cap.shape, dtype=np.int64)
    return _enumerated_rank_tuples(ranks_cap, row_limit)


@functools.lru_cache(maxsize=256)
def _row_rank_tuples(ranks_cap: tuple[int, ...], row_limit: int) -> np.ndarray:
    """:func:`_rank_tuples` of one row, (C, n), read-only: the same caps and limit recur from target to target."""
    ranks = _enumerated_rank_tuples(np.array([ranks_cap], dtype=np.int64), np.array([row_limit]))[1]
    ranks.flags.writeable = False
    return ranks


def _enumerated_rank_tuples(ranks_cap: np.ndarray, row_limit: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_rank_tuples` for any number of rows at once."""
    rows, n = ranks_cap.shape
    owner = np.flatnonzero(np.all(ranks_cap > 0, axis=1) & (row_limit > 0))
    product = np.ones(len(owner), dtype=np.int64)
    levels = []  # per joint: each partial tuple's parent and its rank there
    for j in range(n):
        children = np.minimum(ranks_cap[owner, j], row_limit[owner] // product)
        parent = np.repeat(np.arange(len(owner)), children)
        rank = np.arange(len(parent)) - (np.cumsum(children) - children)[parent]
        owner, product = owner[parent], product[parent] * (rank + 1)
        levels.append((parent, rank))
    ranks = np.zeros((len(owner), n), dtype=np.int64)
    index = np.arange(len(owner))
    for j in range(n - 1, -1, -1):  # back along the parents
        parent, rank = levels[j]
        ranks[:, j] = rank[index]
        index = parent[index]
    return owner, ranks


@functools.lru_cache(maxsize=None)
def _down_set_size(n: int, limit: int) -> int:
    """How many rank tuples of n joints have ∏(r_j + 1) ≤ limit.

    >>> _down_set_size(2, 4)   # (0,0) (0,1) (0,2) (0,3) (1,0) (1,1) (2,0) (3,0)
    8
    """
    if limit < 1:
        return 0
    if n == 0:
        return 1
    total, factor = 0, 1
    while factor <= limit:
        quotient = limit // factor
        same = limit // quotient  # every factor up to this one leaves the same quotient
        total += (same - factor + 1) * _down_set_size(n - 1, quotient)
        factor = same + 1
    return total


def _position_in_group(keys: np.ndarray) -> np.ndarray:
    """0, 1, 2, … within each run of equal values of sorted ``keys``."""
    if len(keys) == 0 or keys[0] == keys[-1]:  # one run
        return np.arange(len(keys))
    index = np.arange(len(keys))
    run_start = np.where(np.concatenate(([True], keys[1:] != keys[:-1])), index, 0)
    return index - np.maximum.accumulate(run_start)


def _capped_products(counts: np.ndarray) -> np.ndarray:
    """∏_j counts[:, j] per row (counts ≥ 0, shape (S, n)), capped at :data:`COUNT_CAP` without overflow, (S,).

    The float product is exact below 2**53: without a zero factor every partial product is a whole number no
    larger than the whole; at or above 2**53 (or past the float range) the cap applies, and a zero factor gives 0.
    """
    factors = np.minimum(counts, COUNT_CAP).astype(float)
    if factors.max(initial=1.0) ** factors.shape[1] < 2.0 ** 53:  # the usual few turns: exact, no cap reached
        return np.prod(factors, axis=1).astype(np.int64)
    with np.errstate(over="ignore", invalid="ignore"):
        product = np.prod(factors, axis=1)
    capped = np.where(product >= 2.0 ** 53, float(COUNT_CAP), product)
    return np.where((factors == 0).any(axis=1), 0.0, capped).astype(np.int64)


def _capped_sums(target: np.ndarray, values: np.ndarray, n_targets: int) -> np.ndarray:
    """Σ values per target (values ≤ COUNT_CAP), capped at :data:`COUNT_CAP`, shape (N,).

    The float sum is exact while it stays below 2**53 (non-negative integers); at or above it the cap applies.
    """
    total = np.bincount(target, weights=values.astype(float), minlength=n_targets)
    return np.where(total >= 2.0 ** 53, COUNT_CAP, total).astype(np.int64)


def _rounds_needed(target: np.ndarray, lengths: np.ndarray, n_targets: int, limit: int) -> np.ndarray:
    """Per target, the rounds of a round robin over its rows' streams (``lengths`` (S,)) that yield ``limit``
    items (all, if fewer), ≥ 1, shape (N,).

    Rounds R yield Y(R) = Σ min(length, R) items. With the streams sorted by length s_0 ≤ s_1 ≤ …, for R in
    (s_{k−1}, s_k] Y(R) = Σ_{i<k} s_i + R·(P − k) (P streams): the smallest R reaching ``limit`` is the smallest
    over those segments of the first R of each that does. R ≤ ``limit``, so longer streams count as ``limit``.
    """
    position = _position_in_group(target)
    streams = np.zeros((n_targets, int(position.max()) + 1 if len(position) else 1), dtype=np.int64)
    streams[target, position] = lengths

    rounds = np.maximum(1, streams.max(axis=1))  # a target whose streams yield fewer than ``limit``: all of them
    capped = np.minimum(streams, limit)
    enough = capped.sum(axis=1) >= limit
    if not enough.any():
        return rounds
    s = np.sort(capped[enough], axis=1)
    shorter = np.cumsum(s, axis=1) - s  # Σ of the streams before each
    segment_start = np.concatenate((np.zeros((len(s), 1), dtype=np.int64), s[:, :-1]), axis=1) + 1
    first_reaching = np.maximum(segment_start, -((shorter - limit) // (s.shape[1] - np.arange(s.shape[1]))))
    rounds[enough] = np.where(first_reaching <= s, first_reaching, limit).min(axis=1)
    return rounds


class TargetNotes(Mapping):
    """The selection's notes: target index → its notes (list of str), for the targets that have any, each
    worded only when read (a batch has thousands; most readers look at a few).

    ``rows`` (k,) ascending are the noted targets; the other arrays (N,) are the per-target counts the notes
    quote: status, rejected, flagged outside the limits, truncated, available, kept, and fitting before
    ``max_joint_move``. ``lowered_to`` is the per-target limit :func:`enumerable_limit` imposed, if any.
    """

    def __init__(self, rows: np.ndarray, status: np.ndarray, rejected: np.ndarray, outside: np.ndarray,
                 truncated: np.ndarray, available: np.ndarray, kept: np.ndarray, with_all_moves: np.ndarray,
                 max_equivalents: int, has_reference: bool, lowered_to: int | None, dof: int) -> None:
        self.rows = rows
        self._columns = (status, rejected, outside, truncated, available, kept, with_all_moves)
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
        status, *counts = self._columns
        status, (rejected, outside, truncated, available, kept, with_all_moves) = (
            status[row], (column[row].item() for column in counts))
        notes = []
        if status == "no_solution_within_limits":
            notes.append(wording["no_fit"].format(rejected=rejected))
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
