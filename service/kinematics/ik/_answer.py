"""One IK answer for a batch of targets of any kinds, built once: solve, fall back, select, as columns.

:func:`answer_ik` splits the targets by kind (full pose, position only,
position + tool direction), solves each kind with its closed form (the free
joints of a redundant arm over their values), sends the targets no closed form
covers or promises to the numeric search, and retries position-only targets
that joints held at the reference could not reach. Every row, analytic or
numeric, then goes through :func:`select_arrays` into the same two tables.
The answer's per-target fields are arrays (N,); solver and singularity reports
are numbered by first appearance in target order.
"""

from __future__ import annotations

import operator
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._budget import UNLIMITED, Budget
from .._errors import InvalidInputError, KinematicsError
from .._limits import Limits
from .._robot import Robot
from ._arrays import IKArrays, arrays_from_results, cached_plan, plan_is_kept, solve_ik_arrays
from ._direction import solve_direction
from ._position_search import search_position
from ._redundant import (FreeJoint, beyond_reach, free_joint_solutions, free_joints_for, no_solution_detail,
                         solve_free_joint_family)
from ._select import MAX_EQUIVALENTS, NOTE_WORDING, BatchSelection, Ordering, SolutionTable, select_arrays
from ._solve import IKOptions, solve_ik_batch, unreachable_details
from ._types import IKResult, Singularity

#: Target kinds (:attr:`IKTargets.kinds`).
POSITION, POSE, DIRECTION = 0, 1, 2


class UnsupportedTargetError(KinematicsError):
    """No closed-form family solves this kind of target for this arm (position + tool direction)."""


@dataclass(frozen=True)
class IKTargets:
    """N targets in the world frame.

    ``matrices`` (N, 4, 4) ``world_T_tool``: for a position-only or a
    direction target only the position (last column) counts. ``kinds`` (N,)
    int: :data:`POSE`, :data:`POSITION` or :data:`DIRECTION`. For direction
    rows, ``tool_axes`` (N, 3) is the unit tool axis (tool frame) and
    ``world_directions`` (N, 3) the unit direction it must point along (world
    frame); other rows of them are ignored.
    """

    matrices: np.ndarray
    kinds: np.ndarray
    tool_axes: np.ndarray | None = None
    world_directions: np.ndarray | None = None

    @classmethod
    def poses(cls, world_T_targets: np.ndarray, *, constrain_orientation: bool = True) -> "IKTargets":
        """Targets (N, 4, 4) all of one kind: full poses, or (``constrain_orientation`` false) positions."""
        matrices = np.asarray(world_T_targets, dtype=float)
        return cls(matrices, np.full(len(matrices), POSE if constrain_orientation else POSITION))


@dataclass(frozen=True)
class AnswerOptions:
    """How to answer: reference (n,) and limits in radians / length units, the selection's options, the
    requested free joints of a redundant arm (``(joint, values or None, samples or None)`` entries, see
    :func:`free_joints_for`), the numeric search's bounds and the request's budget."""

    reference: np.ndarray | None = None
    limits: Limits | None = None  # default: the robot's own
    filter_limits: bool = True
    ordering: Ordering = Ordering()
    max_equivalents: int = MAX_EQUIVALENTS
    search: IKOptions = field(default_factory=IKOptions)
    free_joints: list[tuple[int, list[float] | None, int | None]] | None = None
    budget: Budget = UNLIMITED


@dataclass(frozen=True)
class SolverReport:
    """Which solver answered a target, and what it promises."""

    method: str
    structure: str
    complete: bool
    time_budget_exhausted: bool
    free_joints: tuple[int, ...]


@dataclass(frozen=True)
class SolveTiming:
    """One solver call: its method and structure, its duration (s) and each of its targets' solution count."""

    method: str
    structure: str
    seconds: float
    solutions_per_target: list[int]


