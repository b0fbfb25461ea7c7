"""Redundant arms (n > 6): the self-motion family as locked 6-DOF problems, one per value of the free joints.

Locking joint j at the value v turns the product of exponentials
``exp([S_1] q_1) ⋯ exp([S_j] v) ⋯ exp([S_n] q_n) · home`` into a chain of the
other joints: every screw after j, and the home pose, is moved by the fixed
motion ``exp([S_j] v)`` (EAIK's "remodelling": locking is its own step, before
any solver sees the arm). The locked screw model goes to the ordinary plan
dispatch (:func:`~._plan.plan_for_geometry`), so whatever family covers the
locked arm solves it completely, and new families apply here as soon as they
are added there.

When every free joint sits at an end of the chain (a prefix or a suffix), the
locked arm is the same for every value; only the target moves:
``target' = E_prefix(v)⁻¹ · target · home⁻¹ · E_suffix(v)⁻¹ · home``. Then one
plan solves all the values as one batch. Otherwise each value has its own plan,
kept per value.

Candidates are full n-joint vectors, so the shared verification (FK of the full
arm), merging, labelling and ordering of :mod:`._arrays` apply unchanged. Each
answer row is one (target, free value) pair; :func:`solve_free_joint_family`
merges the rows of a target into one answer whose solutions carry their free
values in their own joint vectors.

With a reference, the free joints are also searched continuously: along each
branch (a combination of the locked family's branch labels) the distance to
the reference is sampled on the grid, and each of the nearest local minima is
refined between its grid neighbours by successively finer sampling (the branch followed by Newton steps
from the nearest sampled solution). The locked
problem is solved completely at each refined value too, so the answer stays
complete for every free value it lists.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._budget import UNLIMITED, Budget
from .._cache import memo
from .._errors import InvalidInputError
from .._robot import Robot
from .._rotations import wrap_angle
from .._tolerances import DUPLICATE_TOLERANCE
from ._arrays import IKArrays, concatenated, joined_label_codes, solve_ik_arrays
from ._plan import Plan, geometry_of, plan_for_geometry
from ._screws import joint_motion
from ._structure import Geometry
from ._types import Candidates, LabelCodes, SingularFlags, Singularity
from ._verify import distance_to_reference, wrap_revolute

#: Samples per free joint when the request names none (api.md's example count).
DEFAULT_SAMPLES = 32
#: Most free values (rows of the grid, over all free joints) one target may ask for.
MAX_FREE_VALUES = 2048
#: Most free values when the free joint is inside the chain (each value builds its own plan).
MAX_PLANNED_VALUES = 256
#: Local minima of the distance to the reference refined per target, nearest first.
REFINED_MINIMA = 4
#: Values tried across each bracket per refinement round; the next bracket spans two of their spacings (8× narrower).
REFINE_POINTS = 17
#: Refinement rounds per minimum: a 2π / 32 bracket (0.4 rad) to ~3e-8 rad.
REFINE_ROUNDS = 8
#: Values at which a candidate locking is tried when the free joints are chosen (generic, so that no accidental
#: alignment of axes at 0 decides the class).
_PROBE_VALUES = (0.713717, -1.921317)
#: Along a path, how far (rad or length units) and at how many values the free joint is searched around the
#: previous sample's value before the whole family is.
TRACK_WINDOW = 0.25
TRACK_SAMPLES = 9
#: Refinement rounds per sample along a path: the window's 0.125 bracket to ~5e-7.
TRACK_REFINE_ROUNDS = 6
#: Newton steps that carry a branch's solution from one free value to a nearby one.
TRACK_STEPS = 6


@dataclass(frozen=True)
class FreeJoint:
    """One free joint of a request: its index and the values (radians or length units) to solve at."""

    joint: int
    values: np.ndarray


def locked_geometry(geometry: Geometry, locked: dict[int, float]) -> Geometry:
    """The screw model of the arm with each joint of ``locked`` held at its value (radians / length units).

    The remaining joints keep their order; each screw after a locked joint, the
    home pose and the link x axes are moved by that joint's motion.
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
    """The plan of a redundant arm with the joints ``free`` locked; ``structure`` names the locked class."""

    def __init__(self, robot: Robot, free: tuple[int, ...]) -> None:
        self.robot = robot
        self.free = free
        self.kept = np.array([i for i in range(robot.dof) if i not in free])
        self.geometry = geometry_of(robot)
        n = robot.dof
        # free joints at the ends of the chain: the locked arm does not depend on their values
        self.prefix = [j for j in free if all(i in free for i in range(j + 1))]
        self.suffix = [j for j in free if all(i in free for i in range(j, n))]
        self.ends_only = len(self.prefix) + len(self.suffix) == len(free)
        if self.ends_only:  # locked at 0 once; the targets are moved instead
            probes = [self._plan_locked_at({j: 0.0 for j in free})]
        else:
            probes = [self._plan_locked_at(dict.fromkeys(free, value)) for value in _PROBE_VALUES]
        self.plan = probes[0]
        self.available = all(p is not None for p in probes) and len({p.structure for p in probes}) == 1
        names = ", ".join(f"q{j + 1}" for j in free)
        self.structure = f"{self.plan.structure} with {names} free" if self.available else ""
        self.generic_count = self.plan.generic_count if self.available else 0
        if self.available:  # a class can be recognised yet degenerate (a locked elbow): it must solve a real pose
            self.available = self._recovers_probe_pose()

    def _recovers_probe_pose(self) -> bool:
        """Whether the locked problem recovers the joint vector a pose was generated from (a fixed generic one)."""
        from .._forward import forward_kinematics

        robot = self.robot
        q = np.random.default_rng(7).uniform(-1.0, 1.0, robot.dof)
        q[list(self.free)] = _PROBE_VALUES[0]
        rows = self.rows_plan(q[list(self.free)][None])
        answer = solve_ik_arrays(robot, forward_kinematics(robot, q)[None], constrain_orientation=True,
                                 reference=None, plan=rows)
        found = answer.joints[0, :answer.count[0]]
        gap = np.abs(wrap_revolute(robot, found - q)).max(axis=1)
        return bool(len(found)) and bool((gap < DUPLICATE_TOLERANCE).any())

    def _plan_locked_at(self, locked: dict[int, float]) -> Plan | None:
        return plan_for_geometry(locked_geometry(self.geometry, locked), constrain_orientation=True,
                                 reference=None)

    def locked_plan(self, values: np.ndarray) -> Plan | None:
        """The locked arm's plan with the free joints at ``values`` (f,); the one plan when they are end joints."""
        if self.ends_only:
            return self.plan
        return self._plan_locked_at(dict(zip(self.free, np.asarray(values, dtype=float).tolist())))

    def rows_plan(self, values: np.ndarray) -> "_RowsPlan":
        """A plan solving row s of a batch of targets with the free joints at ``values[s]`` (S, f)."""
        return _RowsPlan(self, np.asarray(values, dtype=float))


