"""The cost of an IK request, before any solving: what the answer can hold and what work it takes.

:func:`estimate` reads the same choices :func:`~._answer.answer_ik` will make (the closed form, a redundant arm's
family over its free values, the numeric search and its starts) and counts, per target and in all, the most rows
the answer can hold once 2π-equivalents are expanded (:mod:`._equivalents`). A boundary holds these numbers
against its caps and words them; nothing here refuses anything but malformed options.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._limits import Limits
from .._robot import Robot
from ..collision import at_collisions, model_for, model_is_kept
from ._answer import (DIRECTION, POSE, POSITION, AnswerOptions, IKTargets, _at_free_joints,
                      direction_free_joints, direction_groups, answered_by_family)
from ._closed_form import cached_plan, plan_is_kept
from ._direction import direction_plan, refined_rows, roll_family, roll_rows
from ._equivalents import (MAX_COMBINATIONS_PER_SOLUTION, combinations_to_rank, enumerable_limit,
                           equivalents_per_solution, worst_answer_per_target)
from ._free_search import EXTRA_VALUES_WITH_REFERENCE
from ._redundant import family_for, free_joints_for, grid_size

#: The most rows a single-target answer may hold for its work to count as small (:attr:`Cost.small`): a
#: closed-form solve, a selection and an encoding of a few milliseconds at most. 512 is a 6-joint arm's eight
#: solutions under limits of two turns a joint (the UR arms' ±2π): such a whole request takes about 1.2 ms where it
#: arrives, and the hand-over to a work loop would add about 200 µs to it.
SMALL_ROWS = 512

#: The most pair distances (distinct solutions × shape pairs) a collision check may measure for its work to count
#: as small: a few hundred microseconds, every pair measured at once (a single PUMA pose with its catalogue
#: capsules, a table and a post: 8 × 34).
SMALL_PAIR_CHECKS = 2048


@dataclass(frozen=True)
class Cost:
    """What an IK request costs, counted before any solving.

    ``solutions_per_target``: the most verified solutions one target can have before expansion (a family's
    generic count; over a redundant arm's free values; over a direction target's sampled rolls (and the rolls the
    continuous search adds with a reference), times the free values of a redundant arm; the numeric search's
    starts). ``free_values``: the most values of the free parameters (joints, roll) solved per target.
    ``numeric_starts``: the numeric search's starts in all (every target it may answer, every combination of held
    free values).
    ``equivalents``: the most 2π-equivalents of one solution within the limits; ``kept``: the most kept per
    target (``max_equivalents``, ``max_solutions``, lowered to :func:`~._equivalents.enumerable_limit` when a
    default asks more than can be ranked: ``lowered``); ``ranked``: the combinations ranked per solution to keep
    them (over :data:`~._equivalents.MAX_COMBINATIONS_PER_SOLUTION` only when the client asked for that many);
    ``rows_per_target`` / ``rejected_per_target``: the worst answer of one target (kept plus rejected) and how
    many of those are rejected; ``rows``: the worst answer in all. ``small``: the work is bounded by a few
    milliseconds whatever the targets ask (:func:`is_small`). A position target on an arm of more than three
    joints may be searched over every joint when its held joints leave it out of reach: that search is bounded by
    the request's deadline, not counted in ``numeric_starts``. With a collision check: ``collision_pairs``, the
    shape pairs checked per solution, and ``collision_checks``, the pair distances in all (every distinct
    solution, before its 2π-equivalents, which move no link).
    """

    targets: int
    solutions_per_target: int
    numeric_starts: int
    free_values: int
    equivalents: int
    kept: int
    lowered: bool
    ranked: int
    rows_per_target: int
    rejected_per_target: int
    rows: int
    small: bool
    collision_pairs: int = 0
    collision_checks: int = 0

    @property
    def too_many_to_rank(self) -> bool:
        """The client asked to keep more equivalents than one answer may rank."""
        return self.ranked > MAX_COMBINATIONS_PER_SOLUTION


def estimate(robot: Robot, targets: IKTargets, options: AnswerOptions, *, kept_asked: bool = True,
             small: bool | None = None) -> Cost:
    """The cost of answering ``targets`` with ``options`` (see :class:`Cost`). ``kept_asked``: the client chose
    ``max_equivalents`` or ``max_solutions`` (a default too large to rank is lowered, not refused). ``small``:
    :func:`is_small` of the same arguments when the caller has it already (it decides where to compute first).

    Raises :class:`~.._errors.InvalidInputError` (located at ``free_joints``) for free joints the arm cannot
    take, as :func:`~._answer.answer_ik` would.
    """
    kinds = np.asarray(targets.kinds)
    limits = Limits.of(robot) if options.limits is None else options.limits
    starts = options.search.numeric.starts
    most, numeric_targets, numeric_per_target, free_values = 0, 0, starts, 1
    if small is None:
        small = is_small(robot, targets, options)  # before anything is built
    for kind, of_kind in enumerate(targets.per_kind):
        if not of_kind:
            continue
        rows = kinds == kind
        if kind == DIRECTION and robot.dof >= 6:  # the family over the free roll: rolls × free values × solutions
            groups = direction_groups(targets, np.flatnonzero(rows))
            free = direction_free_joints(robot, options.free_joints, max(len(rolls) for _, _, rolls in groups),
                                         targets.at(int(np.flatnonzero(rows)[0]), "orientation"))
            family = roll_family(robot, free)
            for members, _, rolls in groups:
                solves = roll_rows(robot, rolls, free, targets.at(int(members[0]), "orientation"))
                if family is not None:
                    solves += refined_rows(family, options.reference is not None)
                    most = max(most, solves * family.generic_count)
                    free_values = max(free_values, solves)
            continue
        if kind == DIRECTION:
            for axis in np.unique(np.asarray(targets.tool_axes)[rows], axis=0):
                plan = direction_plan(robot, axis)
                most = max(most, 0 if plan is None else plan.plan.generic_count)
            continue
        constrained = kind == POSE
        free = None
        family_asked = constrained and answered_by_family(robot, options)
        if family_asked:
            with _at_free_joints():
                free = free_joints_for(robot, options.free_joints)
        if free is not None or family_asked:
            family = None if free is None else family_for(robot, tuple(sorted(f.joint for f in free)))
            values = 1 if free is None else grid_size([len(f.values) for f in free])
            if family is not None and family.available:
                refined = EXTRA_VALUES_WITH_REFERENCE if options.reference is not None and len(free) == 1 else 0
                most = max(most, (values + refined) * family.generic_count)
                free_values = max(free_values, values + refined)
            else:  # the numeric search, at each combination of the values asked (or once over every joint)
                numeric_targets += of_kind
                numeric_per_target = max(numeric_per_target, starts * (values if options.free_joints else 1))
                most = max(most, numeric_per_target)
            continue
        plan = cached_plan(robot, constrain_orientation=constrained, reference=options.reference)
        if plan is None:
            numeric_targets += of_kind
            most = max(most, starts)
        else:
            most = max(most, plan.generic_count)
    kept = options.max_equivalents if options.ordering.max_solutions is None else min(
        options.max_equivalents, options.ordering.max_solutions)
    equivalents = equivalents_per_solution(robot, limits)
    ranked = combinations_to_rank(robot.dof, kept, equivalents)
    lowered = ranked > MAX_COMBINATIONS_PER_SOLUTION and not kept_asked
    if lowered:
        kept = enumerable_limit(robot.dof)
        ranked = combinations_to_rank(robot.dof, kept, equivalents)
    rows_per_target, rejected = worst_answer_per_target(most, equivalents, kept)
    numeric_starts = numeric_targets * numeric_per_target
    count = len(kinds)
    pairs = 0
    if options.collisions is not None:
        pairs = collision_pair_bound(robot, options.collisions)
        if pairs <= COMPILED_PAIRS:  # few enough to compile (and count exactly) now
            with at_collisions():
                pairs = len(model_for(robot, options.collisions).pairs)
    return Cost(count, most, numeric_starts, free_values, equivalents, kept, lowered, ranked, rows_per_target,
                rejected, count * rows_per_target, small, pairs,
                count * most * pairs)


#: Most shape pairs compiled while the cost is counted; past it the bound of :func:`collision_pair_bound` stands
#: for the count (compiling is a Python loop over the pairs), for a boundary to refuse.
COMPILED_PAIRS = 200_000


def collision_pair_bound(robot: Robot, request) -> int:
    """An upper bound on the shape pairs a collision request checks, without compiling them: every two link
    shapes (when self-collision is checked) and every link shape with every obstacle."""
    shapes = len(robot.collision)
    return (shapes * (shapes - 1) // 2 if request.self_collision else 0) + shapes * len(request.obstacles)


def is_small(robot: Robot, targets: IKTargets, options: AnswerOptions) -> bool:
    """:attr:`Cost.small`, decided without building anything (a plan or a collision model not yet kept makes the
    work not small): the closed form of a kept plan, no search, no family, an answer of at most
    :data:`SMALL_ROWS` rows, and a collision check of at most :data:`SMALL_PAIR_CHECKS` pair distances."""
    per_kind = targets.per_kind
    if robot.dof > 6 or options.free_joints is not None or per_kind[DIRECTION]:
        return False
    if options.collisions is not None and not model_is_kept(robot, options.collisions):
        return False  # compiling the pairs may take milliseconds
    if robot.dof > 3 and per_kind[POSITION]:  # a held joint may leave a point to the search
        return False
    most = 0
    for constrained in [kind == POSE for kind in (POSITION, POSE) if per_kind[kind]]:
        if not plan_is_kept(robot, constrain_orientation=constrained, reference=options.reference):
            return False
        plan = cached_plan(robot, constrain_orientation=constrained, reference=options.reference)
        if plan is None:
            return False
        most = max(most, plan.generic_count)
    limits = Limits.of(robot) if options.limits is None else options.limits
    kept = options.max_equivalents if options.ordering.max_solutions is None else min(
        options.max_equivalents, options.ordering.max_solutions)
    rows, _ = worst_answer_per_target(most, equivalents_per_solution(robot, limits), kept)
    count = len(targets.kinds)
    checks = 0 if options.collisions is None else count * most * len(model_for(robot, options.collisions).pairs)
    return count * rows <= SMALL_ROWS and checks <= SMALL_PAIR_CHECKS