class PerTarget(Sequence):
    """A per-target column of Python values (N,), each made when read by ``entry(index)``: a batch has
    thousands of targets, and most readers look at a few (``list(column)`` makes them all)."""

    def __init__(self, length: int, entry: Callable[[int], Any]) -> None:
        self._length, self._entry = length, entry

    def __len__(self) -> int:
        return self._length

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self._entry(i) for i in range(*index.indices(self._length))]
        index = operator.index(index)
        if not -self._length <= index < self._length:
            raise IndexError(index)
        return self._entry(index % self._length)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Sequence) and list(self) == list(other)

    __hash__ = None

    def __repr__(self) -> str:
        return f"PerTarget({list(self)!r})"


@dataclass
class TargetAnswer:
    """One target's answer (a view of :class:`IKAnswer`): its fields and its rows of the two tables."""

    status: str
    detail: str | None
    solver: SolverReport
    singularities: list[Singularity]
    truncated: bool
    trimmed: int
    available: int
    solutions: SolutionTable
    rejected: SolutionTable


@dataclass
class IKAnswer:
    """The answer for N targets, as columns.

    Per target (N,): ``status`` (object: "ok", "unreachable",
    "no_solution_within_limits"), ``detail`` (str or None, worded when
    read), ``solver`` (index into ``solvers``), ``singularities`` (lists of
    indices into ``singularity_reports``, made when read), ``truncated``, ``trimmed``,
    ``available``. ``solutions`` and ``rejected`` hold the rows grouped by
    target, joints in radians / length units; a position-only target's
    orientation residuals are NaN. ``solution_violations`` (S, n) and
    ``rejected_violations`` (R, n) say which joints of a row outside the
    ``limits`` break them. ``timings`` lists the solver calls.
    """

    status: np.ndarray
    detail: PerTarget  # of str | None
    solver: np.ndarray
    solvers: list[SolverReport]
    singularities: PerTarget  # of list[int]
    singularity_reports: list[Singularity]
    truncated: np.ndarray
    trimmed: np.ndarray
    available: np.ndarray
    solutions: SolutionTable
    rejected: SolutionTable
    solution_violations: np.ndarray
    rejected_violations: np.ndarray
    limits: Limits
    timings: list[SolveTiming]
    detail_of: Callable[[int, Mapping[str, str]], str | None] = field(default=lambda row, wording: None,
                                                                      repr=False, compare=False)

    def __len__(self) -> int:
        return len(self.status)

    def details(self, wording: Mapping[str, str] = NOTE_WORDING) -> PerTarget:
        """Each target's detail (str or None), the selection's notes in ``wording``: the keys and fields of
        :data:`NOTE_WORDING`, a boundary's words for the options (``detail`` reads in the core's)."""
        return PerTarget(len(self), lambda row: self.detail_of(row, wording))

    def target(self, index: int) -> TargetAnswer:
        """Target ``index``'s answer as one object (its table rows sliced out, nothing recomputed)."""
        def rows(table: SolutionTable) -> SolutionTable:
            start, stop = np.searchsorted(table.target, [index, index + 1])
            return table.take(np.arange(start, stop))
        return TargetAnswer(str(self.status[index]), self.detail[index], self.solvers[int(self.solver[index])],
                            [self.singularity_reports[i] for i in self.singularities[index]],
                            bool(self.truncated[index]), int(self.trimmed[index]), int(self.available[index]),
                            rows(self.solutions), rows(self.rejected))


@dataclass
class _Solved:
    """Solved rows of one kind: ``rows`` (k,) target indices and their solutions; ``solver`` (k,) indexes
    ``solvers``. Only the rows that have them appear in ``details`` (put before the selection's notes),
    ``remarks`` (after them) and ``singularities`` (local row → its singular conditions)."""

    rows: np.ndarray
    arrays: IKArrays
    solvers: list[SolverReport]
    solver: np.ndarray
    details: dict[int, str]
    singularities: dict[int, list[Singularity]]
    constrained: bool  # whether the orientation residual means something (pose and direction rows)
    remarks: dict[int, str] = field(default_factory=dict)
    chosen: BatchSelection | None = None  # the selection of its rows, once made


