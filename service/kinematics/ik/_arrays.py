"""Closed-form IK end to end as arrays: candidates, FK check, merging, labels and order, with no loop over targets.

:func:`solve_ik_arrays` is the core of every analytic solve. The object API
(:func:`~service.kinematics.ik.solve_ik_batch`, :func:`~service.kinematics.ik.solve_ik`)
is a thin wrapper that turns its rows into :class:`Solution` records.

Layout: N targets, m candidate slots per target (the family's generic count,
e.g. 8 for the PUMA and the UR5), n joints. After merging and ordering the
solutions of target i are ``joints[i, :count[i]]``, in output order (nearest
to the reference first when one is given, else the family's slot order);
slots past ``count[i]`` hold no solution.
"""

from __future__ import annotations

import math
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from .._budget import UNLIMITED, Budget
from .._cache import is_memoised, memo
from .._robot import Robot
from .._tolerances import ACCEPT_RESIDUAL, POLISH_RESIDUAL
from ._plan import Plan, plan_for
from ._types import LabelCodes, SingularFlags
from ._verify import (accepted, distance_to_reference, first_of_each, first_of_each_one, polish, residual_arrays,
                      residuals_of_rows, wrap_revolute)
from ._structure import arm_size


@dataclass(frozen=True)
class IKArrays:
    """Every verified, distinct solution of a batch of targets, as arrays.

    Attributes
    ----------
    joints : ndarray, shape (N, m, n)
        Radians (revolute joints wrapped to (−π, π]) and length units. Row i
        holds target i's solutions in its first ``count[i]`` slots.
    valid : ndarray of bool, shape (N, m)
        ``valid[i, s]`` is ``s < count[i]``.
    count : ndarray of int, shape (N,)
        Solutions per target; 0 means unreachable.
    position, orientation : ndarrays, shape (N, m)
        FK residuals of each solution: length units and radians.
    labels : dict
        Branch labels: name → (values, codes of shape (N, m)), ``values[code]``
        being the label of a slot (e.g. ``"shoulder" → (("left", "right"), codes)``).
    singularities : SingularFlags
        The singular conditions each target meets (N rows).
    structure : str
        The kinematic family that solved it.
    free_joints : list of int
        Joints the target does not determine, set to the reference value (or 0).
    complete : ndarray of bool, shape (N,)
        Whether row i's solutions are known to be all of them. Always true for
        an exact closed form; a closed form on an idealised (rounded) arm sets
        it false where refinement cannot promise it (:mod:`._idealised`), and
        the general 6R solver where its algebra does not (:mod:`._general_6r`);
        the object API then asks the fallback solver.
    """

    joints: np.ndarray
    valid: np.ndarray
    count: np.ndarray
    position: np.ndarray
    orientation: np.ndarray
    labels: LabelCodes
    singularities: SingularFlags
    structure: str
    free_joints: list[int]
    complete: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.complete is None:
            object.__setattr__(self, "complete", np.ones(len(self.count), dtype=bool))

    def take(self, rows: np.ndarray) -> "IKArrays":
        """The answer for the targets ``rows`` (indices) only, in that order."""
        singularities = SingularFlags(len(rows))
        for mask, flag in self.singularities.entries:
            singularities.add(mask[rows], flag)
        return IKArrays(self.joints[rows], self.valid[rows], self.count[rows], self.position[rows],
                        self.orientation[rows], {name: (values, codes[rows]) for name, (values, codes)
                                                 in self.labels.items()},
                        singularities, self.structure, self.free_joints, self.complete[rows])