def family_for(robot: Robot, free: tuple[int, ...]) -> FreeJointFamily:
    """:class:`FreeJointFamily` of ``robot`` with ``free`` locked, built once per robot and choice."""
    return memo(robot, ("free_joint_family", free), lambda: FreeJointFamily(robot, free))


class NotRedundantError(InvalidInputError):
    """Free joints were asked of an arm with 6 joints or fewer (``dof``): it has none to free."""

    def __init__(self, message: str, *, dof: int = 0) -> None:
        super().__init__(message)
        self.dof = dof


def default_free_joints(robot: Robot) -> tuple[int, ...] | None:
    """The free joint(s) whose locking leaves a closed-form 6-DOF class, or None when no choice does.

    One joint is locked per degree of redundancy. A decomposable class wins over
    the general 6R solver; among equals, the first candidate whose locked arm a
    family solves wins, in this order: the last joint (a Panda's or
    an iiwa's q7: their shoulder is then a spherical wrist at the base), the
    first (a Gen3's q1), the third (the SRS arms' other classic choice, their
    q3), then the others. End joints come first because
    the locked arm is then the same for every value: the samples solve as one
    vectorised batch, about four times faster than one plan per value.
    """
    def choose() -> tuple[int, ...] | None:
        n = robot.dof
        extra = n - 6
        if extra < 1:
            return None
        order = [n - 1, 0, 2, *range(n)]
        order = list(dict.fromkeys(order))
        candidates = [(j,) for j in order] if extra == 1 else _combinations(order, extra)
        general = None  # a decomposable class wins over the general 6R solver (an eigenproblem per value)
        for free in candidates:
            family = family_for(robot, tuple(sorted(free)))
            if family.available:
                if family.plan.structure != "general_6r":
                    return family.free
                general = general or family.free
        return general

    return memo(robot, "default_free_joints", choose)