def answer_ik(robot: Robot, targets: IKTargets, options: AnswerOptions = AnswerOptions()) -> IKAnswer:
    """Every solution of each target, selected against the limits (see the module docstring)."""
    matrices, kinds = np.asarray(targets.matrices, dtype=float), np.asarray(targets.kinds)
    limits = Limits.of(robot) if options.limits is None else options.limits
    free = None
    if options.free_joints is not None or robot.dof > 6:
        with _at_free_joints():
            free = free_joints_for(robot, options.free_joints)
    timings: list[SolveTiming] = []
    solved = [*_solved_directions(robot, targets, options, timings),
              *_solved_poses(robot, matrices, kinds, free, options, timings)]
    answer = _selected(robot, len(matrices), solved, limits, options, timings)
    retry = [row for row in np.flatnonzero((kinds == POSITION) & (answer.status == "unreachable")).tolist()
             if answer.solvers[answer.solver[row]].free_joints
             and answer.solvers[answer.solver[row]].method == "analytic"]
    if retry:  # held joints must not make a reachable point unreachable: search every joint
        results = [search_position(robot, matrices[row], list(answer.solvers[answer.solver[row]].free_joints),
                                   options.reference, options.search) for row in retry]
        solved.append(_from_results(robot, np.array(retry), results, False))
        answer = _selected(robot, len(matrices), solved, limits, options, timings)
    return answer


def solutions_per_target(robot: Robot, kinds: np.ndarray, free_joints: list | None, refined: bool
                         ) -> tuple[int, bool]:
    """The cost model's count, before any solving: the most solutions a target of ``kinds`` (N,) can have in
    closed form (its plan's generic count; a redundant arm's over its free values, see
    :func:`free_joint_solutions`), and whether some kind goes to the numeric search instead (its starts count).
    ``free_joints`` and ``refined`` (a reference is given) are :class:`AnswerOptions`'."""
    most, numeric = 0, False
    for constrained in np.unique(np.asarray(kinds) > 0).tolist():
        # a position-only plan holding joints at the reference has the generic count of the kept one
        plan = cached_plan(robot, constrain_orientation=constrained, reference=None)
        count = None if plan is None else plan.generic_count
        if plan is None and constrained and robot.dof > 6:
            with _at_free_joints():
                count = free_joint_solutions(robot, free_joints, refined)
        most, numeric = (most, True) if count is None else (max(most, count), numeric)
    return most, numeric


def plans_are_kept(robot: Robot, kinds: np.ndarray, reference: np.ndarray | None) -> bool:
    """Whether the plans that targets of ``kinds`` (N,) need are already built and kept on the robot, so that
    neither :func:`solutions_per_target` nor :func:`answer_ik` derives one (False for direction targets, whose
    families are chosen per tool axis)."""
    kinds = np.asarray(kinds)
    if (kinds == DIRECTION).any():
        return False
    return all(plan_is_kept(robot, constrain_orientation=constrained, reference=reference)
               for constrained in np.unique(kinds == POSE).tolist())


@contextmanager
def _at_free_joints() -> Iterator[None]:
    """Locate the errors about the free joints at the option that asks for them (``free_joints``)."""
    try:
        yield
    except InvalidInputError as error:
        raise error.relocated("free_joints") from None


def _solved_directions(robot: Robot, targets: IKTargets, options: AnswerOptions, timings: list[SolveTiming]):
    """Position + direction targets, one closed-form solve per tool axis."""
    directions = np.flatnonzero(np.asarray(targets.kinds) == DIRECTION)
    if not len(directions):
        return
    axes, group = np.unique(np.asarray(targets.tool_axes)[directions], axis=0, return_inverse=True)
    for number in range(len(axes)):
        rows = directions[group.reshape(-1) == number]
        started = time.perf_counter()
        arrays = solve_direction(robot, targets.matrices[rows, :3, 3], targets.world_directions[rows], axes[number],
                                 options.reference)
        if arrays is None:
            raise UnsupportedTargetError("no closed-form family covers position + tool direction targets of this "
                                         "arm with this tool axis")
        timings.append(SolveTiming("analytic", arrays.structure, time.perf_counter() - started,
                                   arrays.count.tolist()))
        positions = targets.matrices[rows, :3, 3]
        details = {local: _direction_detail(robot, positions[local]) for local in np.flatnonzero(arrays.count == 0)}
        yield _from_arrays(arrays, rows, details, True)