def arrays_from_results(robot: Robot, results: list) -> IKArrays:
    """N :class:`IKResult` records (the fallback's, the position search's) as one :class:`IKArrays`.

    Row i holds result i's solutions in their order, padded to the most
    solutions of any result; branch labels become codes (names and values in
    order of first appearance); each result's singularities its row's flags.
    ``structure`` and ``free_joints`` are the first result's: the records keep
    their own.
    """
    n_targets, width = len(results), max([len(result.solutions) for result in results], default=0)
    joints = np.zeros((n_targets, width, robot.dof))
    position, orientation = np.full((n_targets, width), np.inf), np.full((n_targets, width), np.inf)
    count = np.array([len(result.solutions) for result in results], dtype=int)
    vocabularies: dict[str, list] = {}
    for result in results:
        for solution in result.solutions:
            for name, value in solution.branch.items():
                vocabulary = vocabularies.setdefault(name, [])
                if value not in vocabulary:
                    vocabulary.append(value)
    codes = {name: np.full((n_targets, width), -1, dtype=np.int8) for name in vocabularies}
    singularities = SingularFlags(n_targets)
    for row, result in enumerate(results):
        for slot, solution in enumerate(result.solutions):
            joints[row, slot] = solution.joints
            position[row, slot], orientation[row, slot] = solution.position_residual, solution.orientation_residual
            for name, value in solution.branch.items():
                codes[name][row, slot] = vocabularies[name].index(value)
        for singularity in result.singularities:
            mask = np.zeros(n_targets, dtype=bool)
            mask[row] = True
            singularities.add(mask, singularity)
    first = results[0] if results else None
    return IKArrays(joints=joints, valid=np.arange(width) < count[:, None], count=count, position=position,
                    orientation=orientation,
                    labels={name: (tuple(vocabularies[name]), codes[name]) for name in vocabularies},
                    singularities=singularities, structure=first.structure if first else "general",
                    free_joints=list(first.free_joints) if first else [],
                    complete=np.array([result.complete for result in results], dtype=bool))


def cached_plan(robot: Robot, *, constrain_orientation: bool, reference: np.ndarray | None) -> Plan | None:
    """:func:`plan_for`, built once per robot and kind of target (and values of the free joints).

    A position-only target on an arm with more than three joints holds the
    others at the reference values: those plans depend on the values and are
    built each time rather than kept.
    """
    key = _plan_key(robot, constrain_orientation, reference)
    if key is None:
        return plan_for(robot, constrain_orientation=False, reference=reference)
    return memo(robot, key, lambda: plan_for(robot, constrain_orientation=constrain_orientation, reference=None))


def plan_is_kept(robot: Robot, *, constrain_orientation: bool, reference: np.ndarray | None) -> bool:
    """Whether :func:`cached_plan` would answer without building a plan."""
    key = _plan_key(robot, constrain_orientation, reference)
    return key is not None and is_memoised(robot, key)


def _plan_key(robot: Robot, constrain_orientation: bool, reference: np.ndarray | None) -> tuple[str, str] | None:
    """The memo key of a kept plan; None for a plan built for the reference's values each time."""
    if constrain_orientation:
        return ("ik_plan", "pose")
    if robot.dof <= 3 or reference is None:
        return ("ik_plan", "position")
    return None


#: Targets solved together: large enough that per-operation overhead is small, small enough that the
#: (chunk × m × n) temporaries stay in cache and memory is bounded whatever the batch size.
CHUNK = 4096


def solve_ik_arrays(robot: Robot, world_T_targets: np.ndarray, *, constrain_orientation: bool = True,
                    reference: np.ndarray | None = None, plan: Plan | None = None,
                    threads: int | None = None, budget: Budget = UNLIMITED) -> IKArrays | None:
    """Every solution for each of N targets, vectorised over the targets.

    Parameters
    ----------
    world_T_targets : ndarray, shape (N, 4, 4)
        Targets in the world frame; with ``constrain_orientation`` false only
        their positions count.
    reference : ndarray, shape (n,), optional
        Orders each target's solutions nearest first (wrap-aware, largest
        single joint move) and sets joints that are free at a singularity.
    plan : optional
        The analytic plan to use (default: the cached one for this robot).

    Returns
    -------
    IKArrays, or None when no analytic family covers this robot (the object
    API then runs the numeric fallback).

    Every candidate is checked by FK: it is kept when its position error is
    within ``ACCEPT_RESIDUAL`` times the robot's size and its orientation error
    within ``ACCEPT_RESIDUAL`` radians; candidates close to that get a few
    Gauss–Newton steps first. Candidates equal to an earlier kept one modulo
    2π (within ``DUPLICATE_TOLERANCE``) are merged into it.

    A batch larger than :data:`CHUNK` is solved in chunks, on up to
    ``threads`` threads (default: one per CPU); numpy releases the GIL inside
    its array operations, so the chunks run in parallel. ``budget`` is
    checked before each chunk.
    """
    if plan is None:
        plan = cached_plan(robot, constrain_orientation=constrain_orientation, reference=reference)
        if plan is None:
            return None
    targets = np.asarray(world_T_targets, dtype=float)
    if len(targets) > CHUNK:
        chunks = [targets[start:start + CHUNK] for start in range(0, len(targets), CHUNK)]
        workers = min(threads or os.cpu_count() or 1, len(chunks))

        def solve(chunk: np.ndarray) -> IKArrays:
            budget.check("the analytic solve")
            return _solve_chunk(robot, chunk, constrain_orientation, reference, plan)

        if workers > 1:
            with ThreadPoolExecutor(workers) as pool:
                parts = list(pool.map(solve, chunks))
        else:
            parts = [solve(chunk) for chunk in chunks]
        return concatenated(parts)
    budget.check("the analytic solve")
    return _solve_chunk(robot, targets, constrain_orientation, reference, plan)