def _combinations(order: list[int], k: int) -> list[tuple[int, ...]]:
    from itertools import combinations

    return [tuple(c) for c in combinations(order, k)][:64]  # bounded: an 8- or 9-joint arm has few


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


class _RowsPlan:
    """The plan interface over a batch of rows, row s being the locked problem at free values ``values[s]``.

    Candidates are full joint vectors (the free joints hold their row's values),
    so the shared verification and merging of :mod:`._arrays` apply unchanged.
    """

    method = "analytic"

    def __init__(self, family: FreeJointFamily, values: np.ndarray) -> None:
        self.family = family
        self.values = values
        self.structure = family.structure
        self.generic_count = family.generic_count
        self.free_joints = list(family.free)
        self.plans = ([family.plan] if family.ends_only
                      else [family.locked_plan(row) for row in values])
        self._m = family.generic_count

    def _moved_targets(self, targets: np.ndarray) -> np.ndarray:
        """Targets of the locked arm (free end joints at 0): E_prefix⁻¹ · target · home⁻¹ · E_suffix⁻¹ · home."""
        family = self.family
        model = family.geometry.model
        moved = targets.copy()
        values = dict(zip(family.free, self.values.T))
        for j in family.prefix:
            motion = joint_motion(model.directions[j], model.points[j], bool(model.is_revolute[j]), -values[j])
            moved = motion @ moved
        if family.suffix:
            home, home_inverse = model.home, np.linalg.inv(model.home)
            suffix = np.broadcast_to(np.eye(4), (len(targets), 4, 4))
            for j in family.suffix:
                suffix = suffix @ joint_motion(model.directions[j], model.points[j], bool(model.is_revolute[j]),
                                               values[j])
            moved = moved @ home_inverse @ np.linalg.inv(suffix) @ home
        return moved

    def solve(self, world_T_targets: np.ndarray, reference: np.ndarray | None) -> Candidates:
        """Candidates (S, m, n) for the rows' targets (S, 4, 4)."""
        family = self.family
        n_rows, n = len(world_T_targets), family.robot.dof
        locked_reference = None if reference is None else reference[family.kept]
        if family.ends_only:
            parts = [(np.arange(n_rows), family.plan.solve(self._moved_targets(world_T_targets), locked_reference))]
        else:
            parts = []
            self._one_pose = {}  # row → the scalar path's candidates, which carry their labels
            for row, plan in enumerate(self.plans):
                if plan is not None:  # one pose per plan: the scalar candidates when the pose is clearly generic
                    solve_one = getattr(plan, "solve_one", None)
                    part = solve_one(world_T_targets[row]) if solve_one is not None else None
                    if part is None:
                        part = plan.solve(world_T_targets[row:row + 1], locked_reference)
                    else:
                        self._one_pose[row] = part
                    parts.append((np.array([row]), part))
        m = max([self._m, *(part.joints.shape[1] for _, part in parts)])
        self._m = m
        joints = np.zeros((n_rows, m, n))
        joints[..., list(family.free)] = self.values[:, None, :]
        valid = np.zeros((n_rows, m), dtype=bool)
        singular = SingularFlags(n_rows)
        kept = family.kept
        for rows, part in parts:
            width = part.joints.shape[1]
            block = joints[rows, :width]
            block[..., kept] = part.joints
            joints[rows, :width] = block
            valid[rows, :width] = part.valid
            for mask, flag in part.singularities.entries:
                full = np.zeros(n_rows, dtype=bool)
                full[rows] = mask
                singular.add(full, Singularity(flag.kind, tuple(int(kept[i]) for i in flag.joints), flag.relation,
                                               flag.detail))
        self._valid = valid
        return Candidates(joints, valid, singular)

    def label_codes(self, joints: np.ndarray) -> LabelCodes:
        """Branch labels of full joint vectors (S·m, n), row-major over (row, slot): the locked family's."""
        kept = self.family.kept
        locked = joints[:, kept]
        if self.family.ends_only:
            return self.family.plan.label_codes(locked)
        m = len(joints) // max(len(self.plans), 1)
        pieces = []
        valid = getattr(self, "_valid", None)
        one_pose = getattr(self, "_one_pose", {})
        for row, plan in enumerate(self.plans):
            part = locked[row * m:(row + 1) * m]
            piece = {}
            if plan is not None:
                if valid is not None and valid.shape == (len(self.plans), m) and row in one_pose:
                    piece = one_pose[row].label_codes(valid[row].tolist())
                if not piece:
                    piece = plan.label_codes(part)
            pieces.append(piece)
        return joined_label_codes(pieces, [(m,)] * len(pieces))