def _direction_detail(robot: Robot, position: np.ndarray) -> str:
    if bool(beyond_reach(robot, position)):
        return "The target position is outside the workspace (farther from the base than the arm can reach)."
    return ("No joint vector puts the tool at this position with its axis along the direction (every solution of "
            "the closed form was checked).")


def _solved_poses(robot: Robot, matrices: np.ndarray, kinds: np.ndarray, free: list[FreeJoint] | None,
                  options: AnswerOptions, timings: list[SolveTiming]):
    """Full-pose then position-only targets: the closed form where it covers and promises, else the fallback."""
    reference = options.reference
    for kind in (POSE, POSITION):
        rows = np.flatnonzero(kinds == kind)
        if not len(rows):
            continue
        constrained = kind == POSE
        started = time.perf_counter()
        if constrained and free is not None:  # a redundant arm: the family over the free joints' values
            with _at_free_joints():
                family = solve_free_joint_family(robot, matrices[rows], free, reference, budget=options.budget)
            if family is None:
                yield _numeric(robot, matrices, rows, True, options, timings, started, free)
                continue
            arrays = family.arrays
            timings.append(SolveTiming("analytic", arrays.structure, time.perf_counter() - started,
                                       arrays.count.tolist()))
            details = {local: no_solution_detail(robot, free, matrices[rows[local], :3, 3])
                       for local in np.flatnonzero(arrays.count == 0).tolist()}
            part = _from_arrays(arrays, rows, details, True)
            missing = family.missing > 0  # the answer is not complete at those values
            part.solver[missing] += len(part.solvers)
            part.solvers += [SolverReport(**{**vars(report), "complete": False}) for report in part.solvers]
            part.remarks = {local: f"At {family.missing[local]} of the free values the locked arm falls outside "
                                   f"the closed-form family, so no solution is listed there."
                            for local in np.flatnonzero(missing).tolist()}
            yield part
            continue
        arrays = solve_ik_arrays(robot, matrices[rows], constrain_orientation=constrained, reference=reference,
                                 budget=options.budget)
        if arrays is None:
            yield _numeric(robot, matrices, rows, constrained, options, timings, started)
            continue
        timings.append(SolveTiming("analytic", arrays.structure, time.perf_counter() - started,
                                   arrays.count.tolist()))
        promised = np.flatnonzero(arrays.complete)
        if len(promised) < len(rows):  # rounded geometry: the closed form cannot promise these, the fallback answers
            arrays = arrays.take(promised)
        if len(promised):
            unreachable = unreachable_details(robot, arrays, matrices[rows[promised]], constrained, reference,
                                              options.budget)
            yield _from_arrays(arrays, rows[promised], unreachable, constrained)
        if len(promised) < len(rows):
            yield _numeric(robot, matrices, rows[~np.isin(np.arange(len(rows)), promised)], constrained, options,
                           timings, time.perf_counter())


def _numeric(robot: Robot, matrices: np.ndarray, rows: np.ndarray, constrained: bool, options: AnswerOptions,
             timings: list[SolveTiming], started: float, free: list[FreeJoint] | None = None) -> _Solved:
    """The fallback's answer for ``rows``: :func:`solve_ik_batch` (the numeric search where no closed form
    covers or promises). On a redundant arm whose locked arm no family covers, says the free joints were not
    applied."""
    results = solve_ik_batch(robot, matrices[rows], constrain_orientation=constrained, reference=options.reference,
                             options=options.search)
    timings.append(SolveTiming(results[0].method, results[0].structure, time.perf_counter() - started,
                               [len(result.solutions) for result in results]))
    part = _from_results(robot, rows, results, constrained)
    if free is not None:
        names = ", ".join(f"q{f.joint + 1}" for f in free)
        note = (f"No closed-form family covers this arm with {names} locked, so the free joints were not applied: "
                f"a numeric search over every joint answered.")
        part.remarks = dict.fromkeys(range(len(rows)), note)
    return part


