"""Every candidate checked by forward kinematics, duplicates merged: a solver's candidates become a table.

No solution leaves the core unless FK of it reproduces its target within a tolerance relative to the robot's
size. :func:`verify` is the one place where that happens, for every solver (the closed forms, a redundant arm's
family, direction targets, the numeric search): candidates close to their target get a few Gauss–Newton steps
first (:mod:`._gauss_newton`), candidates equal to an earlier kept one modulo 2π are merged into it, and the
solver's promise that a target's solutions are all of them is weighed against what verified
(:func:`promised`).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .._cache import memo
from .._forward import JointTrig
from .._robot import Robot
from .._angles import wrap_angle, wrap_any_float
from .._tolerances import ACCEPT_RESIDUAL, DUPLICATE_TOLERANCE, POLISH_RESIDUAL, ROUNDING_TOLERANCE
from ._gauss_newton import gauss_newton
from ._goals import Goal, PoseGoal, pose_residuals_of_rows
from ._structure import arm_size
from ._table import SolutionTable, branch_labels
from ._types import Candidates, LabelCodes, SingularFlags, every

#: Candidates with errors above this (and up to ``POLISH_RESIDUAL``) get Gauss–Newton steps before the check.
POLISH_FROM = ACCEPT_RESIDUAL * 1e-3
#: Gauss–Newton steps of that polish: near a singularity a closed form loses digits that one or two restore.
POLISH_STEPS = 3

#: Singular relations under which a family's "no solution" is not a proof: it set a joint it found undetermined to
#: the reference value (or 0), or two roots met (a double root that rounding can push just off the real line).
FRAGILE_RELATIONS = frozenset({"free", "sum", "difference", "signed_sum",
                               "boundary", "stretched", "folded", "stretched_or_folded"})


def wrap_revolute(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Revolute joint values wrapped to (−π, π]; prismatic values unchanged. Shape (..., n), a new array."""
    if robot.is_revolute.all():  # the usual arm: no pass to keep prismatic values
        return wrap_angle(q)
    return np.where(robot.is_revolute, wrap_angle(q), q)