@dataclass(frozen=True)
class FamilyAnswer:
    """Every solution of each target over the free values, one answer row per target (see :class:`IKArrays`).

    ``arrays.free_joints`` lists the free joints; each solution's free values are
    its own joint values there. ``missing`` (N,) counts the free values of each
    target at which the locked arm had no plan (the answer is then not complete
    for those values). ``refined`` (N,) counts the values added by the continuous
    search.
    """

    arrays: IKArrays
    values: np.ndarray
    missing: np.ndarray
    refined: np.ndarray


def solve_free_joint_family(robot: Robot, world_T_targets: np.ndarray, free: list[FreeJoint],
                            reference: np.ndarray | None, *, minima: int = REFINED_MINIMA,
                            rounds: int = REFINE_ROUNDS, budget: Budget = UNLIMITED) -> FamilyAnswer | None:
    """Every solution of each target (N, 4, 4) at each combination of the free joints' values.

    ``free`` names the free joints and their values (the grid is their
    product). With a reference, ``minima`` local minima of the distance are
    refined by ``rounds`` rounds of :func:`_refine_nearest` each. Returns None when locking
    them leaves no analytic family (the caller then falls back to the numeric
    search). ``budget`` is checked before each target and within its solves.
    """
    family = family_for(robot, tuple(sorted(f.joint for f in free)))
    if not family.available:
        return None
    by_joint = {f.joint: np.asarray(f.values, dtype=float) for f in free}
    grids = np.meshgrid(*(by_joint[j] for j in family.free), indexing="ij")
    values = np.stack([g.ravel() for g in grids], axis=-1)  # (S, f)
    if len(values) > MAX_FREE_VALUES:
        raise InvalidInputError(f"{len(values)} free values requested; at most {MAX_FREE_VALUES} per target")
    if not family.ends_only and len(values) > MAX_PLANNED_VALUES:
        raise InvalidInputError(
            f"{len(values)} free values requested; a free joint inside the chain needs one plan per value, so at "
            f"most {MAX_PLANNED_VALUES} (an end joint takes up to {MAX_FREE_VALUES})")
    targets = np.asarray(world_T_targets, dtype=float)
    rows_plan = _cached_rows_plan(family, values)
    answers, refined = [], []
    for target in targets:
        budget.check("the free-joint family")
        grid = _solve_rows(robot, family, rows_plan, target, values, reference, budget)
        extra = None
        if reference is not None and len(family.free) == 1:
            extra = _refine_nearest(robot, family, target, values, grid, reference, minima, rounds)
        answers.append(grid if extra is None else concatenated([grid, extra]))
        refined.append(0 if extra is None else len(extra.count))
    missing = sum(plan is None for plan in rows_plan.plans) if not family.ends_only else 0
    merged = _merged_rows(robot, answers, reference)
    return FamilyAnswer(merged, values, np.full(len(targets), missing), np.array(refined))