def _from_arrays(arrays: IKArrays, rows: np.ndarray, details: dict[int, str], constrained: bool) -> _Solved:
    """Closed-form rows: one solver (complete, or not where the family cannot promise it), each row's singular
    conditions where it has a solution."""
    solvers = [SolverReport("analytic", arrays.structure, promise, False, tuple(arrays.free_joints))
               for promise in (True, False)]
    solved = arrays.count > 0
    singularities: dict[int, list[Singularity]] = {}
    for mask, flag in arrays.singularities.entries:
        for local in np.flatnonzero(mask & solved).tolist():
            met = singularities.setdefault(local, [])
            if flag not in met:
                met.append(flag)
    return _Solved(rows, arrays, solvers, (~arrays.complete).astype(int), details, singularities, constrained)


def _from_results(robot: Robot, rows: np.ndarray, results: list[IKResult], constrained: bool) -> _Solved:
    """Rows answered as :class:`IKResult` records (the fallback, the position search), as arrays."""
    solvers, solver = _numbered([SolverReport(r.method, r.structure, r.complete, r.search_exhausted_budget,
                                              tuple(r.free_joints)) for r in results])
    return _Solved(rows, arrays_from_results(robot, results), solvers, solver,
                   {local: r.detail for local, r in enumerate(results) if r.detail},
                   {local: list(r.singularities) for local, r in enumerate(results) if r.singularities}, constrained)


def _selected(robot: Robot, n_targets: int, parts: list[_Solved], limits: Limits, options: AnswerOptions,
              timings: list[SolveTiming]) -> IKAnswer:
    """Select every part's rows (once: a part keeps its selection) and gather them into one answer; a later
    part's rows replace an earlier part's answer for the same targets (the position search after an unreachable
    held-joint solve)."""
    status = np.empty(n_targets, dtype=object)
    solver_of, reports_of = np.zeros(n_targets, dtype=int), []  # index into every part's solvers, in part order
    singular_of: dict[int, list[Singularity]] = {}
    truncated, trimmed = np.zeros(n_targets, dtype=bool), np.zeros(n_targets, dtype=int)
    available = np.zeros(n_targets, dtype=int)
    kept_parts, rejected_parts = [], []
    owner, local_of = np.full(n_targets, -1), np.zeros(n_targets, dtype=int)
    for number, part in enumerate(parts):
        owner[part.rows], local_of[part.rows] = number, np.arange(len(part.rows))
    for number, part in enumerate(parts):
        live = owner[part.rows] == number
        if not live.any():
            continue
        if part.chosen is None:
            part.chosen = select_arrays(robot, part.arrays, limits, filter_limits=options.filter_limits,
                                        reference=options.reference, ordering=options.ordering,
                                        max_equivalents=options.max_equivalents, budget=options.budget)
        chosen = part.chosen
        rows = part.rows
        status[rows[live]], truncated[rows[live]] = chosen.status[live], chosen.truncated[live]
        trimmed[rows[live]], available[rows[live]] = chosen.trimmed[live], chosen.available[live]
        solver_of[rows[live]] = part.solver[live] + len(reports_of)
        reports_of += part.solvers
        for local, met in part.singularities.items():
            if live[local]:
                singular_of[int(rows[local])] = met
        for table, into in ((chosen.solutions, kept_parts), (chosen.rejected, rejected_parts)):
            if not live.all():
                table = table.take(np.flatnonzero(live[table.target]))
            table = SolutionTable(rows[table.target], table.joints, table.within_limits, table.position,
                                  table.orientation if part.constrained else np.full(len(table.target), np.nan),
                                  table.labels)
            into.append(table)
    distinct, same = _numbered(reports_of)  # equal reports of different parts are one
    by_appearance = list(dict.fromkeys(same[solver_of].tolist()))  # number them by first appearance in target order
    renumber = np.zeros(len(distinct), dtype=int)
    renumber[by_appearance] = np.arange(len(by_appearance))
    solvers, solver = [distinct[i] for i in by_appearance], renumber[same[solver_of]]
    singular_rows = sorted(singular_of)  # only the targets that meet a condition, in target order
    reports, numbered = _numbered_lists([singular_of[row] for row in singular_rows])
    numbered_of = dict(zip(singular_rows, numbered))
    singularities = PerTarget(n_targets, lambda row: list(numbered_of.get(row, ())))

    def detail_of(row: int, wording: Mapping[str, str]) -> str | None:
        return None if owner[row] < 0 else _worded(parts[int(owner[row])], int(local_of[row]), wording)

    kept, rejected = _merged(kept_parts, robot.dof), _merged(rejected_parts, robot.dof)
    return IKAnswer(status, PerTarget(n_targets, lambda row: detail_of(row, NOTE_WORDING)), solver, solvers,
                    singularities, reports, truncated, trimmed, available, kept, rejected,
                    _violations(robot, limits, kept), _violations(robot, limits, rejected), limits, timings, detail_of)


