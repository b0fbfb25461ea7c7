"""From verified solutions to the answer: joint limits, 2π-equivalents, ordering and trimming.

* Every solution is expanded into each 2π-equivalent that fits the limits of
  joints with finite bounds (a ±360° joint has two of most angles), up to a cap.
* ``filter_limits`` moves solutions with no fitting equivalent to ``rejected``,
  each with its violations.
* With a reference, solutions are ordered nearest first. A joint with finite
  limits is measured by its actual travel (its equivalents are different
  physical positions); a continuous joint across the 2π wrap.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from .._limits import Limits, Violation, fitting_equivalents, violations
from .._robot import Robot
from ._types import IKResult, Solution
from ._verify import wrap_revolute

Norm = Literal["linf", "l2"]


@dataclass(frozen=True)
class Selected:
    solution: Solution
    within_limits: bool
    violations: list[Violation]


@dataclass
class Selection:
    status: Literal["ok", "unreachable", "no_solution_within_limits"]
    solutions: list[Selected]
    rejected: list[Selected]
    expansion_truncated: bool = False
    trimmed: int = 0  # solutions left out by max_solutions / max_joint_move
    notes: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class Ordering:
    """How to rank solutions against a reference."""

    norm: Norm = "linf"
    weights: np.ndarray | None = None
    max_solutions: int | None = None
    max_joint_move: float | None = None


def travel(robot: Robot, limits: Limits, q: np.ndarray, reference: np.ndarray, ordering: Ordering) -> np.ndarray:
    """Distance of each row of q (k, n) from the reference, shape (k,)."""
    difference = np.asarray(q) - reference
    continuous = robot.is_revolute & ~(np.isfinite(limits.lower) & np.isfinite(limits.upper))
    difference = np.where(continuous, wrap_revolute(robot, difference), difference)
    difference = np.abs(difference)
    if ordering.weights is not None:
        difference = difference * ordering.weights
    return difference.max(axis=-1) if ordering.norm == "linf" else np.linalg.norm(difference, axis=-1)


def select(robot: Robot, result: IKResult, limits: Limits, *, filter_limits: bool = True,
           reference: np.ndarray | None = None, ordering: Ordering = Ordering(),
           max_equivalents: int = 1024) -> Selection:
    """Apply limits, expand equivalents, order and trim the solutions of one IK result."""
    if result.status == "unreachable":
        return Selection("unreachable", [], [])
    kept: list[Selected] = []
    rejected: list[Selected] = []
    truncated = False
    for solution in result.solutions:
        budget = max(max_equivalents - len(kept), 1)
        equivalents, cut = fitting_equivalents(robot, limits, solution.joints, budget)
        truncated |= cut
        if len(equivalents):
            kept.extend(Selected(_with_joints(solution, q), True, []) for q in equivalents)
        else:
            entry = Selected(solution, False, violations(robot, limits, solution.joints))
            (rejected if filter_limits else kept).append(entry)
        if len(kept) >= max_equivalents:
            truncated |= solution is not result.solutions[-1]
            break
    selection = Selection("ok" if kept else "no_solution_within_limits", kept, rejected, truncated)
    if reference is not None:
        _order(robot, limits, selection, reference, ordering)
    if truncated:
        selection.notes.append(f"more than {max_equivalents} solutions fit the limits; the list was cut")
    return selection


def _with_joints(solution: Solution, q: np.ndarray) -> Solution:
    return Solution(q, solution.branch, solution.position_residual, solution.orientation_residual, solution.singular)


def _order(robot: Robot, limits: Limits, selection: Selection, reference: np.ndarray, ordering: Ordering) -> None:
    for name in ("solutions", "rejected"):
        entries = getattr(selection, name)
        if not entries:
            continue
        distance = travel(robot, limits, np.array([e.solution.joints for e in entries]), reference, ordering)
        order = np.argsort(distance, kind="stable")
        entries = [entries[i] for i in order]
        if name == "solutions":
            before = len(entries)
            if ordering.max_joint_move is not None:
                entries = [e for e, d in zip(entries, distance[order]) if d <= ordering.max_joint_move]
            if ordering.max_solutions is not None:
                entries = entries[: ordering.max_solutions]
            selection.trimmed = before - len(entries)
        setattr(selection, name, entries)