def _cached_rows_plan(family: FreeJointFamily, values: np.ndarray) -> _RowsPlan:
    """The rows plan for these values, kept on the family for the last few grids (the default grid repeats)."""
    key = values.tobytes()
    store = family.__dict__.setdefault("_rows_plans", {})
    plan = store.get(key)
    if plan is None:
        if len(store) >= 8:
            store.pop(next(iter(store)))
        plan = store[key] = family.rows_plan(values)
    return plan


def _solve_rows(robot: Robot, family: FreeJointFamily, rows_plan: _RowsPlan, target: np.ndarray,
                values: np.ndarray, reference: np.ndarray | None, budget: Budget = UNLIMITED) -> IKArrays:
    targets = np.broadcast_to(target, (len(values), 4, 4))
    return solve_ik_arrays(robot, targets, constrain_orientation=True, reference=reference, plan=rows_plan,
                           budget=budget)


def _branch_keys(arrays: IKArrays) -> np.ndarray:
    """One integer per slot (S, m) naming its branch: the combination of its label codes (−1: unlabelled)."""
    key = np.zeros(arrays.valid.shape, dtype=np.int64)
    for _, (values, codes) in sorted(arrays.labels.items()):
        key = key * (len(values) + 1) + (codes.astype(np.int64) + 1)
    return key


def _refine_nearest(robot: Robot, family: FreeJointFamily, target: np.ndarray, values: np.ndarray,
                    grid: IKArrays, reference: np.ndarray, minima_kept: int, rounds: int) -> IKArrays | None:
    """Solutions at the free values where a branch's distance to the reference has a minimum between samples.

    Along each branch the distance is known at the grid values; each of the
    ``minima_kept`` nearest local minima is bracketed by its grid
    neighbours and sampled at :data:`REFINE_POINTS` values, the branch followed
    there by Newton steps from the best solution so far; the bracket then
    narrows around the best value, and so on for ``rounds`` rounds (one batched
    Newton solve per round for all brackets). Returns the complete solution sets at the
    refined values, or None when there is nothing to refine.
    """
    joint = family.free[0]
    v = values[:, 0]
    order = np.argsort(v, kind="stable")
    v_sorted = v[order]
    distance = np.where(grid.valid, distance_to_reference(robot, grid.joints, reference), np.inf)[order]
    keys = _branch_keys(grid)[order]
    periodic = bool(robot.is_revolute[joint]) and np.isclose(v_sorted[-1] - v_sorted[0] + 2 * np.pi / len(v),
                                                             2 * np.pi) and len(v) > 2
    minima = []  # (distance, low, high, its solution, its value)
    sorted_joints = grid.joints[order]
    for key in np.unique(keys[grid.valid[order]]):
        on_branch = np.where(keys == key, distance, np.inf)
        slot = on_branch.argmin(axis=1)
        curve = on_branch[np.arange(len(v)), slot]  # (S,)
        for s in np.flatnonzero(np.isfinite(curve)):
            left, right = s - 1, s + 1
            if periodic:
                left, right = left % len(v), right % len(v)
            inside = [0 <= i < len(v) for i in (left, right)]
            left_value = curve[left] if inside[0] else np.inf
            right_value = curve[right] if inside[1] else np.inf
            if curve[s] <= left_value and curve[s] <= right_value:
                low = v_sorted[left] if inside[0] else v_sorted[s]
                high = v_sorted[right] if inside[1] else v_sorted[s]
                if periodic and s == 0:
                    low -= 2 * np.pi
                if periodic and s == len(v) - 1:
                    high += 2 * np.pi
                minima.append((float(curve[s]), float(low), float(high), sorted_joints[s, slot[s]],
                               float(v_sorted[s]), int(key)))
    if not minima:
        return None
    minima.sort(key=lambda entry: entry[0])
    chosen = minima[:minima_kept]
    low = np.array([entry[1] for entry in chosen])
    high = np.array([entry[2] for entry in chosen])
    start = np.array([entry[3] for entry in chosen])  # (K, n)
    keys_chosen = np.array([entry[5] for entry in chosen])

    best_value = np.array([entry[4] for entry in chosen])
    best_distance = np.array([entry[0] for entry in chosen])
    count = len(chosen)
    for _ in range(rounds):  # each round: REFINE_POINTS values across each bracket, then a bracket 8× narrower
        points = low[:, None] + (high - low)[:, None] * np.linspace(0.0, 1.0, REFINE_POINTS)[None, :]
        seeds = np.repeat(start, REFINE_POINTS, axis=0)
        if family.ends_only:  # one plan for every value: the closed form at all the points in one batch
            tracked, ok = _on_branch(robot, family, target, points.ravel(), np.repeat(keys_chosen, REFINE_POINTS),
                                     seeds, reference)
        else:
            tracked, ok = _track_branch(robot, family, target, seeds, points.ravel())
        distance = np.where(ok, distance_to_reference(robot, tracked, reference), np.inf).reshape(count, -1)
        pick = distance.argmin(axis=1)
        found = distance[np.arange(count), pick]
        better = found < best_distance
        best_distance = np.where(better, found, best_distance)
        best_value = np.where(better, points[np.arange(count), pick], best_value)
        start = np.where(better[:, None], tracked.reshape(count, REFINE_POINTS, -1)[np.arange(count), pick], start)
        spacing = (high - low) / (REFINE_POINTS - 1)
        low, high = np.maximum(low, best_value - spacing), np.minimum(high, best_value + spacing)
    best = best_value[np.isfinite(best_distance)]
    best = np.unique(_wrapped(robot, joint, best))
    best = best[np.abs(best[:, None] - v[None, :]).min(axis=1) > DUPLICATE_TOLERANCE]  # not already on the grid
    if not len(best):
        return None
    return _solve_at(robot, family, target, best, reference)


