"""Redundant arms (n > 6): the self-motion family as locked 6-DOF problems, one per value of the free joints.

Locking joint j at the value v turns the product of exponentials
``exp([S_1] q_1) ⋯ exp([S_j] v) ⋯ exp([S_n] q_n) · home`` into a chain of the other joints: every screw after j,
and the home pose, is moved by the fixed motion ``exp([S_j] v)`` (EAIK's "remodelling": locking is its own step,
before any solver sees the arm). The locked screw model goes to the ordinary plan dispatch
(:func:`~._plan.plan_for_geometry`), so whatever family covers the locked arm solves it completely, and new
families apply here as soon as they are added there.

When every free joint sits at an end of the chain (a prefix or a suffix), the locked arm is the same for every
value; only the target moves: ``target' = E_prefix(v)⁻¹ · target · home⁻¹ · E_suffix(v)⁻¹ · home``. Then one
plan solves all the values as one batch. Otherwise each value has its own plan, kept per value in a bounded
cache of the family.

Candidates are full n-joint vectors, so the shared verification (:func:`~._verify.verify`: FK of the full arm,
merging, labels) applies unchanged: each row of :meth:`FreeJointFamily.solve_rows` is one (target, free value)
pair, and :func:`solve_family` gathers the rows of a target into one answer whose solutions carry their free
values in their own joint vectors. With a reference, the free joint is also searched continuously
(:mod:`._free_search`).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from .._budget import UNLIMITED, Budget
from .._cache import DerivedStore, bounded_memo, memo
from .._errors import InvalidInputError
from .._robot import Robot
from .._tolerances import DUPLICATE_TOLERANCE
from ._general_6r import GENERAL_STRUCTURES
from ._goals import PoseGoal
from ._plan import Plan, geometry_of, plan_for_geometry
from ._screws import joint_motion
from ._structure import Geometry
from ._table import SolutionTable, merged_labels
from ._types import Candidates, SingularFlags, Singularity
from ._verify import Verified, distance_to_reference, verify, wrap_revolute

#: Samples per free joint when the request names none (api.md's example count).
DEFAULT_SAMPLES = 32
#: Most free values (rows of the grid, over all free joints) one target may ask for.
MAX_FREE_VALUES = 2048
#: Most free values when a free joint is inside the chain (each value builds its own plan).
MAX_PLANNED_VALUES = 256
#: Values at which a candidate locking is tried when the free joints are chosen (generic, so that no accidental
#: alignment of axes at 0 decides the class).
_PROBE_VALUES = (0.713717, -1.921317)
#: Choices of free joints tried when the request names none (an arm of many joints has many): each builds the
#: locked arm's plan, up to ~0.1 s for a general 6R one, so this bounds the first request's work to about 2 s.
#: The likeliest choices come first (end joints, then the SRS arms' q3).
_CHOICES_TRIED = 16
#: Families kept per robot (a request may name any choice of free joints).
_FAMILIES_KEPT = 16


@dataclass(frozen=True)
class FreeJoint:
    """One free joint of a request: its index and the values (radians or length units) to solve at."""

    joint: int
    values: np.ndarray


class NotRedundantError(InvalidInputError):
    """Free joints were asked of an arm with 6 joints or fewer (``dof``): it has none to free."""

    def __init__(self, message: str, *, dof: int = 0) -> None:
        super().__init__(message)
        self.dof = dof


def locked_geometry(geometry: Geometry, locked: dict[int, float]) -> Geometry:
    """The screw model of the arm with each joint of ``locked`` held at its value (radians / length units).

    The remaining joints keep their order; each screw after a locked joint, the home pose and the link x axes
    are moved by that joint's motion.
    """
    model = geometry.model
    directions, points = model.directions.copy(), model.points.copy()
    home = model.home.copy()
    link_x = None if geometry.link_x is None else geometry.link_x.copy()
    for joint in sorted(locked, reverse=True):  # later joints first: earlier indices stay valid
        motion = joint_motion(directions[joint], points[joint], bool(model.is_revolute[joint]),
                              np.asarray(locked[joint], dtype=float))
        R, t = motion[:3, :3], motion[:3, 3]
        after = slice(joint + 1, None)
        directions[after] = directions[after] @ R.T
        points[after] = points[after] @ R.T + t
        if link_x is not None:
            link_x[after] = link_x[after] @ R.T
        home = motion @ home
    kept = [i for i in range(geometry.dof) if i not in locked]
    locked_model = type(model)(directions[kept], points[kept], model.is_revolute[kept].copy(), home)
    return Geometry(locked_model, geometry.length_scale, up=geometry.up,
                    link_x=None if link_x is None else link_x[kept])


class FreeJointFamily:
    """The plans of a redundant arm with the joints ``free`` locked; ``structure`` names the locked class.

    A value object once built: its only mutable part is :attr:`_plans`, an explicit bounded memo of the locked
    plans per value (for free joints inside the chain), which concurrent requests share.
    """

    def __init__(self, robot: Robot, free: tuple[int, ...]) -> None:
        self.robot = robot
        self.free = free
        self.kept = np.array([i for i in range(robot.dof) if i not in free])
        self.geometry = geometry_of(robot)
        n = robot.dof
        # free joints at the ends of the chain: the locked arm does not depend on their values
        self.prefix = tuple(j for j in free if all(i in free for i in range(j + 1)))
        self.suffix = tuple(j for j in free if all(i in free for i in range(j, n)))
        self.ends_only = len(self.prefix) + len(self.suffix) == len(free)
        self._plans = DerivedStore()
        if self.ends_only:  # locked at 0 once; the targets are moved instead
            probes = [self._plan_locked_at({j: 0.0 for j in free})]
        else:
            probes = [self._plan_locked_at(dict.fromkeys(free, value)) for value in _PROBE_VALUES]
        self.plan = probes[0]
        available = all(p is not None for p in probes) and len({p.structure for p in probes}) == 1
        names = ", ".join(f"q{j + 1}" for j in free)
        self.structure = f"{self.plan.structure} with {names} free" if available else ""
        self.generic_count = self.plan.generic_count if available else 0
        # a class can be recognised yet degenerate (a locked elbow): it must solve a real pose
        self.available = available and self._recovers_probe_pose()

    @property
    def free_joints(self) -> tuple[int, ...]:
        """The joints an answer lists free, in the arm's numbering: the locked ones (at the free values) and
        those the locked plan leaves free and holds at the reference value or 0 (the second joint of a coaxial
        pair, a joint the target never determines)."""
        left_free = () if self.plan is None else self.plan.free_joints
        return tuple(sorted({*self.free, *(int(self.kept[k]) for k in left_free)}))

    def _plan_locked_at(self, locked: dict[int, float]) -> Plan | None:
        return plan_for_geometry(locked_geometry(self.geometry, locked), constrain_orientation=True,
                                 reference=None)

    def locked_plan(self, values: np.ndarray) -> Plan | None:
        """The locked arm's plan with the free joints at ``values`` (f,); the one plan when they are end joints."""
        if self.ends_only:
            return self.plan
        values = np.asarray(values, dtype=float)
        return self._plans.bounded("locked", values.tobytes(), lambda: self._plan_locked_at(
            dict(zip(self.free, values.tolist()))), MAX_PLANNED_VALUES)

    def _recovers_probe_pose(self) -> bool:
        """Whether the locked problem recovers the joint vector a pose was generated from (a fixed generic one).

        The second joint of a coaxial pair in the locked arm takes that vector's value from the reference, as it
        takes a request's: the target fixes only the pair's relation (:mod:`._coaxial`). Other joints the locked
        plan would hold (a locked elbow leaves the shoulder free) get no reference: such a class is degenerate.
        """
        from .._forward import forward_kinematics

        robot = self.robot
        q = np.random.default_rng(7).uniform(-1.0, 1.0, robot.dof)
        q[list(self.free)] = _PROBE_VALUES[0]
        targets = forward_kinematics(robot, q)[None]
        held = self.kept[getattr(self.plan, "coaxial_held", [])]
        reference = None
        if len(held):
            reference = np.zeros(robot.dof)
            reference[held] = q[held]
        found = verify(robot, PoseGoal(targets), self.solve_rows(targets, q[list(self.free)][None], reference)).table
        gap = np.abs(wrap_revolute(robot, found.joints - q)).max(axis=1)
        return bool((gap < DUPLICATE_TOLERANCE).any())

    def solve_rows(self, world_T_targets: np.ndarray, values: np.ndarray, reference: np.ndarray | None, *,
                   budget: Budget = UNLIMITED) -> Candidates:
        """Candidates (S, m, n) for targets (S, 4, 4), row s with the free joints at ``values[s]`` (S, f): full
        joint vectors, the free joints holding their row's values, labelled by the locked family. A row whose
        locked arm has no plan has no candidate and is not complete. ``budget`` is checked before each row whose
        locked arm is solved on its own (building its plan, the first time, takes tens of milliseconds)."""
        n_rows, n = len(world_T_targets), self.robot.dof
        locked_reference = None if reference is None else reference[self.kept]
        if self.ends_only:
            parts = [(np.arange(n_rows), self.plan, self.plan.solve(self._moved_targets(world_T_targets, values),
                                                                    locked_reference))]
        else:
            parts = []
            for row in range(n_rows):
                budget.check("the free-joint family")
                plan = self.locked_plan(values[row])
                if plan is not None:
                    parts.append((np.array([row]), plan, plan.solve(world_T_targets[row:row + 1], locked_reference)))
        m = max([self.generic_count, 1, *(part.joints.shape[1] for _, _, part in parts)])
        joints = np.zeros((n_rows, m, n))
        joints[..., list(self.free)] = values[:, None, :]
        valid = np.zeros((n_rows, m), dtype=bool)
        complete = np.zeros(n_rows, dtype=bool)
        singular = SingularFlags(n_rows)
        pieces, lengths = [], []
        for rows, plan, part in parts:
            width = part.joints.shape[1]
            block = joints[rows, :width]
            block[..., self.kept] = part.joints
            joints[rows, :width] = block
            valid[rows, :width] = part.valid
            complete[rows] = True if part.complete is None else part.complete
            labels = part.labels if part.labels is not None else {
                name: (values_, codes.reshape(len(rows), width))
                for name, (values_, codes) in plan.label_codes(np.nan_to_num(part.joints).reshape(-1, len(self.kept)))
                .items()}
            pieces.append({name: (values_, np.pad(codes, ((0, 0), (0, m - width)), constant_values=-1).ravel())
                           for name, (values_, codes) in labels.items()})
            lengths.append(len(rows) * m)
            for mask, flag in part.singularities.entries:
                full = np.zeros(n_rows, dtype=bool)
                full[rows] = mask
                singular.add(full, Singularity(flag.kind, tuple(int(self.kept[i]) for i in flag.joints),
                                               flag.relation, flag.detail))
        order = np.concatenate([rows for rows, _, _ in parts]) if parts else np.zeros(0, dtype=int)
        merged = merged_labels(pieces, lengths)
        labels = {}
        for name, (values_, codes) in merged.items():  # the pieces' rows back in row order
            table = np.full((n_rows, m), -1, dtype=np.int8)
            table[order] = codes.reshape(-1, m)
            labels[name] = (values_, table)
        return Candidates(joints, valid, singular, complete=complete, labels=labels,
                          promise_needs_every_slot=any(part.promise_needs_every_slot for _, _, part in parts))

    def _moved_targets(self, targets: np.ndarray, values: np.ndarray) -> np.ndarray:
        """Targets of the locked arm (free end joints at 0): E_prefix⁻¹ · target · home⁻¹ · E_suffix⁻¹ · home."""
        model = self.geometry.model
        moved = targets.copy()
        by_joint = dict(zip(self.free, values.T))
        for j in self.prefix:
            moved = joint_motion(model.directions[j], model.points[j], bool(model.is_revolute[j]), -by_joint[j]) @ moved
        if self.suffix:
            home, home_inverse = model.home, np.linalg.inv(model.home)
            suffix = np.broadcast_to(np.eye(4), (len(targets), 4, 4))
            for j in self.suffix:
                suffix = suffix @ joint_motion(model.directions[j], model.points[j], bool(model.is_revolute[j]),
                                               by_joint[j])
            moved = moved @ home_inverse @ np.linalg.inv(suffix) @ home
        return moved


