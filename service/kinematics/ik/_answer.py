"""One IK answer for a batch of targets of any kinds: solve, fall back, select, as columns.

:func:`answer_ik` splits the targets by kind (full pose, position only, position + tool direction) and answers
each with one solver: the arm's closed form (a redundant arm's family over its free joints), or the numeric
search where no closed form covers the arm or promises a target. Every solver's candidates are verified into
one :class:`~._table.SolutionTable` (:func:`~._verify.verify`); every target is answered by exactly one part,
so the parts' tables are laid end to end and selected once (:func:`~._select.select`).

The shapes an answer takes: candidates (N, m, n) → verified table → selected tables → :class:`IKAnswer` (the
tables and per-target columns) → the wire, encoded from the tables as they stand.

A target's status: ``ok`` with solutions; ``no_solution_within_limits`` when every solution breaks a limit;
``unreachable`` only where the solver proves there is none (a complete closed form, a reach bound);
``not_found`` where a search that cannot promise completeness found none.
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
from .._forward import JointTrig
from .._limits import Limits, outside_limits
from .._robot import Robot
from ..collision import CollisionRequest, at_collisions, clearances
from ._closed_form import cached_plan, plan_candidates, solve_closed_form
from ._coaxial import CoaxialPlan, coaxial_pair
from ._direction import (DEFAULT_ROLL_SAMPLES, direction_candidates, direction_plan, distinct_rolls, roll_family,
                         roll_free_joints, roll_rows, roll_samples, solve_roll_family, tool_roll)
from ._general_6r import GENERAL_STRUCTURES
from ._goals import DirectionGoal, PoseGoal
from ._idealised import IdealisedPlan
from ._numeric import NumericOptions, search
from ._plan import Plan, geometry_of
from ._redundant import (FreeJoint, beyond_reach, family_for, free_joints_for, no_solution_detail, solve_family)
from ._select import MAX_EQUIVALENTS, NOTE_WORDING, Ordering, Selection, check_options, select
from ._table import SolutionTable
from ._types import LabelCodes, Singularity, every
from ._verify import Verified, verify

#: Target kinds (:attr:`IKTargets.kinds`).
POSITION, POSE, DIRECTION = 0, 1, 2


class UnsupportedTargetError(KinematicsError):
    """No closed-form family solves this kind of target for this arm (position + tool direction)."""


@dataclass(frozen=True)
class IKTargets:
    """N targets in the world frame.

    ``matrices`` (N, 4, 4) ``world_T_tool``: for a position-only or a direction target only the position (last
    column) counts. ``kinds`` (N,) int: :data:`POSE`, :data:`POSITION` or :data:`DIRECTION`. For direction rows,
    ``tool_axes`` (N, 3) is the unit tool axis (tool frame) and ``world_directions`` (N, 3) the unit direction it
    must point along (world frame); other rows of them are ignored. ``rolls`` (N entries, optional): for a
    direction row of an arm of 6 or more joints, the tool rolls (radians, (S,)) to solve at, None for the
    default :data:`~._direction.DEFAULT_ROLL_SAMPLES` samples.
    """

    matrices: np.ndarray
    kinds: np.ndarray
    tool_axes: np.ndarray | None = None
    world_directions: np.ndarray | None = None
    rolls: Sequence[np.ndarray | None] | None = None
    indexed: bool = False

    @property
    def per_kind(self) -> list[int]:
        """How many targets are of each kind, indexed by the kind (:data:`POSITION`, :data:`POSE`,
        :data:`DIRECTION`)."""
        return np.bincount(np.asarray(self.kinds), minlength=3).tolist() if len(self.kinds) else [0, 0, 0]

    def at(self, row: int, *field: str) -> tuple:
        """Where an error about target ``row`` is located in the request: ``("target", *field)`` for a single
        target, ``("targets", row, *field)`` for a batch's (``indexed``)."""
        return ("targets", row, *field) if self.indexed else ("target", *field)

    def rolls_of(self, row: int) -> np.ndarray:
        """The rolls (S,) radians that direction row ``row`` is solved at, each once."""
        asked = None if self.rolls is None else self.rolls[row]
        return roll_samples(DEFAULT_ROLL_SAMPLES) if asked is None else distinct_rolls(asked)

    @classmethod
    def poses(cls, world_T_targets: np.ndarray, *, constrain_orientation: bool = True) -> "IKTargets":
        """Targets (N, 4, 4) all of one kind: full poses, or (``constrain_orientation`` false) positions."""
        matrices = np.asarray(world_T_targets, dtype=float)
        return cls(matrices, np.full(len(matrices), POSE if constrain_orientation else POSITION))


