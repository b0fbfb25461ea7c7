"""A redundant arm's free joint searched continuously: the family's solution nearest a reference.

Along each branch (a combination of the locked family's branch labels, :func:`branch_keys`) the distance to the
reference is known at the grid's free values; each of the nearest local minima is bracketed by its grid
neighbours and sampled at :data:`REFINE_POINTS` values, the branch followed there (by the closed form when the
locked arm is the same for every value, else by Newton steps from the best solution so far), then the bracket
narrows around the best value, :data:`REFINE_ROUNDS` times. The locked problem is solved completely at each
refined value, so the answer stays complete for every free value it lists.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .._robot import Robot
from .._angles import wrap_angle
from .._tolerances import DUPLICATE_TOLERANCE
from ._gauss_newton import gauss_newton
from ._goals import PoseGoal
from ._redundant import FreeJointFamily, solve_at
from ._table import SolutionTable
from ._types import LabelCodes
from ._verify import Verified, distance_to_reference, wrap_revolute

#: Local minima of the distance to the reference refined per target, nearest first.
REFINED_MINIMA = 4
#: The free values solved beyond the grid when a reference is given: the refined minima and, where they found
#: nothing near it, the reference's own value (:func:`solve_at_reference`).
EXTRA_VALUES_WITH_REFERENCE = REFINED_MINIMA + 1
#: How near a solution found already must be to the reference for its own value not to be solved, and how near
#: to one found already a solution at that value is the same (radians or length units, the largest joint move):
#: above the refinement's last bracket (~3e-8 rad), below any step between two members a client tells apart.
SAME_AS_FOUND = 1e-6
#: Values tried across each bracket per refinement round; the next bracket spans two of their spacings (8× narrower).
REFINE_POINTS = 17
#: Refinement rounds per minimum: a 2π / 32 bracket (0.4 rad) to ~3e-8 rad.
REFINE_ROUNDS = 8
#: Newton steps that carry a branch's solution from one free value to a nearby one, and the error (normalised) at
#: which it has arrived.
TRACK_STEPS = 6
TRACK_CONVERGED = 1e-9


def branch_keys(labels: LabelCodes, rows: int) -> np.ndarray:
    """One integer per row (S,) naming its branch: the combination of its label codes (−1: unlabelled)."""
    key = np.zeros(rows, dtype=np.int64)
    for _, (values, codes) in sorted(labels.items()):
        key = key * (len(values) + 1) + (codes.astype(np.int64) + 1)
    return key


def refine_nearest(robot: Robot, family: FreeJointFamily, target: np.ndarray, values: np.ndarray, grid: Verified,
                   reference: np.ndarray, minima_kept: int, rounds: int) -> Verified | None:
    """The complete solutions at the free values where a branch's distance to the reference has a minimum between
    samples (see the module docstring), one verified row per refined value; None when there is nothing to refine.

    ``values`` (S,) are the grid's values of the one free joint; ``grid`` its answer, row s at ``values[s]``.
    """
    joint = family.free[0]

    def solve(chosen: np.ndarray) -> Verified:
        return solve_at(robot, family, target, chosen[:, None], reference)

    track = None if family.ends_only else (lambda seeds, points: _track_branch(robot, family, target, seeds, points))
    periodic = bool(robot.is_revolute[joint]) and _evenly_over_a_turn(values)
    return refine_over(robot, values, grid, reference, minima_kept, rounds, solve, track, periodic,
                       lambda chosen: _wrapped(robot, joint, chosen))


def solve_at_reference(robot: Robot, family: FreeJointFamily, target: np.ndarray, found: list[Verified],
                       reference: np.ndarray) -> Verified | None:
    """The complete solutions at the reference's own value of the one free joint, where the grid and the
    refinement (``found``) have none within :data:`SAME_AS_FOUND` of the reference: a branch that reaches the
    target only between two grid values (an elbow a few hundredths of a radian from straight gives one that
    narrow) has no sample to refine from, and a reference on it is then found where it is. Rows within
    SAME_AS_FOUND of one found already are left out; None where a solution found already is that near the
    reference (nothing is solved then)."""
    found_joints = np.concatenate([part.table.joints for part in found])
    if len(found_joints) and distance_to_reference(robot, found_joints, reference).min() <= SAME_AS_FOUND:
        return None
    joint = family.free[0]
    solved = solve_at(robot, family, target, np.asarray(reference, dtype=float)[[joint]][None], reference)
    new = [len(found_joints) == 0 or distance_to_reference(robot, found_joints, row).min() > SAME_AS_FOUND
           for row in solved.table.joints]
    if all(new):
        return solved
    return Verified(solved.table.take(np.flatnonzero(new)), solved.complete, solved.nearest, solved.singularities)


def _evenly_over_a_turn(values: np.ndarray) -> bool:
    """Whether sorted ``values`` (S,) sample a whole turn evenly (the last one a step short of the first + 2π)."""
    v = np.sort(values)
    return len(v) > 2 and bool(np.isclose(v[-1] - v[0] + 2 * np.pi / len(v), 2 * np.pi))


def refine_over(robot: Robot, values: np.ndarray, grid: Verified, reference: np.ndarray, minima_kept: int,
                rounds: int, solve: Callable[[np.ndarray], Verified],
                track: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]] | None, periodic: bool,
                wrap: Callable[[np.ndarray], np.ndarray]) -> Verified | None:
    """:func:`refine_nearest` for any one-parameter family: ``solve(v)`` answers completely at the values v (K,),
    one verified row each; ``track(seeds (K, n), v (K,))`` follows branches by Newton steps (None: ``solve`` is
    cheap enough to call at every point, the closed form in one batch); ``periodic``: the values wrap around a
    turn; ``wrap`` maps refined values into the parameter's range."""
    table = grid.table
    if not len(table):
        return None
    order = np.argsort(values, kind="stable")
    rank = np.empty(len(values), dtype=int)
    rank[order] = np.arange(len(values))
    v_sorted = values[order]
    distance = distance_to_reference(robot, table.joints, reference)
    keys = branch_keys(table.labels, len(table))
    position = rank[table.target]  # each solution's value, by its rank among the sorted values
    minima = []  # (distance, low, high, its solution, its value, its branch)
    for key in np.unique(keys):
        on_branch = np.flatnonzero(keys == key)
        curve = np.full(len(values), np.inf)
        best = np.full(len(values), -1)
        for row in on_branch[np.argsort(distance[on_branch], kind="stable")[::-1]]:  # nearest last: it wins
            curve[position[row]], best[position[row]] = distance[row], row
        for s in np.flatnonzero(np.isfinite(curve)):
            left, right = s - 1, s + 1
            if periodic:
                left, right = left % len(values), right % len(values)
            inside = [0 <= i < len(values) for i in (left, right)]
            left_value = curve[left] if inside[0] else np.inf
            right_value = curve[right] if inside[1] else np.inf
            if curve[s] <= left_value and curve[s] <= right_value:
                low = v_sorted[left] if inside[0] else v_sorted[s]
                high = v_sorted[right] if inside[1] else v_sorted[s]
                if periodic and s == 0:
                    low -= 2 * np.pi
                if periodic and s == len(values) - 1:
                    high += 2 * np.pi
                minima.append((float(curve[s]), float(low), float(high), table.joints[best[s]], float(v_sorted[s]),
                               int(key)))
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
        if track is None:  # the closed form at all the points in one batch
            tracked, ok = _on_branch(robot, solve, points.ravel(), np.repeat(keys_chosen, REFINE_POINTS), seeds)
        else:
            tracked, ok = track(seeds, points.ravel())
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
    best = np.unique(wrap(best))
    best = best[np.abs(best[:, None] - values[None, :]).min(axis=1) > DUPLICATE_TOLERANCE]  # not already on the grid
    if not len(best):
        return None
    return solve(best)