def family_for(robot: Robot, free: tuple[int, ...]) -> FreeJointFamily:
    """:class:`FreeJointFamily` of ``robot`` with ``free`` locked, built once per robot and choice (the last
    :data:`_FAMILIES_KEPT` choices are kept)."""
    return bounded_memo(robot, "free_joint_family", free, lambda: FreeJointFamily(robot, free), _FAMILIES_KEPT)


def default_free_joints(robot: Robot) -> tuple[int, ...] | None:
    """The free joint(s) whose locking leaves a closed-form 6-DOF class, or None when no choice does.

    One joint is locked per degree of redundancy. A decomposable class wins over the general solver; among
    equals, the first candidate whose locked arm a family solves wins, in this order: the last joint (a Panda's
    or an iiwa's q7: their shoulder is then a spherical wrist at the base), the first (a Gen3's q1), the third
    (the SRS arms' other classic choice, their q3), then the others. End joints come first because the locked
    arm is then the same for every value: the samples solve as one vectorised batch, about four times faster
    than one plan per value. A slide without limits is never chosen: it has no range to sample (a request may
    still free it with its own values). At most :data:`_CHOICES_TRIED` choices are tried, and none when the free
    joints are too many to sample even twice each within :data:`MAX_FREE_VALUES`.
    """
    def choose() -> tuple[int, ...] | None:
        n = robot.dof
        extra = n - 6
        if extra < 1 or _default_samples(extra, MAX_FREE_VALUES) == 0:
            return None  # nothing to free, or too many free joints to sample each: the numeric search answers
        samplable = [j for j in range(n) if robot.is_revolute[j] or np.isfinite([robot.lower[j], robot.upper[j]]).all()]
        order = [j for j in dict.fromkeys([n - 1, 0, 2, *range(n)]) if j in samplable]
        candidates = itertools.islice(itertools.combinations(order, extra), _CHOICES_TRIED)
        general = None  # a decomposable class wins over the general solver (an eigenproblem per value)
        for free in candidates:
            family = family_for(robot, tuple(sorted(free)))
            if family.available:
                if family.plan.structure not in GENERAL_STRUCTURES:
                    return family.free
                general = general or family.free
        return general

    return memo(robot, "default_free_joints", choose)