@dataclass(frozen=True)
class IKOptions:
    """How to search: the numeric search's bounds, and its own budget (the request's, or a tighter time cap)."""

    numeric: NumericOptions = field(default_factory=NumericOptions)
    budget: Budget = UNLIMITED


@dataclass(frozen=True)
class AnswerOptions:
    """How to answer: reference (n,) and limits in radians / length units, the selection's options, the
    requested free joints of a redundant arm (``(joint, values or None, samples or None)`` entries, see
    :func:`~._redundant.free_joints_for`), the numeric search's bounds, the request's budget, and what each
    solution is checked against for collisions (None: no check)."""

    reference: np.ndarray | None = None
    limits: Limits | None = None  # default: the robot's own
    filter_limits: bool = True
    ordering: Ordering = Ordering()
    max_equivalents: int = MAX_EQUIVALENTS
    search: IKOptions = field(default_factory=IKOptions)
    free_joints: list[tuple[int, list[float] | None, int | None]] | None = None
    budget: Budget = UNLIMITED
    collisions: CollisionRequest | None = None


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

    Per target (N,): ``status`` (object: "ok", "unreachable", "not_found", "no_solution_within_limits"),
    ``detail`` (str or None, worded when read), ``solver`` (index into ``solvers``), ``singularities`` (lists
    of indices into ``singularity_reports``, made when read), ``truncated``, ``trimmed``, ``available``.
    ``solutions`` and ``rejected`` hold the rows grouped by target, joints in radians / length units; a
    position-only target's orientation residuals are NaN. ``solution_violations`` (S, n) and
    ``rejected_violations`` (R, n) say which joints of a row outside the ``limits`` break them. ``timings``
    lists the solver calls.
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
    every_detail: Callable[[Mapping[str, str]], list[str | None]] = field(default=lambda wording: [], repr=False,
                                                                           compare=False)

    def __len__(self) -> int:
        return len(self.status)

    def details(self, wording: Mapping[str, str] = NOTE_WORDING) -> PerTarget:
        """Each target's detail (str or None), the selection's notes in ``wording``: the keys and fields of
        :data:`NOTE_WORDING`, a boundary's words for the options (``detail`` reads in the core's)."""
        return PerTarget(len(self), lambda row: self.detail_of(row, wording))

    def detail_list(self, wording: Mapping[str, str] = NOTE_WORDING) -> list[str | None]:
        """:meth:`details`, every one made at once (what an encoder of the whole batch wants)."""
        return self.every_detail(wording)

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
class _Part:
    """Targets ``rows`` (k,, ascending) answered by one solver: their verified solutions (``verified``, k targets), the
    solver, and per local row the words before the selection's notes (``details``) and after them
    (``remarks``). ``reported`` (k,) says where the solver's singular conditions are reported (default: the rows
    with a solution); ``unfinished`` (k,) where the numeric search's iteration cap stopped starts; ``sampled``
    (k,) where the solver answered complete at sampled values of a continuous freedom (the roll, a redundant
    arm's free joints), so an empty answer proves nothing: ``not_found`` rather than ``unreachable``."""

    rows: np.ndarray
    verified: Verified
    method: str
    structure: str
    free_joints: tuple[int, ...]
    details: dict[int, str] = field(default_factory=dict)
    remarks: dict[int, str] = field(default_factory=dict)
    reported: np.ndarray | None = None
    unfinished: np.ndarray | None = None
    sampled: np.ndarray | None = None


def answer_ik(robot: Robot, targets: IKTargets, options: AnswerOptions = AnswerOptions()) -> IKAnswer:
    """Every solution of each target, selected against the limits (see the module docstring)."""
    matrices, kinds = np.asarray(targets.matrices, dtype=float), np.asarray(targets.kinds)
    limits = Limits.of(robot) if options.limits is None else options.limits
    check_options(robot, options.ordering, options.reference, options.max_equivalents)
    timings: list[SolveTiming] = []
    parts: list[_Part] = []
    per_kind = targets.per_kind
    if per_kind[DIRECTION]:
        parts += _directions(robot, targets, options, timings)
    if per_kind[POSE]:
        rows = np.arange(len(kinds)) if per_kind[POSE] == len(kinds) else np.flatnonzero(kinds == POSE)
        parts += _poses(robot, matrices, rows, options, timings)
    if per_kind[POSITION]:
        parts += _positions(robot, matrices, np.flatnonzero(kinds == POSITION), options, timings)
    return _assembled(robot, len(kinds), parts, limits, options, timings)


@contextmanager
def _at_free_joints() -> Iterator[None]:
    """Locate the errors about the free joints at the option that asks for them (``free_joints``)."""
    try:
        yield
    except InvalidInputError as error:
        raise error.relocated("free_joints") from None