def concatenated(parts: list[IKArrays]) -> IKArrays:
    """One IKArrays holding the rows of ``parts`` in turn (consecutive chunks of targets, or several answers for
    one target), padded to the widest part's slots (a solver may give each part only as many slots as it needs, as
    the general 6R solver does); labels joined by :func:`joined_label_codes`."""
    width = max(p.joints.shape[1] for p in parts)
    parts = [_padded(p, width) for p in parts]
    singularities = SingularFlags(sum(len(p.count) for p in parts))
    offset = 0
    for part in parts:
        for mask, flag in part.singularities.entries:
            full = np.zeros(singularities.count, dtype=bool)
            full[offset:offset + len(mask)] = mask
            singularities.add(full, flag)
        offset += len(part.count)
    first = parts[0]
    return IKArrays(
        joints=np.concatenate([p.joints for p in parts]), valid=np.concatenate([p.valid for p in parts]),
        count=np.concatenate([p.count for p in parts]), position=np.concatenate([p.position for p in parts]),
        orientation=np.concatenate([p.orientation for p in parts]),
        labels=joined_label_codes([p.labels for p in parts], [p.valid.shape for p in parts]),
        singularities=singularities, structure=first.structure, free_joints=first.free_joints,
        complete=np.concatenate([p.complete for p in parts]))


def joined_label_codes(pieces: list[LabelCodes], shapes: list[tuple[int, ...]]) -> LabelCodes:
    """The label codes of several pieces laid end to end (along axis 0). A name's values are those of the first
    piece that has it, the others' codes mapped onto them; −1 where a piece lacks the name (its codes' shape
    in ``shapes``) or the value."""
    names: dict[str, tuple] = {}
    for piece in pieces:
        for name, (values, _) in piece.items():
            names.setdefault(name, values)
    joined: LabelCodes = {}
    for name, values in names.items():
        columns = []
        for piece, shape in zip(pieces, shapes):
            if name in piece:
                own, codes = piece[name]
                remap = np.array([values.index(v) if v in values else -1 for v in own] + [-1], dtype=np.int8)
                columns.append(remap[codes])
            else:
                columns.append(np.full(shape, -1, dtype=np.int8))
        joined[name] = (values, np.concatenate(columns))
    return joined


def _padded(part: IKArrays, width: int) -> IKArrays:
    """``part`` with empty slots appended up to ``width`` (no solution in them: invalid, label code −1)."""
    extra = width - part.joints.shape[1]
    if extra == 0:
        return part
    def pad(array: np.ndarray, value) -> np.ndarray:
        widths = [(0, 0), (0, extra)] + [(0, 0)] * (array.ndim - 2)
        return np.pad(array, widths, constant_values=value)
    return IKArrays(joints=pad(part.joints, 0.0), valid=pad(part.valid, False), count=part.count,
                    position=pad(part.position, np.inf), orientation=pad(part.orientation, np.inf),
                    labels={name: (values, pad(codes, -1)) for name, (values, codes) in part.labels.items()},
                    singularities=part.singularities, structure=part.structure, free_joints=part.free_joints,
                    complete=part.complete)