def sample_values(robot: Robot, joint: int, samples: int) -> np.ndarray:
    """``samples`` values of a joint, evenly over its limits (ends included), or over [−π, π) for a revolute
    joint without limits (or with a range wider than a turn); a prismatic joint needs limits."""
    lower, upper = float(robot.lower[joint]), float(robot.upper[joint])
    if robot.is_revolute[joint]:
        if not (np.isfinite(lower) and np.isfinite(upper)) or upper - lower >= 2 * np.pi:
            return -np.pi + 2 * np.pi * np.arange(samples) / samples
    elif not (np.isfinite(lower) and np.isfinite(upper)):
        raise InvalidInputError(f"joint {joint} is prismatic without limits: give its free values as 'values'")
    return np.linspace(lower, upper, samples) if samples > 1 else np.array([(lower + upper) / 2])


Requested = list[tuple[int, list[float] | None, int | None]]


def free_joints_for(robot: Robot, requested: Requested | None, *, most: int = MAX_FREE_VALUES
                    ) -> list[FreeJoint] | None:
    """The free joints and values to solve at, from a request's ``(joint, values, samples)`` entries (radians /
    length units) or, when there are none, the default choice sampled :data:`DEFAULT_SAMPLES` times (fewer when
    the grid would hold more than ``most`` values: a direction target solves the grid at each of its rolls).

    Returns None when the request names none and no locking leaves a family. Raises :class:`InvalidInputError`
    for a request that does not name exactly n − 6 distinct joints of the arm (:class:`NotRedundantError` for an
    arm of 6 joints or fewer), or whose grid of values exceeds :data:`MAX_FREE_VALUES`, located in
    ``requested``: ``()`` for the whole list, ``(index, "joint")`` or ``(index, "values")`` for one entry.
    """
    extra = robot.dof - 6
    if not requested:
        chosen = default_free_joints(robot)
        if chosen is None:
            return None
        family = family_for(robot, chosen)
        samples = _default_samples(len(chosen), min(most, MAX_FREE_VALUES if family.ends_only else MAX_PLANNED_VALUES))
        if samples == 0:
            return None  # too many free joints to sample each: the numeric search answers
        return [FreeJoint(j, sample_values(robot, j, samples)) for j in chosen]
    if extra < 1:
        raise NotRedundantError(f"free joints apply to arms with more than 6 joints; this one has {robot.dof}",
                                dof=robot.dof)
    if len(requested) != extra:
        raise InvalidInputError(f"an arm with {robot.dof} joints has {extra} free joint(s) for a full pose; "
                                f"{len(requested)} given")
    joints = [joint for joint, _, _ in requested]
    for index, joint in enumerate(joints):
        if not 0 <= joint < robot.dof:
            raise InvalidInputError(f"joint index must be 0…{robot.dof - 1}, not {joint}",
                                    location=(index, "joint"))
        if joints.index(joint) != index:
            raise InvalidInputError(f"joint {joint} is named twice", location=(index, "joint"))
    sizes = [len(values) if values is not None else int(samples) for _, values, samples in requested]
    grid = grid_size(sizes)
    if grid > MAX_FREE_VALUES:
        raise InvalidInputError(f"{_worded_size(grid)} combinations of free values requested "
                                f"({' × '.join(map(str, sizes))}); at most {MAX_FREE_VALUES} per target")
    free = []
    for index, (joint, values, samples) in enumerate(requested):
        if values is not None:
            array = np.asarray(values, dtype=float)
            if not np.isfinite(array).all():
                raise InvalidInputError("free values must be finite", location=(index, "values"))
        else:
            array = sample_values(robot, joint, int(samples))
        free.append(FreeJoint(joint, array))
    return free