def _timed(timings: list[SolveTiming], part: _Part, started: float) -> _Part:
    timings.append(SolveTiming(part.method, part.structure, time.perf_counter() - started,
                               part.verified.count.tolist()))
    return part


def _poses(robot: Robot, matrices: np.ndarray, rows: np.ndarray, options: AnswerOptions,
           timings: list[SolveTiming]) -> list[_Part]:
    """Full-pose targets: a redundant arm's family over its free joints, else the closed form where it covers and
    promises, the numeric search elsewhere."""
    goal = PoseGoal(matrices[rows])
    started = time.perf_counter()
    if answered_by_family(robot, options):
        with _at_free_joints():
            free = free_joints_for(robot, options.free_joints)
        if free is not None:
            return _family(robot, goal, rows, free, options, timings, started)
        if robot.dof > 6:  # no locking leaves a closed-form family
            return [_timed(timings, _numeric(robot, goal, rows, options), started)]
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    if plan is None:
        return [_timed(timings, _numeric(robot, goal, rows, options), started)]
    verified = solve_closed_form(robot, plan, goal, options.reference, budget=options.budget)
    closed = _Part(rows, verified, "analytic", plan.structure, tuple(plan.free_joints))
    return _with_fallback(robot, goal, closed, options, timings, started, plan)


def answered_by_family(robot: Robot, options: AnswerOptions) -> bool:
    """Whether full poses are answered as a family over free joints: those the request names, or a redundant
    arm's (:func:`redundant_family`)."""
    return options.free_joints is not None or redundant_family(robot)


def redundant_family(robot: Robot) -> bool:
    """Whether the arm's full poses are a family over free joints whatever the request: a redundant arm (n > 6)
    unless its one degree of redundancy is a coaxial pair's split (:func:`coaxial_redundancy`)."""
    return robot.dof > 6 and not coaxial_redundancy(robot)


def coaxial_redundancy(robot: Robot) -> bool:
    """Whether a 7-joint arm's redundancy is the split of two coaxial joints (:mod:`._coaxial`) whose arm
    without the second joint a closed form covers. Every value of a free joint would give the same solutions up
    to that split, so the arm is answered as a six-joint one with a coaxial pair: the second joint held at the
    reference value (or 0), listed free, and the relation stated (api.md: at a singularity the family is
    represented and the coupling is stated)."""
    if robot.dof != 7 or coaxial_pair(geometry_of(robot)) is None:
        return False
    return isinstance(cached_plan(robot, constrain_orientation=True, reference=None), CoaxialPlan)


def _positions(robot: Robot, matrices: np.ndarray, rows: np.ndarray, options: AnswerOptions,
               timings: list[SolveTiming]) -> list[_Part]:
    """Position-only targets: the closed form with the joints past the third held at the reference (or 0); a
    position those held joints cannot reach is searched over every joint before it is called unreachable."""
    goal = PoseGoal(matrices[rows], constrain_orientation=False)
    started = time.perf_counter()
    plan = cached_plan(robot, constrain_orientation=False, reference=options.reference)
    if plan is None:
        return [_timed(timings, _numeric(robot, goal, rows, options), started)]
    verified = solve_closed_form(robot, plan, goal, options.reference, budget=options.budget)
    closed = _Part(rows, verified, "analytic", plan.structure, tuple(plan.free_joints))
    held = [j for j in plan.free_joints if j >= 3] if robot.dof > 3 else []
    parts = _with_fallback(robot, goal, closed, options, timings, started, plan)
    if not held:
        return parts
    closed = parts[0]
    empty = np.flatnonzero((closed.verified.count == 0) & closed.verified.complete)
    if not len(empty):
        return parts
    names = ", ".join(f"q{i + 1}" for i in held)
    far = beyond_reach(robot, matrices[closed.rows[empty], :3, 3])
    for local in empty[far].tolist():
        closed.details[local] = ("The target position is outside the workspace (farther from the base than the "
                                 "arm can reach).")
    search_rows = empty[~far]
    kept = np.setdiff1d(np.arange(len(closed.rows)), search_rows)
    parts[0] = _taken(closed, kept)
    if len(search_rows):
        started = time.perf_counter()
        anchor = np.zeros(robot.dof) if options.reference is None else options.reference
        searched = _numeric(robot, goal.take(search_rows), closed.rows[search_rows], options, anchor)
        for local in range(len(search_rows)):
            searched.details[local] = (
                f"The position is out of reach with {names} held at the reference values (or 0); a numeric search "
                f"over every joint found these solutions, nearest the held values first. It cannot promise that "
                f"every solution was found." if searched.verified.count[local] else
                f"The position is out of reach with {names} held at the reference values (or 0), and a numeric "
                f"search over every joint found no solution; it lies within the arm's reach sphere, so it is not "
                f"proven outside the workspace. " + searched.details.get(local, "")).strip()
        parts.append(_timed(timings, searched, started))
    return parts