def _solve_chunk(robot: Robot, targets: np.ndarray, constrain_orientation: bool, reference: np.ndarray | None,
                 plan: Plan) -> IKArrays:
    if len(targets) == 1:  # one pose: the family's scalar path when it has one and the pose is clearly generic
        answer = solve_one_pose(robot, targets[0], constrain_orientation, reference, plan)
        if answer is not None and (answer.count or not answer.singularities.entries):
            return answer.arrays()  # (no solution at a singular condition: the array path weighs the promise)
    candidates = plan.solve(targets, reference)
    n_targets, m, n = candidates.joints.shape
    joints = wrap_revolute(robot, np.nan_to_num(candidates.joints))
    position, orientation = residual_arrays(robot, joints, targets)
    _polish_near(robot, joints, targets, position, orientation, candidates.valid, constrain_orientation)
    ok = candidates.valid & accepted(robot, position, orientation, constrain_orientation)
    kept = first_of_each(robot, joints, ok)
    labels = plan.label_codes(joints.reshape(-1, n))
    # output order: kept slots first, nearest to the reference first, else in slot order (stable)
    if reference is not None:
        key = np.where(kept, distance_to_reference(robot, joints, reference), np.inf)
        order = np.argsort(key, axis=1, kind="stable")
    else:
        order = np.argsort(~kept, axis=1, kind="stable")
    count = kept.sum(axis=1)
    error = position / arm_size(robot)
    if constrain_orientation:
        error = np.maximum(error, orientation)
    complete = _promised(candidates, count, np.where(candidates.valid, error, np.inf).min(axis=1),
                         constrain_orientation)
    if candidates.promise_needs_every_slot:  # the solver's promise holds only if every valid slot gave a solution
        complete &= count == candidates.valid.sum(axis=1)
    take = (np.arange(n_targets)[:, None], order)
    return IKArrays(
        joints=joints[take], valid=kept[take], count=count,
        position=position[take], orientation=orientation[take],
        labels={name: (values, codes.reshape(n_targets, m)[take]) for name, (values, codes) in labels.items()},
        singularities=candidates.singularities, structure=plan.structure, free_joints=list(plan.free_joints),
        complete=complete)


class OnePoseAnswer:
    """:func:`_solve_chunk`'s answer for one target, from :func:`solve_one_pose`, as lists in output order.

    ``rows`` holds the m slots' joint vectors, the ``count`` solutions first;
    ``position`` and ``orientation`` their FK residuals; ``codes`` one list of
    label codes per name of ``names`` (values ``values``), −1 past ``count``.
    :meth:`arrays` is the :class:`IKArrays` of it; the object API reads the
    lists directly.
    """

    __slots__ = ("rows", "count", "position", "orientation", "names", "values", "codes", "plan", "singularities")

    def __init__(self, rows, count, position, orientation, names, values, codes, plan, singularities) -> None:
        self.rows, self.count, self.position, self.orientation = rows, count, position, orientation
        self.names, self.values, self.codes, self.plan, self.singularities = names, values, codes, plan, singularities

    def arrays(self) -> IKArrays:
        valid = np.zeros((1, len(self.rows)), dtype=bool)
        valid[0, :self.count] = True
        residuals = np.array([self.position, self.orientation])
        codes = np.array(self.codes, dtype=np.int8).reshape(len(self.names), 1, -1)
        return IKArrays(joints=np.array(self.rows)[None], valid=valid, count=np.array([self.count]),
                        position=residuals[:1], orientation=residuals[1:],
                        labels={name: (values, column) for name, values, column in zip(self.names, self.values, codes)},
                        singularities=self.singularities, structure=self.plan.structure,
                        free_joints=list(self.plan.free_joints), complete=np.ones(1, dtype=bool))