def joint_difference(robot: Robot, q: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """q − reference with revolute differences taken across the 2π wrap, in (−π, π]. Shape (..., n)."""
    return wrap_revolute(robot, np.asarray(q) - reference)


def distance_to_reference(robot: Robot, q: np.ndarray, reference: np.ndarray, *, norm: str = "linf",
                          weights: np.ndarray | None = None) -> np.ndarray:
    """Wrap-aware distance of each row of q (..., n) from the reference, shape (...,).

    ``norm`` is ``"linf"`` (the largest single joint move, the default) or ``"l2"``; ``weights`` scale each
    joint's difference.
    """
    difference = np.abs(joint_difference(robot, q, reference))
    if weights is not None:
        difference = difference * weights
    return difference.max(axis=-1) if norm == "linf" else np.linalg.norm(difference, axis=-1)


def linf_distances_of_rows(robot: Robot, rows: list[list[float]], reference: list[float]) -> list[float]:
    """:func:`distance_to_reference` (``linf``, no weights) of a few rows of n floats, on floats, bit for bit."""
    revolute = robot.is_revolute.tolist()
    return [max([abs(wrap_any_float(value - at)) if turns else abs(value - at)
                 for value, at, turns in zip(row, reference, revolute)]) for row in rows]


def residuals(robot: Robot, q: np.ndarray, world_T_target: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Position (length units) and orientation (radians) errors of FK(q) against the target: k candidates (k, n)
    for one target (4, 4), or one candidate per target (k, 4, 4). Returns shape (k,) each."""
    q, world_T_target = np.asarray(q, dtype=float), np.asarray(world_T_target, dtype=float)
    if world_T_target.ndim == 2:
        position, orientation = PoseGoal(world_T_target[None]).residuals(robot, q[None])
        return position[0], orientation[0]
    position, orientation = PoseGoal(world_T_target).residuals(robot, q[:, None])
    return position[:, 0], orientation[:, 0]


def residual_arrays(robot: Robot, q: np.ndarray, world_T_targets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`residuals` of m candidates per target: q (N, m, n), targets (N, 4, 4) → (N, m) each."""
    return PoseGoal(np.asarray(world_T_targets, dtype=float)).residuals(robot, np.asarray(q, dtype=float))


def error_size(robot: Robot, position, orientation, constrain_orientation: bool, size_of_arm: float | None = None):
    """One number per residual pair: the position error as a fraction of the arm's size (``size_of_arm``, read
    once by a caller with many floats, or :func:`arm_size`), or the larger of that and the orientation error
    (radians). Arrays, or one pair of floats (:func:`verify_one`); a NaN error either way gives NaN."""
    size = position / (arm_size(robot) if size_of_arm is None else size_of_arm)
    if not constrain_orientation:
        return size
    if type(size) is float:  # np.maximum's rule on floats, without its cost per call
        return size if size >= orientation or size != size else orientation
    return np.maximum(size, orientation)


def accepted(robot: Robot, position: np.ndarray, orientation: np.ndarray, constrain_orientation: bool) -> np.ndarray:
    """Which residuals pass the FK check."""
    return error_size(robot, position, orientation, constrain_orientation) <= ACCEPT_RESIDUAL


def polished(size):
    """Whether candidates of these error sizes (:func:`error_size`: an array, or a float) get Gauss–Newton steps
    before the check: near their target, not yet within it."""
    return (size > POLISH_FROM) & (size <= POLISH_RESIDUAL)


def duplicate_tolerance(robot: Robot) -> np.ndarray:
    """Per joint (n,), how close two solutions' values must be to count as one: ``DUPLICATE_TOLERANCE`` radians
    for a revolute joint, that times the arm's size for a prismatic one."""
    return memo(robot, "ik_duplicate_tolerance", lambda: _read_only(
        np.where(robot.is_revolute, DUPLICATE_TOLERANCE, DUPLICATE_TOLERANCE * arm_size(robot))))


def _read_only(array: np.ndarray) -> np.ndarray:
    """``array``, no longer writeable: a value kept on the robot and shared."""
    array.flags.writeable = False
    return array


#: Most slots compared pairwise at once (N × m(m − 1)/2 pairs of n values): past it the targets go in chunks, and
#: a target of more slots than :data:`_PAIRWISE_SLOTS` (the numeric search's starts) is scanned against the
#: solutions kept so far, so memory stays bounded whatever the number of starts.
_PAIR_ENTRIES = 1 << 20
_PAIRWISE_SLOTS = 32


def first_of_each(robot: Robot, joints: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """Which slots (N, m) hold the first occurrence of a distinct solution among the ``ok`` ones.

    ``joints`` (N, m, n) has its revolute joints wrapped to (−π, π]; they are compared modulo 2π, each joint
    within :func:`duplicate_tolerance`. A slot is dropped when it equals a slot kept before it, exactly as a
    sequential scan would.
    """
    n_targets, m, n = joints.shape
    if m == 1:
        return ok.copy()
    tolerance = duplicate_tolerance(robot)
    revolute = robot.is_revolute
    if m > _PAIRWISE_SLOTS:
        return np.stack([_scanned(joints[row], ok[row], tolerance, revolute) for row in range(n_targets)]) \
            if n_targets else ok.copy()
    if n_targets == 1:
        kept = ok.copy()
        kept[0] = first_of_each_slot(robot, joints[0].tolist(), kept[0].tolist())
        return kept
    earlier, later = _slot_pairs(m)
    chunk = max(1, _PAIR_ENTRIES // max(1, len(later) * n))
    kept = ok.copy()
    for start in range(0, n_targets, chunk):
        block = slice(start, start + chunk)
        same = _same_pairs(joints[block], earlier, later, tolerance, revolute)  # (b, pairs)
        if not same.any():  # no two slots one solution: every ok slot is a first occurrence
            continue
        # the sequential scan over slots, on booleans only: the pairs of slot s are those with later == s
        offset = 0
        for slot in range(1, m):
            kept[block, slot] &= ~np.any(same[:, offset:offset + slot] & kept[block, :slot], axis=1)
            offset += slot
    return kept


def first_of_each_slot(robot: Robot, rows: Sequence[Sequence[float]], ok: list[bool]) -> list[bool]:
    """:func:`first_of_each` of one target's few slots ``rows`` (m, n: lists of floats), ``ok`` and the result as
    lists (m,): each ok slot against the distinct slots kept before it, joint by joint from the last (where
    distinct solutions mostly differ, as :func:`_same_pairs` screens) until one is apart. For a handful of slots
    this is a few comparisons per pair, where the pairwise arrays cost a dozen array operations.

    The comparisons are :func:`_same`'s on the same values: a revolute gap past π is taken from 2π (numpy's
    ``minimum(gap, 2π − gap)``, an infinite gap included), and a NaN gap is apart."""
    joints, turns, within = _duplicate_rule(robot)
    pi, two_pi = math.pi, 2 * math.pi
    last, before_last = joints[0], joints[1:]
    last_turns, last_within = turns[last], within[last]
    kept: list[bool] = []
    distinct: list[tuple[Sequence[float], float]] = []  # the slots kept, each with its last joint's value
    for q, keep in zip(rows, ok):
        if keep:
            value = q[last]
            for other, other_value in distinct:
                gap = abs(value - other_value)
                if last_turns and gap > pi:
                    gap = two_pi - gap
                if not gap <= last_within:
                    continue  # the last joint is apart: another solution (most pairs end here)
                for j in before_last:
                    gap = abs(q[j] - other[j])
                    if turns[j] and gap > pi:
                        gap = two_pi - gap
                    if not gap <= within[j]:
                        break  # this joint is apart: another solution
                else:  # every joint within its tolerance: the same solution as one kept before
                    keep = False
                    break
            if keep:
                distinct.append((q, value))
        kept.append(keep)
    return kept


def _duplicate_rule(robot: Robot) -> tuple[range, list[bool], list[float]]:
    """The joints from the last to the first, and per joint whether it is revolute and its
    :func:`duplicate_tolerance`, as floats (kept per robot)."""
    return memo(robot, "ik_duplicate_check",
                lambda: (range(robot.dof - 1, -1, -1), robot.is_revolute.tolist(),
                         duplicate_tolerance(robot).tolist()))


def _same_pairs(joints: np.ndarray, earlier: np.ndarray, later: np.ndarray, tolerance: np.ndarray,
                revolute: np.ndarray) -> np.ndarray:
    """Which pairs of slots (``earlier``, ``later``, (P,) each) of each target's ``joints`` (b, m, n) are one
    solution, shape (b, P): screened on the last joint alone (distinct solutions mostly differ there), then
    :func:`_same` on every joint of the pairs that pass, so that only those gaps are gathered whole."""
    last = joints[:, :, -1]
    close = _same(np.abs(last[:, later] - last[:, earlier])[..., None], tolerance[-1:], revolute[-1:])
    rows, pairs = np.nonzero(close)
    if len(rows):
        close[rows, pairs] = _same(np.abs(joints[rows, later[pairs]] - joints[rows, earlier[pairs]]), tolerance,
                                   revolute)
    return close


def _same(gap: np.ndarray, tolerance: np.ndarray, revolute: np.ndarray) -> np.ndarray:
    """Which pairs of joint vectors are one solution, from their gaps |a − b| (..., n) (overwritten): every joint
    within ``tolerance`` (n,), revolute ones modulo 2π. Shape (...)."""
    # wrapped values: a revolute difference d lies in (−2π, 2π), and |wrap(d)| = min(|d|, 2π − |d|)
    if revolute.all():
        np.minimum(gap, 2 * np.pi - gap, out=gap)
    elif revolute.any():
        gap[..., revolute] = np.minimum(gap[..., revolute], 2 * np.pi - gap[..., revolute])
    return (gap <= tolerance).all(axis=-1)


@functools.lru_cache(maxsize=_PAIRWISE_SLOTS)
def _slot_pairs(m: int) -> tuple[np.ndarray, np.ndarray]:
    """Every pair of m slots (earlier, later), grouped by the later slot: (0, 1), (0, 2), (1, 2), (0, 3), …"""
    later, earlier = np.tril_indices(m, -1)  # row-major: grouped by the row, the later slot
    earlier.flags.writeable = later.flags.writeable = False
    return earlier, later


def _scanned(joints: np.ndarray, ok: np.ndarray, tolerance: np.ndarray, revolute: np.ndarray) -> np.ndarray:
    """:func:`first_of_each` for one target of many slots (m, n): each ok slot against the distinct ones so far."""
    kept = np.zeros(len(ok), dtype=bool)
    distinct = np.zeros((0, joints.shape[1]))
    for slot in np.flatnonzero(ok).tolist():
        if not _same(np.abs(distinct - joints[slot]), tolerance, revolute).any():
            kept[slot] = True
            distinct = np.vstack([distinct, joints[slot]])
    return kept


@dataclass(frozen=True)
class Verified:
    """A solver's answer for N targets after the FK check.

    ``table`` holds every distinct verified solution, grouped by target, each target's in the solver's slot
    order; ``complete`` (N,) whether the solver's promise that they are all of them stands; ``nearest`` (N,)
    the smallest error of any candidate (:func:`error_size`; ∞ where there was none), which says whether the
    target was narrowly missed; ``singularities`` the conditions the solver met (N rows).
    """

    table: SolutionTable
    complete: np.ndarray
    nearest: np.ndarray
    singularities: SingularFlags

    @functools.cached_property
    def count(self) -> np.ndarray:
        """Solutions per target, shape (N,), read-only (counted once: the answer reads it several times)."""
        return _read_only(self.table.counts(len(self.complete)))


def verify(robot: Robot, goal: Goal, candidates: Candidates, reference: np.ndarray | None = None,
           label_codes: Callable[[np.ndarray, JointTrig], LabelCodes] | None = None,
           held: np.ndarray | None = None) -> Verified:
    """The verified, distinct solutions among ``candidates`` (N, m, n) for the goal's N targets: each target's
    in slot order, or nearest the ``reference`` (n,) first (wrap-aware, the largest joint move; ties in slot
    order).

    Labels are the candidates' own; ``label_codes`` labels joint vectors (M, n) for a solver that gives none,
    with the cos and sin of their joints that the FK check computed (a :class:`JointTrig`).
    The joints ``held`` ((n,) bool: a redundant arm's free joints at the values asked) keep their values exactly
    when a candidate is polished.
    """
    n_targets, m, n = candidates.joints.shape
    raw = candidates.joints
    joints = np.ascontiguousarray(wrap_revolute(robot, raw if np.isfinite(raw).all() else np.nan_to_num(raw)))
    rows_of_joints = joints.reshape(-1, n)  # a view: the polish below writes through it
    trig = JointTrig(rows_of_joints)  # computed by the FK check, shared with the labels
    position, orientation = goal.residuals(robot, joints, trig)
    constrained = goal.constrain_orientation
    valid = candidates.valid
    size = error_size(robot, position, orientation, constrained)
    checked = valid | _unvouched(valid, size)[:, None]
    near = checked & polished(size)
    if near.any():
        rows, slots = np.nonzero(near)
        refined = gauss_newton(robot, goal, joints[rows, slots], rows, steps=POLISH_STEPS, tolerance=POLISH_FROM,
                               moving=None if held is None else ~held)
        joints[rows, slots] = wrap_revolute(robot, refined.joints)
        trig.renew(rows * m + slots)
        p, o = _residuals_at(robot, goal, joints[rows, slots], rows)
        position[rows, slots], orientation[rows, slots] = p, o
        size[rows, slots] = error_size(robot, p, o, constrained)
    kept = first_of_each(robot, joints, checked & (size <= ACCEPT_RESIDUAL))
    count = kept.sum(axis=1)
    nearest = np.where(valid, size, np.inf).min(axis=1, initial=np.inf)
    nearest_position = None
    if isinstance(goal, PoseGoal) and constrained and robot.dof < 6:  # fewer joints than the pose constrains
        nearest_position = np.where(checked, position, np.inf).min(axis=1, initial=np.inf) / arm_size(robot)
    complete = promised(candidates, count, nearest, constrained, nearest_position)
    if candidates.near_singular is not None and complete.any():
        complete &= ~not_isolated(robot, goal, joints, kept & candidates.near_singular, size,
                                  candidates.singularities)
    if candidates.promise_needs_every_slot:  # the solver's promise holds only if every valid slot gave a solution
        complete &= count == valid.sum(axis=1)
    labels = candidates.labels if candidates.labels is not None else (
        {} if label_codes is None else {name: (values, codes.reshape(n_targets, m))
                                        for name, (values, codes) in label_codes(rows_of_joints, trig).items()})
    if reference is None:
        rows, slots = np.nonzero(kept)
    else:
        key = np.where(kept, distance_to_reference(robot, joints, reference), np.inf)
        order = np.argsort(key, axis=1, kind="stable")
        rows = np.repeat(np.arange(n_targets), count)
        slots = order[np.arange(order.shape[1]) < count[:, None]]
    table = SolutionTable(rows.astype(np.int64), joints[rows, slots], np.ones(len(rows), dtype=bool),
                          position[rows, slots],
                          orientation[rows, slots] if constrained else np.full(len(rows), np.nan),
                          {name: (values, codes[rows, slots].astype(np.int8, copy=False))
                           for name, (values, codes) in labels.items()})
    return Verified(table, complete, nearest, candidates.singularities)


#: The least singular value of the arm's Jacobian (position rows over the arm's size, :meth:`PoseGoal.jacobian`)
#: below which a verified solution is taken as not isolated in double precision: other joint vectors along its
#: null motion reach the pose to rounding as well. Where two singular sets meet the value is about the product of
#: the distances from each: 2e-16 … 3e-14 at the solutions of the promises the probes found broken (they listed
#: members 1.2e-3 … 0.8 rad from the pose's own configuration, :data:`._types.NEAR_SINGULAR`). Near one set alone
#: the solution stays held though the value falls with the square of the distance at a fold: the Stanford arm with
#: its slide 1e-6 of its size from axis 2, 3e-13 to 5e-13, its own configuration listed within 6e-5 rad.
ISOLATED_BELOW = 1e-13

#: How far (radians, or fractions of the arm's size) a verified solution may be from the arm's exact solution
#: for it to stand for that one: its residual over the least singular value bounds that distance to first order.
#: A residual within ``ROUNDING_TOLERANCE`` is the FK's own rounding and says nothing of that distance: there
#: the least singular value alone decides (:data:`ISOLATED_BELOW`, the bound at a residual of 1e-16). Above it
#: the residual is the family's own miss: an OPW arm 1e-11 off its family, its wrist centre 1.6e-9 from axis 1,
#: listed q1 0.018 rad from the pose's own with a residual of 8e-12 and σ_min 3e-10 (a bound of 0.027).
ISOLATION_SPREAD = 1e-3


def not_isolated(robot: Robot, goal: PoseGoal, joints: np.ndarray, checked: np.ndarray, size: np.ndarray,
                 singularities: SingularFlags) -> np.ndarray:
    """The targets (N,) with a solution among the ``checked`` slots (N, m) of ``joints`` (N, m, n) that is not
    isolated, on a target the family flagged no singular condition for (a flag states what the listed solutions
    represent): its residual (``size`` (N, m), :func:`error_size`; one of rounding counts as ``ISOLATED_BELOW ·
    ISOLATION_SPREAD``) over the least singular value of the Jacobian is more than :data:`ISOLATION_SPREAD`. Such
    a target's solutions are one of many joint vectors that reach it within that residual: the family's list
    cannot promise to hold each of the others."""
    checked = checked & ~singularities.any()[:, None]
    rows, slots = np.nonzero(checked)
    outcome = np.zeros(len(joints), dtype=bool)
    if len(rows):
        least = np.linalg.svd(goal.jacobian(robot, joints[rows, slots], rows), compute_uv=False)[:, -1]
        residual = size[rows, slots]
        residual = np.where(residual > ROUNDING_TOLERANCE, residual, ISOLATED_BELOW * ISOLATION_SPREAD)
        outcome[rows[residual > ISOLATION_SPREAD * least]] = True
    return outcome


def _unvouched(valid: np.ndarray, size: np.ndarray) -> np.ndarray:
    """The targets (N,) none of whose valid candidates (N, m) comes within :data:`POLISH_RESIDUAL` of them
    (``size``, :func:`error_size`): there the FK check takes the family's other candidates too. A family
    fitted to an arm that deviates from it within the fit's tolerance (axes 1e-8 off parallel, as rounded
    geometry gives) may judge its own over-determined steps (a point's height, an orientation a roll must
    reach) inexact by about as much, on every candidate, where the arm reaches the target; the FK check, with
    its polish, is the judge of what reaches it."""
    return ~(valid & (size <= POLISH_RESIDUAL)).any(axis=1)


def verify_one(robot: Robot, goal: PoseGoal, one_pose, reference: np.ndarray | None = None) -> Verified | None:
    """:func:`verify` of one target's candidates from a family's scalar path (a :class:`~._scalar.OnePose`: slots
    as lists of floats, None where empty, each with its label codes), on floats: the same table (made from the
    rows kept when first read, :class:`OnePoseVerified`), promise and nearest miss. Only the valid slots are checked,
    and only the rows kept need a clear label (a least-squares slot the FK check rejects may sit where a label
    flips).

    None where :func:`verify` would polish a candidate, a candidate's error is NaN, or a kept row's label is not
    clear: then :func:`verify` of the candidates (or the array path) decides."""
    # the valid slots' joints (revolute ones wrapped already: verify's wrap leaves them) and label codes
    rows = [q for q in one_pose.rows if q is not None]
    codes = [code for q, code in zip(one_pose.rows, one_pose.codes) if q is not None]
    constrained = goal.constrain_orientation
    residuals = pose_residuals_of_rows(robot, rows, goal.world_T_targets[0, :3].tolist()) if rows else []
    size_of_arm = arm_size(robot)
    sizes, ok = [], []
    for position, orientation in residuals:
        size = error_size(robot, position, orientation, constrained, size_of_arm)
        if size != size or polished(size):  # a NaN error, or one verify would polish
            return None
        sizes.append(size)
        ok.append(size <= ACCEPT_RESIDUAL)
    kept = [row for row, keep in enumerate(first_of_each_slot(robot, rows, ok)) if keep]
    for row in kept:
        if None in codes[row]:
            return None
    if reference is not None and len(kept) > 1:  # nearest first (a stable sort, as the array path's)
        distance = linf_distances_of_rows(robot, [rows[row] for row in kept], reference.tolist())
        kept = [kept[i] for i in sorted(range(len(kept)), key=distance.__getitem__)]
    nearest = np.array([min(sizes, default=np.inf)])
    complete = promised(one_pose, np.array([len(kept)]), nearest, constrained)
    no_orientation = math.nan  # a position target's orientation residual, as the table holds it
    kept_rows = OnePoseRows([rows[row] for row in kept],
                            [residuals[row] if constrained else (residuals[row][0], no_orientation) for row in kept],
                            [codes[row] for row in kept], one_pose.names, one_pose.values)
    return OnePoseVerified(kept_rows, robot.dof, complete, nearest, one_pose.singularities)


class OnePoseRows(NamedTuple):
    """One target's verified, distinct solutions as :func:`verify_one` keeps them, on floats: ``joints`` (lists of
    n floats, revolute joints wrapped) in output order, their ``residuals`` ((position, orientation) pairs, the
    orientation NaN for a position target) and label ``codes`` (a tuple per row, one code per name of ``names``,
    read in ``values``)."""

    joints: list[list[float]]
    residuals: list[tuple[float, float]]
    codes: list[tuple[int, ...]]
    names: tuple[str, ...]
    values: tuple[tuple[str, ...], ...]

    def table(self, dof: int) -> SolutionTable:
        """The rows as target 0's :class:`SolutionTable`."""
        return one_pose_table([self], dof)

    def branches(self) -> list[dict]:
        """Each row's branch labels as a dict of its own (:meth:`SolutionTable.branches` of :meth:`table`)."""
        by_codes = branch_labels(self.names, self.values)
        return [by_codes[codes].copy() for codes in self.codes]


def one_pose_table(targets: list[OnePoseRows], dof: int) -> SolutionTable:
    """The rows of consecutive targets (one :class:`OnePoseRows` each, all with the same label names) as one
    :class:`SolutionTable`, its columns built once."""
    counts = [len(rows.joints) for rows in targets]
    count = sum(counts)  # each column contiguous (the arrays form encodes them as they stand)
    first = targets[0]
    if len(targets) == 1:
        joints, residuals, codes = first.joints, first.residuals, first.codes
        target = np.zeros(count, dtype=np.int64)
    else:
        joints = [q for rows in targets for q in rows.joints]
        residuals = [pair for rows in targets for pair in rows.residuals]
        codes = [code for rows in targets for code in rows.codes]
        target = np.repeat(np.arange(len(targets), dtype=np.int64), counts)
    position, orientation = zip(*residuals) if count else ((), ())
    columns = np.array(list(zip(*codes)), dtype=np.int8).reshape(len(first.names), count)
    labels = {name: (values, column) for name, values, column in zip(first.names, first.values, columns)}
    return SolutionTable(target, np.array(joints, dtype=float).reshape(count, dof), np.ones(count, dtype=bool),
                         np.array(position, dtype=float), np.array(orientation, dtype=float), labels)


class OnePoseVerified(Verified):
    """:class:`Verified` of one target from :func:`verify_one`: its ``rows`` (:class:`OnePoseRows`) on floats, the
    table made from them when first read (a one-pose record reads the floats and needs no table). Built here only
    (``dataclasses.replace`` does not rebuild it: a caller changing a table starts from :func:`verify`'s)."""

    def __init__(self, rows: OnePoseRows, dof: int, complete: np.ndarray, nearest: np.ndarray,
                 singularities: SingularFlags) -> None:
        # a frozen dataclass's fields, set as its generated __init__ sets them
        set_field = object.__setattr__
        set_field(self, "rows", rows)
        set_field(self, "dof", dof)
        set_field(self, "complete", complete)
        set_field(self, "nearest", nearest)
        set_field(self, "singularities", singularities)

    @functools.cached_property
    def table(self) -> SolutionTable:
        return self.rows.table(self.dof)

    @functools.cached_property
    def count(self) -> np.ndarray:
        return _read_only(np.array([len(self.rows.joints)]))


def _residuals_at(robot: Robot, goal: Goal, q: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The goal's residuals of one joint vector per listed target: q (K, n) against targets ``rows`` (K,)."""
    position, orientation = goal.take(rows).residuals(robot, q[:, None, :])
    return position[:, 0], orientation[:, 0]


def promised(candidates: Candidates, count: np.ndarray, nearest: np.ndarray, constrain_orientation: bool,
             nearest_position: np.ndarray | None = None) -> np.ndarray:
    """Which rows (N,) may claim every solution: the family's own word (:attr:`Candidates.complete`), except for
    rows with no verified solution where the family set a joint it found free or saw two roots meet:

    * whose nearest candidate missed by less than ``POLISH_RESIDUAL`` (``nearest`` (N,): fraction of the arm's
      size, or radians): the representative it chose, or the double root, failed narrowly; another value of
      that joint, or the root pair a rounding error moved off the real line, may not (an arm whose remaining
      axes are not exactly aligned with the free one, as rounded geometry gives). For an arm with fewer joints
      than the pose constrains (``nearest_position`` (N,) given: the smallest position error of any candidate
      checked, fraction of the arm's size), a narrow miss of the position alone counts too: the orientation it
      missed follows from joints the family read off that fragile position solution (a P-R-R arm rounded by
      1e-6 at a double root: the position missed by 3.5e-7, q2, read off a radius of that order, by 0.72 rad);
    * on a pose target, a joint left free (relation ``free``) where some candidate reached the position: the
      position does not fix that joint, the orientation (or the joints after it) may, and the value the family
      held it at is one of many. Where no candidate was valid, the family found the position out of reach
      whatever the free joint (a family whose free joint changes the reach says so itself, through
      :attr:`Candidates.complete`).

    Those rows go to the fallback."""
    complete = np.ones(len(count), dtype=bool) if candidates.complete is None else candidates.complete.copy()
    if every(count):  # both exceptions are about rows without a solution
        return complete
    empty = count == 0
    narrow = empty & (nearest <= POLISH_RESIDUAL)
    if nearest_position is not None:
        narrow |= empty & (nearest_position <= POLISH_RESIDUAL)
    for mask, flag in candidates.singularities.entries:
        if flag.relation in FRAGILE_RELATIONS:
            complete &= ~(mask & narrow)
        if constrain_orientation and flag.relation == "free":
            complete &= ~(mask & empty & candidates.valid.any(axis=1))
    return complete