def _directions(robot: Robot, targets: IKTargets, options: AnswerOptions, timings: list[SolveTiming]
                ) -> list[_Part]:
    """Position + direction targets: one closed-form solve per tool axis on a 5-joint arm, the family over the
    free roll on an arm of 6 or more (one part per tool axis and set of rolls)."""
    directions = np.flatnonzero(np.asarray(targets.kinds) == DIRECTION)
    if robot.dof >= 6:
        return _roll_families(robot, targets, directions, options, timings)
    for row in directions.tolist():
        if targets.rolls is not None and targets.rolls[row] is not None:
            raise InvalidInputError(f"roll_samples and roll_values apply to arms of 6 or more joints, whose roll "
                                    f"about the tool axis is free; this one has {robot.dof}",
                                    location=targets.at(row, "orientation"))
    axes, group = np.unique(np.asarray(targets.tool_axes)[directions], axis=0, return_inverse=True)
    parts = []
    for number in range(len(axes)):
        rows = directions[group.reshape(-1) == number]
        started = time.perf_counter()
        plan = direction_plan(robot, axes[number])
        if plan is None:
            raise UnsupportedTargetError("no closed-form family covers position + tool direction targets of this "
                                         "arm with this tool axis")
        goal = _direction_goal(targets, rows, plan.tool_axis)
        options.budget.check("the analytic solve")
        verified = verify(robot, goal, direction_candidates(robot, plan, goal, options.reference), options.reference)
        roll = tool_roll(plan)
        if roll is not None:
            verified.singularities.add(verified.count > 0, roll)
        part = _Part(rows, verified, "analytic", plan.structure,
                     () if plan.roll_joint is None else (plan.roll_joint,))
        for local in np.flatnonzero(verified.count == 0).tolist():
            part.details[local] = (
                "The target position is outside the workspace (farther from the base than the arm can reach)."
                if bool(beyond_reach(robot, goal.positions[local])) else
                "No joint vector puts the tool at this position with its axis along the direction (every "
                "solution of the closed form was checked)." if verified.complete[local] else
                "The closed form found no joint vector that puts the tool at this position with its axis along "
                "the direction, and cannot promise there is none (it met a condition where solutions may be "
                "missed).")
        parts.append(_timed(timings, part, started))
    return parts


def _direction_goal(targets: IKTargets, rows: np.ndarray, tool_axis: np.ndarray) -> DirectionGoal:
    """The direction goal of ``rows`` (k,) of the targets, their directions made unit."""
    world = np.asarray(targets.world_directions, dtype=float)[rows]
    return DirectionGoal(targets.matrices[rows, :3, 3], world / np.linalg.norm(world, axis=-1, keepdims=True),
                         tool_axis)


def direction_groups(targets: IKTargets, rows: np.ndarray) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """The direction rows (k,) grouped by tool axis and rolls: (rows, unit tool axis (3,), rolls (S,)) each."""
    groups: dict[tuple[bytes, bytes], list[int]] = {}
    axes = np.asarray(targets.tool_axes, dtype=float)
    for row in rows.tolist():
        key = (np.round(axes[row] / np.linalg.norm(axes[row]), 12).tobytes(), targets.rolls_of(row).tobytes())
        groups.setdefault(key, []).append(row)
    return [(np.array(members), axes[members[0]] / np.linalg.norm(axes[members[0]]), targets.rolls_of(members[0]))
            for members in groups.values()]


def direction_free_joints(robot: Robot, requested, most_rolls: int, location: tuple) -> list[FreeJoint] | None:
    """The free joints of direction targets solved at up to ``most_rolls`` rolls: a redundant arm's, as the request
    names them or by default (:func:`~._direction.roll_free_joints`, its errors at ``location``); None on a
    6-joint arm, which refuses any, as a pose target does."""
    if requested is not None:
        with _at_free_joints():
            return free_joints_for(robot, requested)
    return roll_free_joints(robot, most_rolls, location) if robot.dof > 6 else None