def _default_samples(free_count: int, most: int) -> int:
    """Samples per free joint of the default grid: :data:`DEFAULT_SAMPLES`, fewer when the grid would hold more
    than ``most`` values (at least 2 per joint), 0 when even that would."""
    samples = DEFAULT_SAMPLES
    while samples >= 2 and samples ** free_count > most:
        samples //= 2
    return samples if samples >= 2 else 0


def grid_size(sizes: list[int]) -> int:
    """The number of combinations of free values, ∏ sizes, counted without building them (stops past
    :data:`MAX_FREE_VALUES`: any larger number is refused alike)."""
    total = 1
    for size in sizes:
        total *= max(int(size), 0)
        if total > MAX_FREE_VALUES:
            return total if total < 10 ** 18 else 10 ** 18
    return total


def _worded_size(size: int) -> str:
    return f"{size:,}" if size < 10 ** 18 else "more than 10^18"


def free_value_grid(free: list[FreeJoint], family: FreeJointFamily) -> np.ndarray:
    """Every combination of the free joints' values, shape (S, f), in the family's joint order (the grid's size
    was checked by :func:`free_joints_for`). A free joint inside the chain needs a plan per value:
    :data:`MAX_PLANNED_VALUES` at most."""
    by_joint = {f.joint: np.asarray(f.values, dtype=float) for f in free}
    columns = [by_joint[j] for j in family.free]
    size = grid_size([len(c) for c in columns])
    if not family.ends_only and size > MAX_PLANNED_VALUES:
        raise InvalidInputError(
            f"{size} free values requested; a free joint inside the chain needs one plan per value, so at most "
            f"{MAX_PLANNED_VALUES} (an end joint takes up to {MAX_FREE_VALUES})")
    grids = np.meshgrid(*columns, indexing="ij")
    return np.stack([g.ravel() for g in grids], axis=-1)