def solve_one_pose(robot: Robot, target: np.ndarray, constrain_orientation: bool, reference: np.ndarray | None,
                   plan: Plan) -> OnePoseAnswer | None:
    """:func:`_solve_chunk` for one target (4, 4) on the family's scalar path (``plan.solve_one``, which labels
    its slots as it solves), in plain floats: the same FK check (:func:`residuals_of_rows`), duplicate scan
    (:func:`first_of_each_one`) and order. None, for the array path to decide, when the family has no scalar
    path, the pose is not clearly generic, a candidate would be polished, or a kept slot's label is not clear."""
    solve_one = getattr(plan, "solve_one", None)
    one_pose = solve_one(target) if solve_one is not None else None
    if one_pose is None:
        return None
    size = arm_size(robot)
    rows = one_pose.rows
    verified = iter(residuals_of_rows(robot, [q for q in rows if q is not None], target[:3].tolist()))
    ok, position, orientation = [], [], []
    for q in rows:
        p, o = next(verified) if q is not None else (math.inf, math.inf)
        error = max(p / size, o) if constrain_orientation else p / size
        if q is not None and _POLISH_FROM < error <= POLISH_RESIDUAL:  # the array path polishes it
            return None
        ok.append(p <= ACCEPT_RESIDUAL * size and (o <= ACCEPT_RESIDUAL or not constrain_orientation))  # accepted()
        position.append(p)
        orientation.append(o)
    rows = [q if q is not None else [0.0] * robot.dof for q in rows]
    kept = first_of_each_one(robot, rows, ok)
    codes = one_pose.code_lists(kept)
    if codes is None:
        return None
    # output order: kept slots first, nearest to the reference first, else in slot order (stable)
    slots = range(len(rows))
    if reference is not None:
        difference = wrap_revolute(robot, np.array(rows) - reference)
        distance = np.abs(difference).max(axis=1).tolist()
        order = sorted(slots, key=lambda s: distance[s] if kept[s] else math.inf)
    else:
        order = [s for s in slots if kept[s]] + [s for s in slots if not kept[s]]
    return OnePoseAnswer([rows[s] for s in order], sum(kept), [position[s] for s in order],
                         [orientation[s] for s in order], one_pose.names, one_pose.values,
                         [[column[s] for s in order] for column in codes], plan, one_pose.singularities)


#: Candidates with errors above this (and up to ``POLISH_RESIDUAL``) get Gauss–Newton steps (:func:`_polish_near`).
_POLISH_FROM = ACCEPT_RESIDUAL * 1e-3


#: Singular relations under which a family's "no solution" is not a proof: it set a joint it found undetermined to
#: the reference value (or 0), or two roots met (a double root that rounding can push just off the real line).
_FRAGILE_RELATIONS = frozenset({"free", "sum", "difference", "signed_sum",
                                "boundary", "stretched", "folded", "stretched_or_folded"})


def _promised(candidates, count: np.ndarray, nearest: np.ndarray, constrain_orientation: bool) -> np.ndarray:
    """Which rows (N,) may claim every solution: the family's own word (:attr:`Candidates.complete`), except for
    rows with no verified solution where the family set a joint it found free or saw two roots meet:

    * whose nearest candidate missed by less than ``POLISH_RESIDUAL`` (``nearest`` (N,): fraction of the arm's
      size, or radians): the representative it chose, or the double root, failed narrowly; another value of
      that joint, or the root pair a rounding error moved off the real line, may not (an arm whose remaining
      axes are not exactly aligned with the free one, as rounded geometry gives);
    * on a pose target, a joint left free (relation ``free``) where some candidate reached the position: the
      position does not fix that joint, the orientation (or the joints after it) may, and the value the family
      held it at is one of many. Where no candidate was valid, the family found the position out of reach
      whatever the free joint (a family whose free joint changes the reach says so itself, through
      :attr:`Candidates.complete`).

    Those rows go to the fallback."""
    complete = np.ones(len(count), dtype=bool) if candidates.complete is None else candidates.complete.copy()
    narrow = (count == 0) & (nearest <= POLISH_RESIDUAL)
    for mask, flag in candidates.singularities.entries:
        if flag.relation in _FRAGILE_RELATIONS:
            complete &= ~(mask & narrow)
        if constrain_orientation and flag.relation == "free":
            complete &= ~(mask & (count == 0) & candidates.valid.any(axis=1))
    return complete


def _polish_near(robot: Robot, joints: np.ndarray, targets: np.ndarray, position: np.ndarray,
                 orientation: np.ndarray, valid: np.ndarray, constrain_orientation: bool) -> None:
    """Refine, in place, candidates close to their target but outside the acceptance tolerance."""
    size = np.maximum(position / arm_size(robot), orientation if constrain_orientation else 0.0)
    near = valid & (size > _POLISH_FROM) & (size <= POLISH_RESIDUAL)
    if not near.any():
        return
    rows, slots = np.nonzero(near)
    refined = wrap_revolute(robot, polish(robot, joints[rows, slots], targets[rows], constrain_orientation))
    joints[rows, slots] = refined
    p, o = residual_arrays(robot, refined[:, None, :], targets[rows])
    position[rows, slots], orientation[rows, slots] = p[:, 0], o[:, 0]