def _on_branch(robot: Robot, solve: Callable[[np.ndarray], Verified], values: np.ndarray, keys: np.ndarray,
               seeds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The solution on branch ``keys[i]`` (:func:`branch_keys`) at each free value ``values[i]`` (K,), by the
    closed form, or the one nearest ``seeds[i]`` where no solution carries that branch's labels. Returns the joint
    vectors (K, n) and which rows have a solution (K,)."""
    table: SolutionTable = solve(values).table
    rows = np.arange(len(values))
    joints, ok = np.zeros((len(values), robot.dof)), np.zeros(len(values), dtype=bool)
    if not len(table):
        return joints, ok
    same = branch_keys(table.labels, len(table)) == keys[table.target]
    gap = np.abs(wrap_angle(table.joints - seeds[table.target])).max(axis=-1)
    # per value: a solution of the same branch first (the first such), else the one nearest the seed
    score = np.where(same, -1.0, gap)
    order = np.lexsort((np.arange(len(table)), score, table.target))
    first = order[np.searchsorted(table.target[order], rows)[np.isin(rows, table.target)]]
    joints[table.target[first]], ok[table.target[first]] = table.joints[first], True
    return joints, ok


def _track_branch(robot: Robot, family: FreeJointFamily, target: np.ndarray, seeds: np.ndarray,
                  values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Follow branches to new free values: Newton steps on the locked joints from ``seeds`` (K, n), with the free
    joint at ``values`` (K,), stopping a row that no longer converges quadratically (off the branch's reach).
    Returns the joint vectors (K, n) and which converged onto the target (K,); the closed form then solves the
    chosen values completely, so this only has to rank them."""
    q = seeds.copy()
    q[:, family.free[0]] = values
    moving = np.zeros(robot.dof, dtype=bool)
    moving[family.kept] = True
    reached = gauss_newton(robot, PoseGoal(target[None]), q, np.zeros(len(q), dtype=int), steps=TRACK_STEPS,
                           tolerance=1e-12, contraction=0.5, moving=moving)
    return wrap_revolute(robot, reached.joints), reached.error <= TRACK_CONVERGED


def _wrapped(robot: Robot, joint: int, values: np.ndarray) -> np.ndarray:
    if robot.is_revolute[joint]:
        inside = (values >= robot.lower[joint]) & (values <= robot.upper[joint])
        return np.where(inside, values, wrap_angle(values))
    return values