@dataclass(frozen=True)
class FamilyVerified:
    """The family's answer for N targets: ``verified`` (N targets, each target's solutions over every free value),
    the grid ``values`` (S, f), and per target (N,) how many free values had no locked plan (``missing``) and how
    many the continuous search and the reference's own value added (``refined``)."""

    verified: Verified
    values: np.ndarray
    missing: np.ndarray
    refined: np.ndarray


def solve_family(robot: Robot, family: FreeJointFamily, goal: PoseGoal, free: list[FreeJoint],
                 reference: np.ndarray | None, *, minima: int | None = None, rounds: int | None = None,
                 budget: Budget = UNLIMITED) -> FamilyVerified:
    """Every solution of each of the goal's N targets at each combination of the free joints' values (the grid),
    and, with a reference and one free joint, at the values where a branch comes nearest it between samples
    (:func:`~._free_search.refine_nearest`, ``minima`` minima refined by ``rounds`` rounds). ``budget`` is checked
    before each target and within its solves."""
    from ._free_search import REFINE_ROUNDS, REFINED_MINIMA, refine_nearest, solve_at_reference

    values = free_value_grid(free, family)
    targets, refined = [], []
    for index, target in enumerate(goal.world_T_targets):
        budget.check("the free-joint family")
        grid = solve_at(robot, family, target, values, reference, budget=budget)
        parts = [grid]
        if reference is not None and len(family.free) == 1:
            extra = refine_nearest(robot, family, target, values[:, 0], grid, reference,
                                   REFINED_MINIMA if minima is None else minima,
                                   REFINE_ROUNDS if rounds is None else rounds)
            if extra is not None:
                parts.append(extra)
            at_reference = solve_at_reference(robot, family, target, parts, reference)
            if at_reference is not None:
                parts.append(at_reference)
        refined.append(sum(len(part.complete) for part in parts[1:]))
        targets.append(one_target(robot, parts, index, reference))
    missing = 0 if family.ends_only else sum(family.locked_plan(row) is None for row in values)
    return FamilyVerified(gathered(robot, targets, missing == 0), values, np.full(len(goal), missing),
                          np.array(refined, dtype=int))