def _on_branch(robot: Robot, family: FreeJointFamily, target: np.ndarray, values: np.ndarray, keys: np.ndarray,
               seeds: np.ndarray, reference: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The solution on branch ``keys[i]`` (see :func:`_branch_keys`) at each free value ``values[i]`` (K,), by
    the closed form, or the one nearest ``seeds[i]`` where no solution carries that branch's labels. Returns the
    joint vectors (K, n) and which rows have a solution (K,)."""
    answer = _solve_at(robot, family, target, values, reference)
    same = (_branch_keys(answer) == keys[:, None]) & answer.valid
    gap = np.abs(wrap_angle(answer.joints - seeds[:, None, :])).max(axis=-1)
    gap = np.where(answer.valid, gap, np.inf)
    slot = np.where(same.any(axis=1), np.argmax(same, axis=1), gap.argmin(axis=1))
    rows = np.arange(len(values))
    return answer.joints[rows, slot], answer.valid[rows, slot]


def _track_branch(robot: Robot, family: FreeJointFamily, target: np.ndarray, seeds: np.ndarray,
                  values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Follow branches to new free values: Newton steps on the locked joints from ``seeds`` (K, n), with the
    free joint at ``values`` (K,). Returns the joint vectors (K, n) and which converged onto the target (K,);
    the closed form then solves the chosen values completely, so this only has to rank them."""
    from .._forward import forward_kinematics, geometric_jacobian
    from ._numeric import pose_error

    joint, kept, scale = family.free[0], family.kept, robot.characteristic_length
    q = seeds.copy()
    q[:, joint] = values
    error = pose_error(forward_kinematics(robot, q), target, scale)
    size = np.abs(error).max(axis=1)
    active = size > 1e-12
    for _ in range(TRACK_STEPS):
        if not active.any():
            break
        J = geometric_jacobian(robot, q[active])
        J[:, :3, :] /= scale
        J = J[:, :, kept]
        with np.errstate(all="ignore"):
            step = np.linalg.solve(J + 1e-12 * np.eye(6), error[active][..., None])[..., 0]
        q[np.ix_(np.flatnonzero(active), kept)] += np.nan_to_num(step)
        error[active] = pose_error(forward_kinematics(robot, q[active]), target, scale)
        new_size = np.abs(error).max(axis=1)
        # converged, or not converging quadratically (off the branch's reach): stop following that row
        active &= (new_size > 1e-12) & (new_size < 0.5 * size)
        size = new_size
    ok = size <= 1e-9
    return wrap_revolute(robot, q), ok


def _wrapped(robot: Robot, joint: int, values: np.ndarray) -> np.ndarray:
    if robot.is_revolute[joint]:
        wrapped = wrap_angle(values)
        inside = (values >= robot.lower[joint]) & (values <= robot.upper[joint])
        return np.where(inside, values, wrapped)
    return values


def _solve_at(robot: Robot, family: FreeJointFamily, target: np.ndarray, points: np.ndarray,
              reference: np.ndarray) -> IKArrays:
    """Every solution at each single free value in ``points`` (K,), one row each."""
    values = points[:, None]
    return _solve_rows(robot, family, family.rows_plan(values), target, values, reference)


def _merged_rows(robot: Robot, answers: list[IKArrays], reference: np.ndarray | None) -> IKArrays:
    """One row per target holding the solutions of all its rows (free values), distinct, in output order:
    nearest to the reference first, else by free value then slot."""
    flat = []
    for answer in answers:
        rows, slots = np.nonzero(answer.valid)
        flat.append((answer, rows, slots))
    m = max(1, max(len(rows) for _, rows, _ in flat))
    n = robot.dof
    n_targets = len(answers)
    joints = np.zeros((n_targets, m, n))
    valid = np.zeros((n_targets, m), dtype=bool)
    position = np.full((n_targets, m), np.inf)
    orientation = np.full((n_targets, m), np.inf)
    names: dict[str, tuple] = {}
    for answer, _, _ in flat:
        for name, (values, _) in answer.labels.items():
            names.setdefault(name, values)
    labels = {name: (values, np.full((n_targets, m), -1, dtype=np.int8)) for name, values in names.items()}
    singular = SingularFlags(n_targets)
    for t, (answer, rows, slots) in enumerate(flat):
        k = len(rows)
        joints[t, :k] = answer.joints[rows, slots]
        valid[t, :k] = True
        position[t, :k] = answer.position[rows, slots]
        orientation[t, :k] = answer.orientation[rows, slots]
        for name, (values, codes) in answer.labels.items():
            target_values = names[name]
            remap = np.array([target_values.index(v) for v in values] + [-1], dtype=np.int8)
            labels[name][1][t, :k] = remap[codes[rows, slots]]
        for mask, flag in answer.singularities.entries:
            if mask[rows].any() if k else False:
                row_mask = np.zeros(n_targets, dtype=bool)
                row_mask[t] = True
                singular.add(row_mask, flag)
    kept = valid  # rows at different free values cannot hold the same solution; each row is already distinct
    if reference is not None:
        key = np.where(kept, distance_to_reference(robot, joints, reference), np.inf)
        order = np.argsort(key, axis=1, kind="stable")
    else:
        order = np.argsort(~kept, axis=1, kind="stable")
    take = (np.arange(n_targets)[:, None], order)
    first = answers[0]
    return IKArrays(joints[take], kept[take], kept.sum(axis=1), position[take], orientation[take],
                    {name: (values, codes[take]) for name, (values, codes) in labels.items()}, singular,
                    first.structure, list(first.free_joints))


def free_joints_for(robot: Robot, requested: list[tuple[int, list[float] | None, int | None]] | None
                    ) -> list[FreeJoint] | None:
    """The free joints and values to solve at, from a request's ``(joint, values, samples)`` entries (radians /
    length units) or, when there are none, the default choice sampled :data:`DEFAULT_SAMPLES` times.

    Returns None when the request names none and no locking leaves a family. Raises
    :class:`InvalidInputError` for a request that does not name exactly n − 6 distinct joints of the arm
    (:class:`NotRedundantError` for an arm of 6 joints or fewer), located in ``requested``: ``()`` for the
    whole list, ``(index, "joint")`` or ``(index, "values")`` for one entry.
    """
    extra = robot.dof - 6
    if not requested:
        chosen = default_free_joints(robot)
        if chosen is None:
            return None
        return [FreeJoint(j, sample_values(robot, j, DEFAULT_SAMPLES)) for j in chosen]
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


def free_joint_solutions(robot: Robot, requested: list[tuple[int, list[float] | None, int | None]] | None,
                         refined: bool) -> int | None:
    """The most solutions one full-pose target of a redundant arm can have over its free joints (``requested`` as
    for :func:`free_joints_for`): the locked arm's generic count at each free value, and at the
    :data:`REFINED_MINIMA` values the continuous search adds when ``refined`` (a reference is given). None when
    no family covers the arm: the numeric search answers."""
    free = free_joints_for(robot, requested)
    if free is None:
        return None
    family = family_for(robot, tuple(sorted(f.joint for f in free)))
    if not family.available:
        return None
    values = int(np.prod([len(f.values) for f in free]))
    return (values + (REFINED_MINIMA if refined and len(free) == 1 else 0)) * family.generic_count


def beyond_reach(robot: Robot, positions: np.ndarray) -> np.ndarray:
    """Which world positions (..., 3) no joint vector can reach, by the reach sphere: each link moves the next
    frame by at most |a| + |d| (plus a prismatic joint's travel), so the tool stays within the sum of those
    and the tool offset from the base origin (the robot's characteristic length, which a robot described by
    joint screws or a URDF measures on its links). A proof of unreachability, not a test of reachability."""
    reach = robot.characteristic_length
    travel = np.where(robot.is_revolute, 0.0, np.maximum(np.abs(robot.lower), np.abs(robot.upper)))
    reach += float(np.sum(travel))
    distance = np.linalg.norm(np.asarray(positions) - robot.world_T_base[:3, 3], axis=-1)
    return distance > reach * (1.0 + 1e-9) + 1e-12


def no_solution_detail(robot: Robot, free: list[FreeJoint], position: np.ndarray | None = None) -> str:
    """What an empty answer of the family means: none at the values solved, which proves nothing for others,
    unless the position lies beyond the arm's reach."""
    if position is not None and bool(beyond_reach(robot, position)):
        return "The target position is outside the workspace (farther from the base than the arm can reach)."
    names = ", ".join(f"q{f.joint + 1}" for f in free)
    count = int(np.prod([len(f.values) for f in free]))
    return (f"No joint vector reaches the target at any of the {count} values of the free joint(s) {names} "
            f"solved (each solved completely); other values of {names} may reach it.")


def follow_free_joints(robot: Robot, world_T_targets: np.ndarray, reference: np.ndarray | None,
                       free: list[FreeJoint] | None = None) -> tuple[list, list[int]] | None:
    """Per-sample IK results of a redundant arm along a path, with the free joint held continuous.

    The first sample takes the family's solution nearest the reference (over
    the whole family: sampled, then searched continuously) or, without one, the
    family's first. Each later sample searches the free joint within
    :data:`TRACK_WINDOW` of the previous sample's value (sampled, then
    continuously) for the solution nearest the previous sample's joints, so the
    free parameter moves only as far as the path needs and every joint's step is
    the smallest the family allows; where that window cannot reach the pose, the
    whole family is searched. Returns (results, free joints) with one
    :class:`IKResult` per sample (to choose from, nearest first), or None when
    locking leaves no family. One free joint only.
    """
    from ._solve import results_from_arrays

    free = free or free_joints_for(robot, None)
    if free is None or len(free) != 1:
        return None
    joint = free[0].joint
    targets = np.asarray(world_T_targets, dtype=float)
    results = []
    previous = reference
    for target in targets:
        answer = None
        if previous is not None and len(results):
            window = previous[joint] + np.linspace(-TRACK_WINDOW, TRACK_WINDOW, TRACK_SAMPLES)
            window = np.clip(window, robot.lower[joint], robot.upper[joint])
            answer = solve_free_joint_family(robot, target[None], [FreeJoint(joint, np.unique(window))], previous,
                                             minima=1, rounds=TRACK_REFINE_ROUNDS)
        if answer is None or answer.arrays.count[0] == 0:
            answer = solve_free_joint_family(robot, target[None], free, previous)
        result = results_from_arrays(robot, answer.arrays, target[None], True, previous)[0]
        if result.solutions:
            previous = np.asarray(result.solutions[0].joints, dtype=float)
        results.append(result)
    return results, [joint]