def _roll_families(robot: Robot, targets: IKTargets, directions: np.ndarray, options: AnswerOptions,
                   timings: list[SolveTiming]) -> list[_Part]:
    """Direction targets of an arm of 6 or more joints: the family over the free roll (and a redundant arm's free
    joints), solved completely at each sampled roll."""
    groups = direction_groups(targets, directions)
    free = direction_free_joints(robot, options.free_joints, max(len(rolls) for _, _, rolls in groups),
                                 targets.at(int(directions[0]), "orientation"))
    family = roll_family(robot, free)
    if family is None:
        raise UnsupportedTargetError(
            "no closed-form family covers this arm's pose problem" + (" with the free joints locked" if robot.dof > 6
                                                                      else ""))
    parts = []
    for rows, axis, rolls in groups:
        started = time.perf_counter()
        roll_rows(robot, rolls, free, targets.at(int(rows[0]), "orientation"))
        goal = _direction_goal(targets, rows, axis)
        answer = solve_roll_family(robot, family, goal, rolls, options.reference, budget=options.budget)
        part = _Part(rows, answer.verified, "analytic", family.structure, family.free_joints,
                     sampled=np.ones(len(rows), dtype=bool))
        for local in np.flatnonzero(answer.verified.count == 0).tolist():
            if bool(beyond_reach(robot, goal.positions[local])):
                part.details[local] = ("The target position is outside the workspace (farther from the base than "
                                       "the arm can reach).")
                part.sampled[local] = False
            else:
                part.details[local] = (
                    f"No joint vector puts the tool at this position with its axis along the direction at any of "
                    f"the {len(rolls)} rolls about the tool axis solved"
                    + (f" (with {family.free_rows} values of the free joints each)" if family.free_rows > 1 else "")
                    + "; each was solved completely, but other rolls may reach it.")
        for local in np.flatnonzero(answer.unpromised > 0).tolist():
            part.remarks[local] = (f"At {answer.unpromised[local]} of the rolls solved the closed form could not "
                                   f"promise every solution (a singular condition), so the answer may miss some.")
        parts.append(_timed(timings, part, started))
    return parts


def _family(robot: Robot, goal: PoseGoal, rows: np.ndarray, free: list[FreeJoint], options: AnswerOptions,
            timings: list[SolveTiming], started: float) -> list[_Part]:
    """A redundant arm's targets: the family over the free joints' values. Where no closed form covers the
    locked arm, the numeric search answers at the values asked (the free joints held), or over every joint when
    the request named none."""
    family = family_for(robot, tuple(sorted(f.joint for f in free)))
    if not family.available:
        held = options.free_joints is not None
        part = _numeric(robot, goal, rows, options, free=free if held else None)
        names = ", ".join(f"q{f.joint + 1}" for f in free)
        note = (f"No closed-form family covers this arm with {names} locked: a numeric search at each of their "
                f"values answered." if held else
                f"No closed-form family covers this arm with {names} locked, so a numeric search over every joint "
                f"answered.")
        part.remarks.update(dict.fromkeys(range(len(rows)), note))
        return [_timed(timings, part, started)]
    with _at_free_joints():
        answer = solve_family(robot, family, goal, free, options.reference, budget=options.budget)
    # solved completely at each free value, which proves nothing for the values between: an empty answer is
    # not_found, unless the position is beyond the arm's reach
    part = _Part(rows, answer.verified, "analytic", family.structure, family.free_joints,
                 sampled=np.ones(len(rows), dtype=bool))
    for local in np.flatnonzero(answer.verified.count == 0).tolist():
        beyond = bool(beyond_reach(robot, goal.world_T_targets[local, :3, 3]))
        part.details[local] = no_solution_detail(free, beyond)
        part.sampled[local] = not beyond
    for local in np.flatnonzero(answer.missing > 0).tolist():
        part.remarks[local] = (f"At {answer.missing[local]} of the free values the locked arm falls outside the "
                               f"closed-form family, so no solution is listed there.")
    return [_timed(timings, part, started)]