def one_target(robot: Robot, parts: list[Verified], index: int, reference: np.ndarray | None) -> Verified:
    """Target ``index``'s answer over a family: the solutions of its parts (each a Verified of rows at free
    values) laid end to end, nearest the reference first over the whole family (ties: in part order), complete
    when every row of every part is, the nearest miss of any, and the conditions met where a row solved."""
    table = SolutionTable.concat([part.table.with_targets(np.zeros(len(part.table), dtype=np.int64))
                                  for part in parts], robot.dof)
    if reference is not None:
        table = table.take(np.argsort(distance_to_reference(robot, table.joints, reference), kind="stable"))
    met = SingularFlags(1)
    for part in parts:
        solved = part.count > 0
        for mask, flag in part.singularities.entries:
            if (mask & solved).any():
                met.add(np.ones(1, dtype=bool), flag)
    return Verified(table.with_targets(np.full(len(table), index)),
                    np.array([all(part.complete.all() for part in parts)]),
                    np.array([min(float(part.nearest.min(initial=np.inf)) for part in parts)]), met)


def gathered(robot: Robot, targets: list[Verified], promised: bool = True) -> Verified:
    """The answers of :func:`one_target`, one per target in order, as one; complete only where ``promised``."""
    if not targets:
        return Verified(SolutionTable.empty(robot.dof), np.zeros(0, dtype=bool), np.zeros(0), SingularFlags(0))
    return Verified(SolutionTable.concat([t.table for t in targets], robot.dof),
                    np.concatenate([t.complete for t in targets]) & promised,
                    np.concatenate([t.nearest for t in targets]), SingularFlags.concat([t.singularities for t in targets]))