def _worded(part: _Solved, local: int, wording: Mapping[str, str]) -> str | None:
    """The detail of a part's row ``local``: the solver's detail, the selection's notes in ``wording``, the
    remarks."""
    notes = part.chosen.notes.worded(local, wording) if local in part.chosen.notes else []
    words = [part.details.get(local), *notes, part.remarks.get(local)]
    return " ".join(filter(None, words)) or None


def _numbered(items: list) -> tuple[list, np.ndarray]:
    """The distinct items in order of first appearance, and each item's index among them, shape (N,)."""
    index: dict = {}
    numbers = np.array([index.setdefault(item, len(index)) for item in items], dtype=int)
    return list(index), numbers


def _numbered_lists(lists: list[list]) -> tuple[list, list[list[int]]]:
    """:func:`_numbered` for lists of items: the distinct items, and each list as their indices."""
    index: dict = {}
    numbers = [[index.setdefault(item, len(index)) for item in items] for items in lists]
    return list(index), numbers


def _violations(robot: Robot, limits: Limits, table: SolutionTable) -> np.ndarray:
    """Which joints (S, n) of each row outside the limits break them (tolerance included); False elsewhere."""
    if table.within_limits.all():  # the usual kept table: nothing to compare
        return np.zeros(table.joints.shape, dtype=bool)
    tolerance = limits.tolerance(robot)
    outside = (table.joints < limits.lower - tolerance) | (table.joints > limits.upper + tolerance)
    return outside & ~table.within_limits[:, None]


def _merged(tables: list[SolutionTable], dof: int) -> SolutionTable:
    """One table from several, rows grouped by target (stable), label codes remapped onto one vocabulary per
    label (names in order of first appearance)."""
    vocabularies: dict[str, list] = {}
    for table in tables:
        for name, (values, _) in table.labels.items():
            vocabulary = vocabularies.setdefault(name, [])
            vocabulary.extend(value for value in values if value not in vocabulary)
    if len(tables) == 1 and all(tuple(vocabularies[name]) == values and codes.dtype == np.int8
                                for name, (values, codes) in tables[0].labels.items()):
        return tables[0]  # its values are the vocabulary already
    remapped = []
    for table in tables:
        labels = {}
        for name, vocabulary in vocabularies.items():
            if name not in table.labels:
                labels[name] = (tuple(vocabulary), np.full(len(table.target), -1, dtype=np.int8))
                continue
            values, codes = table.labels[name]
            lookup = np.array([*(vocabulary.index(value) for value in values), -1], dtype=np.int8)
            labels[name] = (tuple(vocabulary), lookup[codes])
        remapped.append(SolutionTable(table.target, table.joints, table.within_limits, table.position,
                                      table.orientation, labels))
    if len(remapped) == 1:
        return remapped[0]
    merged = SolutionTable.concatenate(remapped, dof)
    return merged.take(np.argsort(merged.target, kind="stable"))