def _with_fallback(robot: Robot, goal: PoseGoal, closed: _Part, options: AnswerOptions, timings: list[SolveTiming],
                   started: float, plan: Plan) -> list[_Part]:
    """The closed form's part for the targets it promises, and the numeric search for the others, seeded with
    the solutions the closed form verified there and reporting the conditions it met (with the plan's note,
    :func:`_fallback_note`). The search's solutions carry the plan's branch labels, as the closed form's do: a
    target near a singularity, which the closed form hands over, keeps the labels a client holds along a path
    (issue 22.11)."""
    verified = closed.verified
    if not every(verified.count):  # (the usual answer has every target solved: nothing to word)
        for local in np.flatnonzero((verified.count == 0) & verified.complete).tolist():
            closed.details[local] = unreachable_detail(robot, goal, local, verified)
    if every(verified.complete):
        return [_timed(timings, closed, started)]
    broken = np.flatnonzero(~verified.complete)
    promised = np.flatnonzero(verified.complete)
    parts = [_timed(timings, _taken(closed, promised), started)] if len(promised) else []
    started = time.perf_counter()
    table = verified.table
    known = np.full((len(broken), max(1, int(verified.count[broken].max(initial=0))), robot.dof), np.nan)
    for index, local in enumerate(broken.tolist()):
        start, stop = np.searchsorted(table.target, [local, local + 1])
        known[index, :stop - start] = table.joints[start:stop]
    # the plan's candidates there (least-squares ones, refinements that stalled) are the search's own starts
    options.budget.check("the numeric search")
    seeds = plan_candidates(plan, goal.world_T_targets[broken], options.reference)
    fallback = _numeric(robot, goal.take(broken), closed.rows[broken], options, options.reference, known=known,
                        seeds=seeds, label_codes=plan.label_codes)
    fallback.verified.singularities.extend(verified.singularities, rows=broken)
    fallback.reported = np.ones(len(broken), dtype=bool)
    note = _fallback_note(plan)
    for local in range(len(broken)):
        fallback.details[local] = f"{note} {fallback.details.get(local, '')}".strip()
    parts.append(_timed(timings, fallback, started))
    return parts


def _fallback_note(plan) -> str:
    """Why the numeric search completed a target the plan could not promise."""
    if plan.structure.startswith(GENERAL_STRUCTURES):
        return ("The general solver (6R, or 5R with one slide) cannot promise every solution for this target (an "
                "ill-conditioned eigenproblem or a near-double root), so the numeric search completed its answer.")
    if getattr(plan, "free_joint_steers_wrist", False):
        return (f"The {plan.structure} family leaves a joint free for every target, held at one value, and the "
                f"wrist cannot reach every orientation: another value of that joint may bring this orientation "
                f"within its reach, so the numeric search completed the answer.")
    if isinstance(plan, IdealisedPlan) and plan.constrain_orientation and plan.free_joints:
        free = ", ".join(f"q{joint + 1}" for joint in plan.free_joints)
        return (f"The arm is within rounding of the {plan.structure} family but not exactly of it, and that family "
                f"leaves {free} free for every target: the arm as given has isolated solutions along it, which its "
                f"closed form cannot list, so the numeric search completed the answer.")
    if isinstance(plan, IdealisedPlan):
        return (f"The arm is within rounding of the {plan.structure} family but not exactly of it; its closed "
                f"form, refined on the arm as given, cannot promise every solution for this target (a pair of "
                f"solutions may appear or vanish between the two), so the numeric search completed it.")
    return (f"The closed form of the {plan.structure} family cannot promise every solution for this target (it met "
            f"a singular condition where a pair of solutions may appear or vanish), so the numeric search "
            f"completed it.")


def _numeric(robot: Robot, goal: PoseGoal, rows: np.ndarray, options: AnswerOptions,
             reference: np.ndarray | None = None, *, known: np.ndarray | None = None,
             seeds: np.ndarray | None = None, free: list[FreeJoint] | None = None,
             label_codes: Callable[[np.ndarray, JointTrig], LabelCodes] | None = None) -> _Part:
    """The numeric search's part for the goal's targets (their indices ``rows``), with ``known`` solutions and
    each target's ``seeds`` (see :func:`~._numeric.search`); with ``free``, once per combination of the free
    joints' values, those joints held. ``label_codes`` labels the solutions (a closed-form plan's, where the
    search completes its answer); None leaves them unlabelled."""
    reference = options.reference if reference is None else reference
    search_options = options.search
    if free is None:
        searched = search(robot, goal, search_options.numeric, reference, known=known, seeds=seeds, held=None,
                          budget=search_options.budget)
        candidates, unfinished = searched.candidates, searched.unfinished
        free_joints: tuple[int, ...] = ()
    else:
        candidates, unfinished = _held_searches(robot, goal, free, search_options, reference)
        free_joints = tuple(f.joint for f in free)
    held = None
    if free is not None:
        held = np.zeros(robot.dof, dtype=bool)
        held[list(free_joints)] = True
    verified = verify(robot, goal, candidates, reference, label_codes, held=held)
    part = _Part(rows, verified, "numeric", "general", free_joints, unfinished=unfinished)
    for local in range(len(rows)):
        words = []
        if not verified.count[local]:
            words.append("No solution was found by the numeric search; the target may be outside the workspace "
                         "(the numeric search cannot prove it).")
        if unfinished[local]:
            words.append(f"The iteration cap ({search_options.numeric.max_iterations}) stopped some starts before "
                         f"they converged.")
        if words:
            part.details[local] = " ".join(words)
    coaxial = [flag for _, flag in verified.singularities.entries if flag.kind == "coaxial"]
    if coaxial:
        part.free_joints = tuple(sorted({*part.free_joints, coaxial[0].joints[1]}))
    return part


