""":func:`~service.kinematics.ik._select.select` for a whole batch at once, as arrays.

The common case is computed for all targets together: every solution of the
target has exactly one usable value per joint (no joint with two or more
2π-equivalents within its limits, none outside its limits), and the order,
if any, is the default ``linf`` one. Then each solution is one answer row,
ordered by distance to the reference (ties by solution order, as the lazy
merge of :func:`select` gives) or kept in solution order, filtered by
``max_joint_move`` and cut by ``max_solutions`` / ``max_equivalents``. Every
other target goes through :func:`select` itself, so the answer is always
the per-result one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._budget import UNLIMITED, Budget
from .._limits import Limits
from .._robot import Robot
from ._arrays import IKArrays
from ._select import MAX_EQUIVALENTS, Ordering, Selected, Selection, _notes, check_ordering, joint_travel, select
from ._types import IKResult, Solution

_TWO_PI = 2.0 * np.pi
_FITS = Selected(None, True, [])  # stands for a kept row when counting for the notes


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
    notes: dict[int, list[str]]
    solutions: SolutionTable
    rejected: SolutionTable
    vectorised: int  # how many targets took the array path
    selections: dict[int, Selection]  # the per-result answer of every target that did not


def select_arrays(robot: Robot, arrays: IKArrays, limits: Limits, *, filter_limits: bool = True,
                  reference: np.ndarray | None = None, ordering: Ordering = Ordering(),
                  max_equivalents: int = MAX_EQUIVALENTS, budget: Budget = UNLIMITED) -> BatchSelection:
    """Apply limits, expand 2π-equivalents, order and trim every target's solutions (see the module docstring).

    ``budget`` is checked before the array step and between the targets that go through :func:`select`.
    """
    budget.check("selection")
    check_ordering(robot, ordering, reference)
    n_targets, _, n = arrays.joints.shape
    rows = SolutionTable(
        target=np.repeat(np.arange(n_targets), arrays.count),
        joints=arrays.joints[arrays.valid], within_limits=np.ones(int(arrays.count.sum()), dtype=bool),
        position=arrays.position[arrays.valid], orientation=arrays.orientation[arrays.valid],
        labels={name: (values, codes[arrays.valid]) for name, (values, codes) in arrays.labels.items()})
    values, single = _single_values(robot, limits, rows.joints)
    per_target_single = np.bincount(rows.target, weights=~single, minlength=n_targets) == 0
    simple = per_target_single
    if reference is not None and ordering.norm != "linf":
        simple &= arrays.count == 0  # the l2 cost is summed with math.fsum there: leave its order to select()
    fast = simple[rows.target]
    kept = rows.take(np.flatnonzero(fast))
    kept.joints = values[fast]
    with_all_moves = np.bincount(kept.target, minlength=n_targets)
    if reference is not None:
        travel_ = joint_travel(robot, limits, kept.joints, reference)
        if ordering.max_joint_move is not None:
            near = np.all(travel_ <= ordering.max_joint_move + limits.tolerance(robot), axis=1)
            kept, travel_ = kept.take(np.flatnonzero(near)), travel_[near]
        cost = (travel_ * ordering.weights if ordering.weights is not None else travel_).max(axis=1)
        order = np.lexsort((cost, kept.target))
        kept = kept.take(order)
    available = np.bincount(kept.target, minlength=n_targets)
    limit = max_equivalents if ordering.max_solutions is None else min(max_equivalents, ordering.max_solutions)
    starts = np.searchsorted(kept.target, np.arange(n_targets))
    rank = np.arange(len(kept.target)) - starts[kept.target]
    kept = kept.take(np.flatnonzero(rank < limit))
    count = np.bincount(kept.target, minlength=n_targets)
    capped = ordering.max_solutions is not None and ordering.max_solutions <= max_equivalents
    truncated = (available > count) & (not capped)
    trimmed = with_all_moves - available + ((available - count) if capped else 0)
    status = np.where(arrays.count == 0, "unreachable", "ok").astype(object)
    notes: dict[int, list[str]] = {}
    for row in np.flatnonzero(simple & (arrays.count > 0) & (truncated | (count == 0))).tolist():
        notes[row] = _notes(Selection(status[row], [_FITS] * int(count[row]), [], bool(truncated[row]),
                                      int(trimmed[row]), int(available[row])),
                            int(with_all_moves[row]), max_equivalents, reference is not None)
    kept_parts, rejected_parts = [kept], []
    selections: dict[int, Selection] = {}
    for row in np.flatnonzero(~simple).tolist():
        selection = selections[row] = select(robot, _result(arrays, row), limits, filter_limits=filter_limits,
                                             reference=reference, ordering=ordering,
                                             max_equivalents=max_equivalents, budget=budget)
        status[row], truncated[row], trimmed[row], available[row] = (
            selection.status, selection.expansion_truncated, selection.trimmed, selection.available)
        if selection.notes:
            notes[row] = selection.notes
        kept_parts.append(_table(row, selection.solutions, rows.labels, n))
        rejected_parts.append(_table(row, selection.rejected, rows.labels, n))
    solutions = _by_target(SolutionTable.concatenate(kept_parts, n)) if len(kept_parts) > 1 else kept
    rejected = _by_target(SolutionTable.concatenate(rejected_parts, n)) if rejected_parts else rows.take(
        np.zeros(0, dtype=int))
    return BatchSelection(status, truncated, trimmed, available, notes, solutions, rejected, int(simple.sum()),
                          selections)


def _single_values(robot: Robot, limits: Limits, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each row's joint values moved into the limits, and whether every joint of it has exactly one usable value.

    The rules of :func:`.._limits.turn_offsets`: a joint with both bounds finite takes q + 2kπ inside them, a
    joint bounded on one side the one q + 2kπ inside nearest q, any other joint q itself if it is inside.
    """
    tolerance = limits.tolerance(robot)
    lower, upper = limits.lower - tolerance, limits.upper + tolerance
    both = robot.is_revolute & np.isfinite(lower) & np.isfinite(upper)
    one_sided = robot.is_revolute & ~both & (np.isfinite(lower) | np.isfinite(upper))
    with np.errstate(invalid="ignore"):
        first = np.ceil((lower - q) / _TWO_PI)
        last = np.floor((upper - q) / _TWO_PI)
        up = q + _TWO_PI * np.ceil((lower - q) / _TWO_PI)
        down = q - _TWO_PI * np.ceil((q - upper) / _TWO_PI)
    values = np.where(both, q + _TWO_PI * first, q)
    values = np.where(one_sided & (q < lower), up, np.where(one_sided & (q > upper), down, values))
    inside = (values >= lower) & (values <= upper)
    single = inside & np.where(both, last == first, True)
    return values, single.all(axis=1)


