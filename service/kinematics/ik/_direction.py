"""Position + tool direction targets: 5-joint arms as a 6-joint pose problem with a virtual joint; arms of 6 or
more joints as a family over the free roll.

The target asks that the tool origin reach ``p`` and the tool axis ``a`` (tool
frame) point along ``d`` (world frame), as IKFast's TranslationDirection5D:
five conditions for five joints. Any rotation ``R_t`` with ``R_t a = d`` makes
a pose target; the tool's roll about ``a`` is what the target leaves open.

* The general case: append a virtual revolute joint turning about ``a`` at the
  tool origin. That joint moves neither the origin nor ``a``, so the 6-joint
  arm reaches ``(p, R_t)`` exactly when the real arm reaches ``(p, d)``, and its
  solutions, without the virtual value, are every solution of the direction
  target. The 6-joint pose problem goes to the ordinary plan dispatch
  (:func:`~._plan.plan_for_geometry`), which solves it completely.
* When ``a`` lies along the last joint's axis (the roll of a desktop arm's
  gripper: the usual case), that joint already turns the tool about ``a``: it
  is free, held at the reference (or 0), and the arm's own pose problem at
  ``R_t`` is solved instead, by the same device with the virtual joint about
  an axis perpendicular to ``a``. A pose of the 5-joint arm is reached by the
  6-joint arm with the virtual joint at 0, and those are the solutions kept.

Arms of 6 or more joints (:class:`RollFamily`): the target leaves one more freedom than the pose problem, the
tool's roll ψ about ``a``. Each roll gives a full pose, ``R(ψ) = R_t · Rot(a, ψ)`` with ``R_t`` the shortest turn
of ``a`` onto ``d`` (:func:`rotations_to`), which the arm's closed form solves completely: the pose plan of a
6-joint arm, or a redundant arm's free-joint family (:mod:`._redundant`) at each of its free values. The family is
sampled at :data:`DEFAULT_ROLL_SAMPLES` rolls evenly over the turn (or the rolls a request gives), at most
:data:`MAX_ROLL_ROWS` pose solves (rolls × free values) per target. With a reference the family is also searched
continuously, so that the nearest member of the whole family is listed: from the grid solutions of the branches
nearest the reference, a descent along the family (the goal's null space, :func:`_projected_members`) reaches each
branch's nearest point, and over a 6-joint arm's roll the free-joint search's bracketing
(:func:`~._free_search.refine_over`) runs too; the rolls (and free values) found are solved completely. Each
solution carries its roll (:func:`rolls_of`, read from its FK), as a free joint carries its value. A target with
no solution at the rolls solved is not proven unreachable (other rolls may reach it).

Every solution is checked by the real arm's FK (:func:`~._verify.verify` with a
:class:`~._goals.DirectionGoal`): position within ``ACCEPT_RESIDUAL`` times its
size, direction within ``ACCEPT_RESIDUAL`` rad.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .._budget import UNLIMITED, Budget
from .._cache import bounded_memo
from .._errors import InvalidInputError
from .._forward import cross, forward_kinematics, radius_about
from .._robot import Robot
from .._angles import wrap_angle
from .._tolerances import DUPLICATE_TOLERANCE, GEOMETRY_TOLERANCE
from ._closed_form import cached_plan, joined
from ._goals import DirectionGoal
from ._plan import Plan, geometry_of, plan_for_geometry
from ._redundant import (MAX_FREE_VALUES, FreeJoint, FreeJointFamily, default_free_joints, family_for,
                         free_joints_for, free_value_grid, gathered, grid_size, one_target)
from ._screws import perpendicular_unit
from ._structure import Geometry, arm_size
from ._types import Candidates, SingularFlags, Singularity
from ._verify import Verified, distance_to_reference, joint_difference, verify

#: The virtual joint's value (rad) within which a 6-joint solution is one of the 5-joint arm (the roll case).
VIRTUAL_AT_ZERO = 1e-6
#: Direction plans kept per robot (one per tool axis a request names).
_PLANS_KEPT = 16
#: Samples of the free roll per direction target of an arm of 6 or more joints when the request names none: 10°
#: apart.
DEFAULT_ROLL_SAMPLES = 36
#: Most rolls × free values of a redundant arm per direction target: each is one complete pose solve (the
#: free-joint family's own cap, :data:`~._redundant.MAX_FREE_VALUES`).
MAX_ROLL_ROWS = MAX_FREE_VALUES


def target_kinds(robot: Robot) -> list[str]:
    """The IK target kinds this arm takes (api.md): ``pose`` and ``position`` always, ``position_direction``
    for arms with 5 joints or more (6 or more: a family over the free roll)."""
    return ["pose", "position"] + (["position_direction"] if robot.dof >= 5 else [])


@dataclass(frozen=True)
class DirectionPlan:
    """How one arm solves direction targets for one tool axis ``tool_axis`` (3,), tool frame."""

    plan: Plan
    tool_axis: np.ndarray
    roll_joint: int | None  # the real joint that turns about the tool axis (free), or None
    structure: str


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _with_virtual_roll(geometry: Geometry, axis_world: np.ndarray) -> Geometry:
    """The arm plus a revolute joint about ``axis_world`` (3,) through the tool origin at q = 0."""
    model = geometry.model
    origin = model.home[:3, 3]
    virtual = type(model)(np.vstack([model.directions, axis_world]), np.vstack([model.points, origin]),
                          np.append(model.is_revolute, True), model.home)
    link_x = None if geometry.link_x is None else np.vstack([geometry.link_x, model.home[:3, 0]])
    return Geometry(virtual, geometry.length_scale, up=geometry.up, link_x=link_x)


def direction_plan(robot: Robot, tool_axis: np.ndarray) -> DirectionPlan | None:
    """The plan for direction targets with this tool axis, or None when no family covers the 6-joint problem.

    Raises :class:`InvalidInputError` for an arm with fewer than 5 joints; arms of 6 or more take
    :class:`RollFamily` instead.
    """
    if robot.dof < 5:
        raise InvalidInputError(
            f"position + tool direction targets need at least 5 joints (five conditions); this one has "
            f"{robot.dof} (give a full pose, or the position only)", location=("target", "orientation"))
    if robot.dof > 5:
        raise ValueError("arms of 6 or more joints solve direction targets by RollFamily")
    a = _unit(np.asarray(tool_axis, dtype=float))

    def build() -> DirectionPlan | None:
        geometry = geometry_of(robot)
        model = geometry.model
        R_home, origin = model.home[:3, :3], model.home[:3, 3]
        axis_world = R_home @ a
        last = robot.dof - 1
        along_last = (bool(model.is_revolute[last])
                      and radius_about(model.directions[last], axis_world) <= GEOMETRY_TOLERANCE * 10
                      and geometry.on_axis(last, origin))
        if not along_last:
            plan = plan_for_geometry(_with_virtual_roll(geometry, axis_world), constrain_orientation=True,
                                     reference=None)
            return None if plan is None else DirectionPlan(plan, a, None, f"virtual_roll+{plan.structure}")
        first = perpendicular_unit(a)
        for axis in (first, cross(a, first)):
            plan = plan_for_geometry(_with_virtual_roll(geometry, R_home @ axis), constrain_orientation=True,
                                     reference=None)
            if plan is not None:
                return DirectionPlan(plan, a, last, f"virtual_joint+{plan.structure}")
        return None

    return bounded_memo(robot, "direction_plan", tuple(np.round(a, 12).tolist()), build, _PLANS_KEPT)


def rotations_to(tool_axis: np.ndarray, world_directions: np.ndarray) -> np.ndarray:
    """Rotations (N, 3, 3) taking the unit vector ``tool_axis`` (3,) onto each of ``world_directions`` (N, 3):
    the shortest turn, or a half turn about an axis perpendicular to it when the two are opposite."""
    a = _unit(np.asarray(tool_axis, dtype=float))
    d = world_directions / np.linalg.norm(world_directions, axis=-1, keepdims=True)
    axis = cross(a, d)
    sine, cosine = np.linalg.norm(axis, axis=-1), d @ a
    opposite = sine < 1e-12
    axis = np.where(opposite[:, None], perpendicular_unit(a), axis / np.where(opposite, 1.0, sine)[:, None])
    angle = np.arctan2(sine, cosine)
    angle = np.where(opposite & (cosine < 0), np.pi, angle)
    return about_axes(axis, angle)


def distinct_rolls(rolls: np.ndarray) -> np.ndarray:
    """The rolls (S,) a request gives, each once: wrapped to (−π, π], in the order given, dropping any within
    ``DUPLICATE_TOLERANCE`` of an earlier one (0 and 2π are one roll, and would list each solution twice)."""
    wrapped = wrap_angle(np.asarray(rolls, dtype=float))
    return wrapped[first_of_each_point(wrapped[:, None])]


def about_axes(axes: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Rotations (N, 3, 3) by ``angles`` (N,) about the unit ``axes`` (N, 3), or one axis (3,) for all
    (Rodrigues: ``I + sin θ K + (1 − cos θ) K²``, K the cross-product matrix of the axis)."""
    axes = np.broadcast_to(axes, (len(angles), 3))
    K = np.zeros((len(angles), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -axes[:, 2], axes[:, 1], -axes[:, 0]
    K = K - np.swapaxes(K, 1, 2)
    s, c = np.sin(angles)[:, None, None], np.cos(angles)[:, None, None]
    return np.eye(3) + s * K + (1 - c) * K @ K


def direction_candidates(robot: Robot, plan: DirectionPlan, goal: DirectionGoal, reference: np.ndarray | None
                         ) -> Candidates:
    """Candidates (N, m, n) of the goal's N position + direction targets by the plan, with their labels and the
    arm's singular conditions (those of the virtual joint left out). When the last joint turns about the tool
    axis it is held at the reference value (or 0) in every candidate; :func:`tool_roll` then names it."""
    n = robot.dof
    targets = np.zeros((len(goal), 4, 4))
    targets[:, 3, 3] = 1.0
    targets[:, :3, 3] = goal.positions
    targets[:, :3, :3] = rotations_to(plan.tool_axis, goal.directions)
    extended = None if reference is None else np.append(reference, 0.0)
    candidates = plan.plan.solve(targets, extended)
    full = np.nan_to_num(candidates.joints)  # (N, m, n + 1)
    valid = candidates.valid.copy()
    if plan.roll_joint is not None:  # the arm's own pose problem: the virtual joint must stay at 0
        valid &= np.abs(wrap_angle(full[..., n])) <= VIRTUAL_AT_ZERO
    joints = full[..., :n].copy()
    if plan.roll_joint is not None:
        joints[..., plan.roll_joint] = 0.0 if reference is None else reference[plan.roll_joint]
    labels = candidates.labels if candidates.labels is not None else {
        name: (values, codes.reshape(valid.shape))
        for name, (values, codes) in plan.plan.label_codes(full.reshape(-1, n + 1)).items()}
    singular = SingularFlags(len(goal))
    for mask, flag in candidates.singularities.entries:  # conditions that involve the virtual joint are not the arm's
        if all(j < n for j in flag.joints):
            singular.add(mask, flag)
    return Candidates(joints, valid, singular, labels=labels, complete=candidates.complete)


def tool_roll(plan: DirectionPlan) -> Singularity | None:
    """The condition every direction answer of an arm whose last joint turns about the tool axis reports."""
    if plan.roll_joint is None:
        return None
    return Singularity("tool_roll", (plan.roll_joint,), "free",
                       f"q{plan.roll_joint + 1} turns the tool about the tool axis, which the target leaves free: "
                       f"held at the reference value (or 0)")


def roll_samples(count: int) -> np.ndarray:
    """``count`` rolls (rad) evenly over a turn, from −π: shape (count,)."""
    return -np.pi + 2 * np.pi * np.arange(count) / count


def roll_poses(tool_axis: np.ndarray, position: np.ndarray, direction: np.ndarray, rolls: np.ndarray) -> np.ndarray:
    """The full poses ``world_T_tool`` (S, 4, 4) of one direction target at each roll (S,):
    rotation ``R_t · Rot(a, ψ)`` (``R_t``: :func:`rotations_to` of the tool axis onto the direction), origin at
    ``position`` (3,). Each turns ``tool_axis`` (3,, unit, tool frame) onto ``direction`` (3,, unit, world)."""
    R_t = rotations_to(tool_axis, direction[None])[0]
    poses = np.zeros((len(rolls), 4, 4))
    poses[:, :3, :3] = R_t @ about_axes(tool_axis, rolls)
    poses[:, :3, 3] = position
    poses[:, 3, 3] = 1.0
    return poses


def rolls_of(tool_axis: np.ndarray, direction: np.ndarray, world_R_tool: np.ndarray) -> np.ndarray:
    """The roll ψ (K,), radians in (−π, π], of each tool rotation ``world_R_tool`` (K, 3, 3) whose tool axis
    (3,, unit, tool frame) points along ``direction`` (3,, unit, world frame): the angle of ``R_t⁻¹ · R`` about
    the tool axis, as :func:`roll_poses` builds it (``u`` ⟂ ``a`` turns to ``cos ψ u + sin ψ (a × u)``).

    >>> a = np.array([0.0, 0.0, 1.0]); d = np.array([1.0, 0.0, 0.0])
    >>> round(float(rolls_of(a, d, roll_poses(a, np.zeros(3), d, np.array([0.5]))[:, :3, :3])[0]), 12)
    0.5
    """
    a = _unit(np.asarray(tool_axis, dtype=float))
    u = perpendicular_unit(a)
    R_t = rotations_to(a, np.asarray(direction, dtype=float)[None])[0]
    turned = (world_R_tool @ u) @ R_t  # rows: (R_t^T R u)^T, (K, 3)
    return np.arctan2(turned @ cross(a, u), turned @ u)


@dataclass(frozen=True)
class RollFamily:
    """How an arm of 6 or more joints solves direction targets: the pose at each roll by ``plan`` (a 6-joint arm's
    pose plan), or by ``family`` (a redundant arm's free-joint family) at each of the ``free`` values (V, f).
    ``generic_count``: the most solutions of one roll (and free value)."""

    plan: Plan | None
    family: FreeJointFamily | None
    free: np.ndarray | None
    structure: str
    generic_count: int

    @property
    def free_joints(self) -> tuple[int, ...]:
        """The joints the answer lists as free: a redundant arm's, or those the 6-joint plan holds (coaxial)."""
        return tuple(self.plan.free_joints) if self.family is None else self.family.free

    @property
    def free_rows(self) -> int:
        """Free values per roll: 1 for a 6-joint arm."""
        return 1 if self.free is None else len(self.free)


def roll_free_joints(robot: Robot, most_rolls: int, location: tuple = ("target", "orientation")
                     ) -> list[FreeJoint] | None:
    """A redundant arm's default free joints under direction targets of up to ``most_rolls`` rolls: the default
    choice sampled so that rolls × free values stay within :data:`MAX_ROLL_ROWS` (32 per free joint on a 7-joint
    arm at the default rolls). Raises :class:`InvalidInputError` when that leaves fewer than two samples per free
    joint; None when no locking leaves a closed-form family."""
    most = MAX_ROLL_ROWS // max(most_rolls, 1)
    free = free_joints_for(robot, None, most=most)
    if free is None and default_free_joints(robot) is not None:
        raise InvalidInputError(f"{most_rolls} rolls leave room for {most} free values per roll (at most "
                                f"{MAX_ROLL_ROWS} pose solves per direction target): too few to sample this arm's "
                                f"{robot.dof - 6} free joint(s) twice each; ask for fewer rolls", location=location)
    return free


def roll_family(robot: Robot, free_joints: list[FreeJoint] | None) -> RollFamily | None:
    """The roll family of an arm of 6 or more joints, or None when no closed form covers its pose problem (a
    redundant arm: with the free joints ``free_joints``, as :func:`~._redundant.free_joints_for` gives them)."""
    if robot.dof == 6:
        plan = cached_plan(robot, constrain_orientation=True, reference=None)
        return None if plan is None else RollFamily(plan, None, None, f"roll_family+{plan.structure}",
                                                    plan.generic_count)
    if free_joints is None:
        return None
    family = family_for(robot, tuple(sorted(f.joint for f in free_joints)))
    if not family.available:
        return None
    return RollFamily(None, family, free_value_grid(free_joints, family), f"roll_family+{family.structure}",
                      family.generic_count)


def roll_rows(robot: Robot, rolls: np.ndarray, free_joints: list[FreeJoint] | None,
              location: tuple = ("target", "orientation")) -> int:
    """Pose solves per direction target: rolls × free values; :class:`InvalidInputError` (at ``location``) past
    :data:`MAX_ROLL_ROWS`."""
    values = 1 if free_joints is None else grid_size([len(f.values) for f in free_joints])
    rows = len(rolls) * values
    if rows > MAX_ROLL_ROWS:
        raise InvalidInputError(f"{len(rolls)} roll samples × {values} free values = {rows} pose solves per "
                                f"direction target; at most {MAX_ROLL_ROWS} (lower roll_samples or the free "
                                f"joints' samples)", location=location)
    return rows


def refined_rows(family: RollFamily, reference_given: bool) -> int:
    """The most pose solves a reference adds per target (each one row: a roll, and a free value): the points of
    :func:`_projected_members` and, over a 6-joint arm's roll, the minima :func:`~._free_search.refine_over`
    refines."""
    from ._free_search import REFINED_MINIMA

    if not reference_given:
        return 0
    return PROJECTION_STARTS + (REFINED_MINIMA if family.family is None else 0)


@dataclass(frozen=True)
class RollVerified:
    """The roll family's answer for N direction targets: ``verified`` (each target's solutions over every roll,
    the table carrying each row's roll), and per target (N,) how many poses the closed form could not promise
    (``unpromised``) and how many rolls the continuous search added (``refined``)."""

    verified: Verified
    unpromised: np.ndarray
    refined: np.ndarray


def solve_roll_family(robot: Robot, family: RollFamily, goal: DirectionGoal, rolls: np.ndarray,
                      reference: np.ndarray | None, *, budget: Budget = UNLIMITED) -> RollVerified:
    """Every solution of each of the goal's N targets at each roll of ``rolls`` (S,) (and each free value), each
    verified by FK against the direction target; with a reference, also at the rolls (and free values) where a
    branch comes nearest it between samples: :func:`_projected_members` and, over the roll of a 6-joint arm,
    :func:`~._free_search.refine_over`. ``budget`` is checked before each target and each chunk of its grid."""
    from ._free_search import REFINE_ROUNDS, REFINED_MINIMA, _evenly_over_a_turn, refine_over

    targets, unpromised, refined = [], [], []
    for index in range(len(goal)):
        budget.check("the roll family")

        def solve(chosen: np.ndarray, index: int = index) -> Verified:
            return _at_rolls(robot, family, goal, index, chosen, reference, budget)

        grid = solve(rolls)
        parts = [grid]
        if reference is not None:
            extras = [_projected_members(robot, family, goal, index, rolls, grid, reference)]
            if family.family is None:
                extras.append(refine_over(robot, rolls, grid, reference, REFINED_MINIMA, REFINE_ROUNDS, solve, None,
                                          _evenly_over_a_turn(rolls), wrap_angle))
            parts += [extra for extra in extras if extra is not None]
        refined.append(sum(len(part.complete) for part in parts[1:]))
        unpromised.append(sum(int((~part.complete).sum()) for part in parts))
        targets.append(one_target(robot, parts, index, reference))
    missing = 0 if family.family is None or family.family.ends_only else sum(
        family.family.locked_plan(row) is None for row in family.free)
    return RollVerified(gathered(robot, targets, missing == 0), np.array(unpromised, dtype=int),
                        np.array(refined, dtype=int))


#: Steps of the projected descent towards the reference along the family, the largest joint move (rad, or
#: length units over the arm's size) of its step along the family, and the branches it starts from.
PROJECTION_STEPS = 60
PROJECTION_STRIDE = 0.2
PROJECTION_STARTS = 4


def _projected_members(robot: Robot, family: RollFamily, goal: DirectionGoal, index: int, rolls: np.ndarray,
                       grid: Verified, reference: np.ndarray) -> Verified | None:
    """The members nearest the reference of the :data:`PROJECTION_STARTS` branches whose grid solutions come
    nearest it: from each, a descent that keeps the direction target and moves along the family towards the
    reference (:func:`_projected_nearest`); the roll (and free value) read off each point reached is then solved
    completely, one verified row per point. None when the grid is empty or every point is on the grid.

    This is what finds the nearest member of a redundant arm's two-parameter family (roll × free joint), and it
    backs up the bracketing search over the roll where a branch moves fast with the roll (near a singularity),
    so that its nearest grid sample is not among the nearest minima."""
    from ._free_search import branch_keys

    table = grid.table
    if not len(table):
        return None
    distance = distance_to_reference(robot, table.joints, reference)
    keys = branch_keys(table.labels, len(table))
    order = np.argsort(distance, kind="stable")
    _, first = np.unique(keys[order], return_index=True)  # each branch's nearest grid solution
    starts = order[np.sort(first)]
    starts = starts[np.argsort(distance[starts], kind="stable")][:PROJECTION_STARTS]
    q, reached = _projected_nearest(robot, goal.take(np.full(len(starts), index)), table.joints[starts], reference)
    if not reached.any():
        return None
    q = q[reached]
    point_rolls = rolls_of(goal.tool_axis, goal.directions[index], forward_kinematics(robot, q)[:, :3, :3])
    free = None if family.family is None else q[:, list(family.free_joints)]
    points = np.column_stack([point_rolls] + ([] if free is None else [free]))
    points = points[first_of_each_point(points)]
    on_grid = np.abs(wrap_angle(points[:, :1] - rolls[None, :])).min(axis=1) <= DUPLICATE_TOLERANCE
    if free is not None:
        on_grid &= (np.abs(points[:, None, 1:] - family.free[None]).max(axis=2) <= DUPLICATE_TOLERANCE).any(axis=1)
    points = points[~on_grid]
    if not len(points):
        return None
    return _solved_at(robot, family, goal, index, points[:, 0], None if free is None else points[:, 1:], reference)


def first_of_each_point(points: np.ndarray) -> np.ndarray:
    """Which rows (K,) of ``points`` (K, 1 + f: roll, free values) are the first of their kind (within
    ``DUPLICATE_TOLERANCE``, the roll across the wrap)."""
    kept = np.zeros(len(points), dtype=bool)
    for k in range(len(points)):
        gap = np.abs(points[:k] - points[k])
        gap[:, 0] = np.abs(wrap_angle(points[:k, 0] - points[k, 0]))
        kept[k] = not ((gap <= DUPLICATE_TOLERANCE).all(axis=1) & kept[:k]).any()
    return kept


def _projected_nearest(robot: Robot, goal: DirectionGoal, q: np.ndarray, reference: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray]:
    """From solutions q (K, n) of the goal's K targets, the nearest points (locally, in the joints' 2-norm,
    revolute differences across the wrap) of the family of solutions to the reference (n,): each step is the
    Gauss–Newton correction ``J⁺ e`` plus the move towards the reference projected on the null space of the
    goal's Jacobian J (6, n), at most :data:`PROJECTION_STRIDE` per joint. Returns the points (K, n) and which
    of them are still on the target (K,)."""
    rows = np.arange(len(q))
    stride = np.where(robot.is_revolute, PROJECTION_STRIDE, PROJECTION_STRIDE * arm_size(robot))
    q = np.array(q, dtype=float)
    for _ in range(PROJECTION_STEPS):
        error = goal.error(robot, q, rows)
        J = goal.jacobian(robot, q, rows)
        inverse = np.linalg.pinv(J, rcond=1e-9)  # (K, n, 6)
        toward = -joint_difference(robot, q, reference)
        along = toward - np.einsum("kij,kj->ki", inverse, np.einsum("kij,kj->ki", J, toward))
        along *= np.minimum(1.0, (stride / np.maximum(np.abs(along), 1e-300)).min(axis=1))[:, None]
        q = q + np.einsum("kij,kj->ki", inverse, error) + along
        if np.abs(along).max() < 1e-13 and np.abs(error).max() < 1e-13:
            break
    return q, np.abs(goal.error(robot, q, rows)).max(axis=1) <= 1e-9


#: Pose solves per chunk of a roll family's grid: the request's budget is checked between chunks, so a large grid
#: of a slow family (general 6R: ~2 ms a pose) stops near the deadline.
ROLL_CHUNK = 256


def _at_rolls(robot: Robot, family: RollFamily, goal: DirectionGoal, index: int, rolls: np.ndarray,
              reference: np.ndarray | None, budget: Budget = UNLIMITED) -> Verified:
    """Every solution of target ``index`` of the goal at each roll (S,) (and, for a redundant arm, each of the
    family's free values: rows roll-major), verified against the direction target: one verified row per (roll,
    free value), each table row carrying its roll. Solved :data:`ROLL_CHUNK` rows at a time, ``budget`` checked
    before each."""
    if family.family is None:
        all_rolls, free = rolls, None
    else:
        all_rolls, free = np.repeat(rolls, family.free_rows), np.tile(family.free, (len(rolls), 1))
    parts = []
    for start in range(0, len(all_rolls), ROLL_CHUNK):
        budget.check("the roll family")
        chunk = slice(start, start + ROLL_CHUNK)
        parts.append(_solved_at(robot, family, goal, index, all_rolls[chunk], None if free is None else free[chunk],
                                reference, budget))
    return parts[0] if len(parts) == 1 else joined(parts, robot.dof)


def _solved_at(robot: Robot, family: RollFamily, goal: DirectionGoal, index: int, rolls: np.ndarray,
               free: np.ndarray | None, reference: np.ndarray | None, budget: Budget = UNLIMITED) -> Verified:
    """Every solution of target ``index`` of the goal at each roll (K,), a redundant arm's free joints at
    ``free`` (K, f) row by row (``budget`` checked before each locked arm solved on its own), verified against
    the direction target (one row each), each table row carrying its roll (read off its FK)."""
    poses = roll_poses(goal.tool_axis, goal.positions[index], goal.directions[index], rolls)
    held, label_codes = None, None
    if family.family is None:
        candidates, label_codes = family.plan.solve(poses, reference), family.plan.label_codes
    else:
        candidates = family.family.solve_rows(poses, free, reference, budget=budget)
        held = np.zeros(robot.dof, dtype=bool)
        held[list(family.free_joints)] = True
    verified = verify(robot, goal.take(np.full(len(rolls), index)), candidates, reference, label_codes, held=held)
    table = verified.table
    R = forward_kinematics(robot, table.joints)[:, :3, :3]
    return replace(verified, table=table.with_roll(rolls_of(goal.tool_axis, goal.directions[index], R)))