def _held_searches(robot: Robot, goal: PoseGoal, free: list[FreeJoint], search_options: IKOptions,
                   reference: np.ndarray | None):
    """The numeric search at each combination of the free joints' values, those joints held: the candidates of
    every combination side by side, per target."""
    from ._types import Candidates, SingularFlags

    grids = np.meshgrid(*(np.asarray(f.values, dtype=float) for f in free), indexing="ij")
    values = np.stack([g.ravel() for g in grids], axis=-1)
    joints, valid, unfinished = [], [], np.zeros(len(goal), dtype=bool)
    for row in values:
        searched = search(robot, goal, search_options.numeric, reference,
                          held=dict(zip((f.joint for f in free), row.tolist())), budget=search_options.budget)
        joints.append(searched.candidates.joints)
        valid.append(searched.candidates.valid)
        unfinished |= searched.unfinished
    candidates = Candidates(np.concatenate(joints, axis=1), np.concatenate(valid, axis=1), SingularFlags(len(goal)),
                            complete=np.zeros(len(goal), dtype=bool))
    return candidates, unfinished


def _taken(part: _Part, local: np.ndarray) -> _Part:
    """The part for its rows ``local`` (indices) only, renumbered."""
    renumber = {int(old): new for new, old in enumerate(np.asarray(local).tolist())}
    verified = part.verified
    keep = np.isin(verified.table.target, local)
    table = verified.table.take(keep)
    table = table.with_targets(np.searchsorted(local, table.target))
    taken = Verified(table, verified.complete[local], verified.nearest[local], verified.singularities.take(local))

    def moved(words: dict[int, str]) -> dict[int, str]:
        return {renumber[row]: text for row, text in words.items() if row in renumber}

    return _Part(part.rows[local], taken, part.method, part.structure, part.free_joints, moved(part.details),
                 moved(part.remarks), None if part.reported is None else part.reported[local],
                 None if part.unfinished is None else part.unfinished[local])


def unreachable_detail(robot: Robot, goal: PoseGoal, local: int, verified: Verified) -> str:
    """Why a target the closed form proves unreachable has no solution: beyond the reach sphere, or (for a pose)
    whether the position alone is reachable."""
    position = goal.world_T_targets[local, :3, 3]
    if bool(beyond_reach(robot, position)):
        return "The target position is outside the workspace (farther from the base than the arm can reach)."
    if not goal.constrain_orientation:
        return "The target position is outside the workspace."
    if robot.dof < 6:  # the arm cannot set the orientation freely: is the position alone reachable?
        plan = cached_plan(robot, constrain_orientation=False, reference=None)
        if plan is not None:
            position_only = solve_closed_form(robot, plan, PoseGoal(goal.world_T_targets[local:local + 1], False),
                                              None)
            if position_only.count[0]:
                return ("The position is reachable but the orientation is not: " + _orientation_freedom(robot) +
                        " No joint vector gives the requested orientation at that position.")
            if position_only.complete[0] and not plan.free_joints:
                return "The target position is outside the workspace."
    return ("No joint vector reaches this pose: every solution of the closed form was checked, none places the "
            "tool there.")


def _orientation_freedom(robot: Robot) -> str:
    """What orientations an arm with fewer than six joints can give the tool, in words."""
    geometry = geometry_of(robot)
    revolute = [i for i in range(robot.dof) if robot.is_revolute[i]]
    if revolute and all(geometry.parallel(revolute[0], i) for i in revolute):
        axis = np.round(geometry.direction(revolute[0]), 6).tolist()
        return (f"every revolute axis of this arm is parallel to {axis} (world frame), so the tool can only turn "
                f"about that direction from its home orientation (for a SCARA, Spong eq. 4.56).")
    return f"an arm with {robot.dof} joints cannot set every orientation independently of the position."