def _result(arrays: IKArrays, row: int) -> IKResult:
    """Target ``row`` of the arrays as an IKResult (the per-result selection's input)."""
    count = int(arrays.count[row])
    solutions = [Solution(arrays.joints[row, s], {name: values[codes[row, s]]
                                                  for name, (values, codes) in arrays.labels.items()
                                                  if codes[row, s] >= 0},
                          float(arrays.position[row, s]), float(arrays.orientation[row, s])) for s in range(count)]
    return IKResult("ok" if count else "unreachable", solutions, "analytic", arrays.structure, True)


def _table(row: int, entries, labels: dict[str, tuple[tuple, np.ndarray]], dof: int) -> SolutionTable:
    n = len(entries)
    codes = {name: (values, np.array([values.index(e.solution.branch[name]) if name in e.solution.branch else -1
                                      for e in entries], dtype=np.int8)) for name, (values, _) in labels.items()}
    return SolutionTable(np.full(n, row), np.array([e.solution.joints for e in entries]).reshape(n, dof),
                         np.array([e.within_limits for e in entries], dtype=bool),
                         np.array([e.solution.position_residual for e in entries], dtype=float),
                         np.array([e.solution.orientation_residual for e in entries], dtype=float), codes)


def _by_target(table: SolutionTable) -> SolutionTable:
    return table.take(np.argsort(table.target, kind="stable"))
