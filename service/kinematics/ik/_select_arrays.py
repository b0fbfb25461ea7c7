""":func:`~service.kinematics.ik._select.select` for a whole batch at once, as arrays.

Same rules as the per-result version (limits, 2π-equivalents in
``itertools.product`` order, ``filter_limits``, reference order, trimming),
computed for every target together. A target where the ``max_equivalents``
cap would cut the list takes the per-result path, so the cut falls exactly
where :func:`select` puts it; that needs more than ``max_equivalents``
solutions for one target and is rare.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._limits import Limits
from .._robot import Robot
from ._arrays import IKArrays
from ._select import Ordering, Selection, select, travel
from ._types import IKResult, Solution

_TWO_PI = 2.0 * np.pi


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
    notes: dict[int, list[str]]
    solutions: SolutionTable
    rejected: SolutionTable


def select_arrays(robot: Robot, arrays: IKArrays, limits: Limits, *, filter_limits: bool = True,
                  reference: np.ndarray | None = None, ordering: Ordering = Ordering(),
                  max_equivalents: int = 1024) -> BatchSelection:
    """Apply limits, expand 2π-equivalents, order and trim every target's solutions, vectorised over targets."""
    n_targets, _, n = arrays.joints.shape
    rows = SolutionTable(
        target=np.repeat(np.arange(n_targets), arrays.count),
        joints=arrays.joints[arrays.valid], within_limits=np.ones(int(arrays.count.sum()), dtype=bool),
        position=arrays.position[arrays.valid], orientation=arrays.orientation[arrays.valid],
        labels={name: (values, codes[arrays.valid]) for name, (values, codes) in arrays.labels.items()})
    # each joint's 2π-equivalents that fit: first turn and how many (revolute joints with both bounds finite)
    tolerance = limits.tolerance(robot)
    lower, upper = limits.lower - tolerance, limits.upper + tolerance
    expands = robot.is_revolute & np.isfinite(lower) & np.isfinite(upper)
    q = rows.joints
    with np.errstate(invalid="ignore"):
        first = np.where(expands, np.ceil((lower - q) / _TWO_PI), 0.0)
        last = np.where(expands, np.floor((upper - q) / _TWO_PI), 0.0)
    options = np.maximum(last - first + 1, 0).astype(np.int64)  # (S, n)
    total = np.prod(options, axis=1)
    fits = total > 0
    kept_count = np.where(fits, total, 0 if filter_limits else 1)
    # targets where the cap cuts the list go through the per-result path
    per_target = np.bincount(rows.target, weights=kept_count, minlength=n_targets)
    last_row = np.cumsum(arrays.count) - 1
    last_kept = kept_count[np.maximum(last_row, 0)] if len(kept_count) else np.zeros(n_targets)
    before_last = per_target - np.where(arrays.count > 0, last_kept, 0)
    exact = (per_target <= max_equivalents) & (before_last < max_equivalents)
    simple_rows = exact[rows.target]

    # kept: every fitting equivalent, in product order; a solution with none stays as it is unless filtered
    source = np.flatnonzero(simple_rows)
    repeats = kept_count[source]
    expanded = np.repeat(source, repeats)
    local = np.arange(len(expanded)) - np.repeat(np.cumsum(repeats) - repeats, repeats)
    joints = q[expanded].copy()
    fitting = fits[expanded]
    for j in reversed(range(n)):
        if not expands[j]:
            continue
        count = np.where(fitting, options[expanded, j], 1)
        turn = np.where(fitting, first[expanded, j] + local % count, 0.0)
        local = local // count
        joints[:, j] += _TWO_PI * turn
    kept = rows.take(expanded)
    kept.joints = joints
    kept.within_limits = fitting
    rejected = rows.take(np.flatnonzero(simple_rows & ~fits)) if filter_limits else rows.take(np.zeros(0, int))
    rejected.within_limits = np.zeros(len(rejected.target), dtype=bool)

    status = np.where(arrays.count == 0, "unreachable",
                      np.where(np.bincount(kept.target, minlength=n_targets) > 0, "ok",
                               "no_solution_within_limits")).astype(object)
    trimmed = np.zeros(n_targets, dtype=int)
    if reference is not None:
        kept, trimmed = _order(robot, limits, kept, reference, ordering, n_targets, trim=True)
        rejected, _ = _order(robot, limits, rejected, reference, ordering, n_targets, trim=False)
    truncated = np.zeros(n_targets, dtype=bool)
    notes: dict[int, list[str]] = {}

    hard = np.flatnonzero(~exact & (arrays.count > 0))
    if len(hard):
        kept_parts, rejected_parts = [kept], [rejected]
        for row in hard.tolist():
            selection = select(robot, _result(arrays, row), limits, filter_limits=filter_limits,
                               reference=reference, ordering=ordering, max_equivalents=max_equivalents)
            status[row], truncated[row], trimmed[row] = (selection.status, selection.expansion_truncated,
                                                         selection.trimmed)
            if selection.notes:
                notes[row] = selection.notes
            kept_parts.append(_table(row, selection.solutions, rows.labels, n))
            rejected_parts.append(_table(row, selection.rejected, rows.labels, n))
        kept, rejected = (_by_target(SolutionTable.concatenate(parts, n)) for parts in (kept_parts, rejected_parts))
    return BatchSelection(status, truncated, trimmed, notes, kept, rejected)


def _order(robot: Robot, limits: Limits, table: SolutionTable, reference: np.ndarray, ordering: Ordering,
           n_targets: int, *, trim: bool) -> tuple[SolutionTable, np.ndarray]:
    """Nearest first within each target (stable), then max_joint_move and max_solutions."""
    trimmed = np.zeros(n_targets, dtype=int)
    if not len(table.target):
        return table, trimmed
    distance = travel(robot, limits, table.joints, reference, ordering)
    order = np.lexsort((distance, table.target))
    table, distance = table.take(order), distance[order]
    if not trim:
        return table, trimmed
    keep = np.ones(len(table.target), dtype=bool)
    if ordering.max_joint_move is not None:
        keep &= distance <= ordering.max_joint_move
    if ordering.max_solutions is not None:
        starts = np.searchsorted(table.target[keep], np.arange(n_targets))
        rank = np.zeros(len(table.target), dtype=int)
        rank[keep] = np.arange(keep.sum()) - starts[table.target[keep]]
        keep &= rank < ordering.max_solutions
    trimmed = np.bincount(table.target, minlength=n_targets) - np.bincount(table.target[keep], minlength=n_targets)
    return table.take(np.flatnonzero(keep)), trimmed


def _result(arrays: IKArrays, row: int) -> IKResult:
    """Target ``row`` of the arrays as an IKResult (the per-result selection's input)."""
    count = int(arrays.count[row])
    solutions = [Solution(arrays.joints[row, s], {name: values[codes[row, s]]
                                                  for name, (values, codes) in arrays.labels.items()},
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