def _assembled(robot: Robot, n_targets: int, parts: list[_Part], limits: Limits, options: AnswerOptions,
               timings: list[SolveTiming]) -> IKAnswer:
    """The parts' tables laid end to end and selected once, with each target's solver, conditions and words."""
    owner, local_of = np.full(n_targets, -1), np.zeros(n_targets, dtype=int)
    complete = np.ones(n_targets, dtype=bool)
    sampled = np.zeros(n_targets, dtype=bool)
    reports: list[SolverReport] = []
    report_of = np.zeros(n_targets, dtype=int)
    singular_of: dict[int, list[Singularity]] = {}
    tables = []
    for number, part in enumerate(parts):
        owner[part.rows], local_of[part.rows] = number, np.arange(len(part.rows))
        verified = part.verified
        complete[part.rows] = verified.complete
        if part.sampled is not None:
            sampled[part.rows] = part.sampled
        flags = 2 * verified.complete.astype(int)  # (complete, unfinished) as one code per target: 0 … 3
        if part.unfinished is not None:
            flags += part.unfinished
        lookup = np.zeros(4, dtype=int)
        for code in np.bincount(flags, minlength=4).nonzero()[0].tolist():  # the codes met, ascending
            report = SolverReport(part.method, part.structure, code >= 2, code % 2 == 1, part.free_joints)
            if report not in reports:
                reports.append(report)
            lookup[code] = reports.index(report)
        report_of[part.rows] = lookup[flags]
        if verified.singularities.entries:
            reported = verified.count > 0 if part.reported is None else part.reported
            for local in np.flatnonzero(reported & verified.singularities.any()).tolist():  # the others meet none
                met = verified.singularities[local]
                if met:
                    singular_of[int(part.rows[local])] = met
        whole = len(parts) == 1 and len(part.rows) == n_targets  # rows 0 … N − 1: the part's own numbering
        tables.append(verified.table if whole else verified.table.with_targets(part.rows[verified.table.target]))
    table = SolutionTable.concat(tables, robot.dof)  # grouped by target (concat regroups interleaved parts)
    excluded = None
    if options.collisions is not None:  # a 2π-equivalent moves no link: each distinct solution is checked once
        options.budget.check("the collision check")
        with at_collisions():
            checked = clearances(robot, options.collisions, table.joints)
        table = table.with_clearances(checked.clearance, checked.contacts)
        excluded = checked.colliding if options.collisions.filter else None
    chosen: Selection = select(robot, table, n_targets, limits, filter_limits=options.filter_limits,
                               reference=options.reference, ordering=options.ordering,
                               max_equivalents=options.max_equivalents, excluded=excluded, budget=options.budget)
    status = chosen.status.copy()
    unproven = ~complete | sampled
    if np.count_nonzero(unproven):
        status[(status == "unreachable") & unproven] = "not_found"
    # solver reports numbered by first appearance in target order
    by_appearance = list(dict.fromkeys(report_of.tolist()))
    if by_appearance == list(range(len(reports))):  # numbered so already (one solver, the usual answer)
        solvers, solver = reports, report_of
    else:
        renumber = np.zeros(max(len(reports), 1), dtype=int)
        renumber[by_appearance] = np.arange(len(by_appearance))
        solvers, solver = [reports[i] for i in by_appearance], renumber[report_of]
    singular_rows = sorted(singular_of)
    distinct: dict[Singularity, int] = {}
    numbered = {row: [distinct.setdefault(flag, len(distinct)) for flag in singular_of[row]] for row in singular_rows}
    singularities = PerTarget(n_targets, lambda row: list(numbered.get(row, ())))

    def detail_of(row: int, wording: Mapping[str, str]) -> str | None:
        if owner[row] < 0:
            return None
        notes = chosen.notes.worded(row, wording) if row in chosen.notes else []
        return _detail(parts[int(owner[row])], int(local_of[row]), notes)

    def every_detail(wording: Mapping[str, str]) -> list[str | None]:
        notes = chosen.notes.worded_every(wording)
        return [None if part < 0 else _detail(parts[part], local, notes.get(row, ()))
                for row, (part, local) in enumerate(zip(owner.tolist(), local_of.tolist()))]

    return IKAnswer(status, PerTarget(n_targets, lambda row: detail_of(row, NOTE_WORDING)), solver, solvers,
                    singularities, list(distinct), chosen.truncated, chosen.trimmed, chosen.available,
                    chosen.solutions, chosen.rejected, _violations(robot, limits, chosen.solutions),
                    _violations(robot, limits, chosen.rejected), limits, timings, detail_of, every_detail)


def _detail(part, local: int, notes) -> str | None:
    """One target's detail: its solver part's words, the selection's notes, the part's remarks."""
    return " ".join(filter(None, [part.details.get(local), *notes, part.remarks.get(local)])) or None


def _violations(robot: Robot, limits: Limits, table: SolutionTable) -> np.ndarray:
    """Which joints (S, n) of each row outside the limits break them (tolerance included); False elsewhere."""
    if np.count_nonzero(table.within_limits) == len(table):  # the usual kept table: nothing to compare
        return np.zeros(table.joints.shape, dtype=bool)
    return outside_limits(robot, limits, table.joints) & ~table.within_limits[:, None]