def solve_free_joint_family(robot: Robot, world_T_targets: np.ndarray, free: list[FreeJoint],
                            reference: np.ndarray | None, *, minima: int | None = None, rounds: int | None = None,
                            budget: Budget = UNLIMITED) -> FamilyVerified | None:
    """:func:`solve_family` for the family that locks ``free``: every solution of each target (N, 4, 4) at each
    combination of the free joints' values; None when locking them leaves no closed-form family."""
    family = family_for(robot, tuple(sorted(f.joint for f in free)))
    if not family.available:
        return None
    return solve_family(robot, family, PoseGoal(np.asarray(world_T_targets, dtype=float)), free, reference,
                        minima=minima, rounds=rounds, budget=budget)


def solve_at(robot: Robot, family: FreeJointFamily, target: np.ndarray, values: np.ndarray,
             reference: np.ndarray | None, *, budget: Budget = UNLIMITED) -> Verified:
    """Every solution of one target (4, 4) at each row of free values (S, f), one verified row each; ``budget``
    as :meth:`FreeJointFamily.solve_rows` checks it."""
    targets = np.broadcast_to(target, (len(values), 4, 4))
    held = np.zeros(robot.dof, dtype=bool)
    held[list(family.free)] = True
    return verify(robot, PoseGoal(np.ascontiguousarray(targets)),
                  family.solve_rows(targets, values, reference, budget=budget), reference, held=held)


def free_joint_solutions(robot: Robot, requested: Requested | None, refined: bool) -> int | None:
    """The most solutions one full-pose target of a redundant arm can have over its free joints (``requested``
    as for :func:`free_joints_for`): the locked arm's generic count at each free value, and at the values the
    continuous search adds when ``refined`` (a reference is given). None when no family covers the arm: the
    numeric search answers."""
    from ._free_search import EXTRA_VALUES_WITH_REFERENCE

    free = free_joints_for(robot, requested)
    if free is None:
        return None
    family = family_for(robot, tuple(sorted(f.joint for f in free)))
    if not family.available:
        return None
    values = grid_size([len(f.values) for f in free])
    return (values + (EXTRA_VALUES_WITH_REFERENCE if refined and len(free) == 1 else 0)) * family.generic_count


def beyond_reach(robot: Robot, positions: np.ndarray) -> np.ndarray:
    """Which world positions (..., 3) no joint vector can reach, by the reach sphere: each link moves the next
    frame by at most |a| + |d| (plus a prismatic joint's travel), so the tool stays within the sum of those and
    the tool offset from the base origin (the robot's characteristic length, which a robot described by joint
    screws or a URDF measures on its links). A proof of unreachability, not a test of reachability."""
    reach = robot.characteristic_length
    travel = np.where(robot.is_revolute, 0.0, np.maximum(np.abs(robot.lower), np.abs(robot.upper)))
    reach += float(np.sum(travel))
    distance = np.linalg.norm(np.asarray(positions) - robot.world_T_base[:3, 3], axis=-1)
    return distance > reach * (1.0 + 1e-9) + 1e-12


def no_solution_detail(free: list[FreeJoint], beyond: bool) -> str:
    """What an empty answer of the family means: none at the values solved, which proves nothing for others,
    unless the position lies ``beyond`` the arm's reach (:func:`beyond_reach`)."""
    if beyond:
        return "The target position is outside the workspace (farther from the base than the arm can reach)."
    names = ", ".join(f"q{f.joint + 1}" for f in free)
    count = math.prod(len(f.values) for f in free)
    return (f"No joint vector reaches the target at any of the {count} values of the free joint(s) {names} "
            f"solved (each solved completely); other values of {names} may reach it.")
