"""Closed-form IK for a batch of targets: the robot's cached plan proposes candidates, :func:`~._verify.verify`
checks them, with no loop over targets; up to :data:`FEW_TARGETS` targets, a plan with a scalar path answers them
one at a time on floats, which costs less than the arrays' fixed cost.

Plans are built once per robot and kind of target (:func:`cached_plan`) and kept on the robot: they are values,
shared by concurrent requests, so a plan's call returns everything its caller needs. A batch larger than
:data:`CHUNK` is solved in chunks of at most the plan's ``targets_per_chunk`` (default :data:`CHUNK`), on up to
``threads`` threads (numpy releases the GIL inside its array operations, so the chunks run in parallel), and the
request's budget is checked before each chunk.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .._budget import UNLIMITED, Budget
from .._cache import is_memoised, memo
from .._robot import Robot
from ._goals import PoseGoal
from ._plan import Plan, plan_for
from ._table import SolutionTable
from ._types import Candidates, SingularFlags
from ._verify import OnePoseVerified, Verified, one_pose_table, verify, verify_one
from ._types import Sealed

#: Targets solved together: large enough that per-operation overhead is small, small enough that the
#: (chunk × m × n) temporaries stay in cache and memory is bounded whatever the batch size. A family whose
#: temporaries per target are a few dozen numbers solves more at once (its ``targets_per_chunk``).
CHUNK = 4096
#: Up to this many targets, a plan with a scalar path (``solve_one``) solves them one at a time on floats: the
#: arrays' fixed cost (about 1.5 ms a chunk for the 6R families) is that of several scalar answers. The two paths
#: cross near 8 for the PUMA, UR and OPW types (a call of 8 targets 1.3–2.2 ms on floats, 1.4–2.4 on the arrays).
FEW_TARGETS = 8


def cached_plan(robot: Robot, *, constrain_orientation: bool, reference: np.ndarray | None) -> Plan | None:
    """:func:`plan_for`, built once per robot and kind of target.

    A position-only target on an arm with more than three joints holds the others at the reference values:
    those plans depend on the values and are built each time rather than kept.
    """
    key = _plan_key(robot, constrain_orientation, reference)
    if key is None:
        return plan_for(robot, constrain_orientation=False, reference=reference)
    return memo(robot, key, lambda: _sealed(plan_for(robot, constrain_orientation=constrain_orientation,
                                                      reference=None)))


def _sealed(plan: Plan | None) -> Plan | None:
    """A plan to keep and share: sealed (:class:`~._types.Sealed`), so that no call can leave state on it."""
    if isinstance(plan, Sealed):
        plan.seal()
    return plan


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


def solve_closed_form(robot: Robot, plan: Plan, goal: PoseGoal, reference: np.ndarray | None, *,
                      threads: int | None = None, budget: Budget = UNLIMITED) -> Verified:
    """Every verified solution of the goal's N targets by the plan, vectorised over the targets (see the module
    docstring). ``reference`` (n,) sets the joints a target leaves free."""
    n_targets = len(goal)
    chunk = getattr(plan, "targets_per_chunk", CHUNK)
    if n_targets <= min(chunk, CHUNK):
        budget.check("the analytic solve")
        return _solved(robot, plan, goal, reference)
    threads = threads or os.cpu_count() or 1
    edges = chunk_edges(n_targets, threads, chunk)

    def solve(start: int, stop: int) -> Verified:
        budget.check("the analytic solve")
        return _solved(robot, plan, goal.take(np.arange(start, stop)), reference)

    workers = min(threads, len(edges) - 1)
    if workers > 1:
        with ThreadPoolExecutor(workers) as pool:
            parts = list(pool.map(solve, edges[:-1], edges[1:]))
    else:
        parts = [solve(start, stop) for start, stop in zip(edges[:-1], edges[1:])]
    return joined(parts, robot.dof)


def chunk_edges(n_targets: int, threads: int, chunk: int = CHUNK) -> list[int]:
    """Where the chunks of N targets start, and N: at most ``chunk`` targets each, as many chunks as a multiple
    of the threads that can work on them, all of one size (within one target), so that each thread has as much
    to do (10,000 on 2 threads: 4 of 2,500, not 4,096 + 4,096 on one and 1,808 on the other). A larger ``chunk``
    (a lean family's) makes fewer chunks, never fewer threads than :data:`CHUNK` would keep busy (10,000 on 2
    threads with 8,192: 2 of 5,000)."""
    chunks = max(-(-n_targets // chunk), min(threads, -(-n_targets // CHUNK)))
    workers = max(1, min(threads, chunks))
    chunks = -(-chunks // workers) * workers
    return [index * n_targets // chunks for index in range(chunks + 1)]


def _solved(robot: Robot, plan: Plan, goal: PoseGoal, reference: np.ndarray | None) -> Verified:
    """One chunk: the plan's candidates, verified. One target, or up to :data:`FEW_TARGETS`, go through its scalar
    path (one at a time) when it has one and every pose is clearly generic, verified on floats where
    :func:`verify_one` can; otherwise the whole chunk through its arrays."""
    n_targets = len(goal)
    if n_targets == 1 and hasattr(plan, "solve_one"):  # apart: a list of one and a join cost the single pose ~2 %
        one_pose = plan.solve_one(goal.world_T_targets[0], reference)
        if one_pose is not None:
            return _one_pose_verified(robot, plan, goal, one_pose, reference)
    elif n_targets <= FEW_TARGETS and hasattr(plan, "solve_one"):
        one_poses = [plan.solve_one(T, reference) for T in goal.world_T_targets]
        if None not in one_poses:
            return joined([_one_pose_verified(robot, plan, goal.take([index]), one_pose, reference)
                           for index, one_pose in enumerate(one_poses)], robot.dof)
    return verify(robot, goal, plan.solve(goal.world_T_targets, reference), reference, plan.label_codes)


def _one_pose_verified(robot: Robot, plan: Plan, goal: PoseGoal, one_pose, reference: np.ndarray | None
                       ) -> Verified:
    """One target's (``goal`` of one) scalar answer (``OnePose``) verified: on floats where :func:`verify_one`
    can, else its candidates on arrays, else (a label not clear) the plan's arrays."""
    verified = verify_one(robot, goal, one_pose, reference)
    if verified is not None:
        return verified
    candidates = _one_pose_candidates(one_pose)
    if candidates is None:
        candidates = plan.solve(goal.world_T_targets, reference)
    return verify(robot, goal, candidates, reference, plan.label_codes)


def plan_candidates(plan: Plan, world_T_targets: np.ndarray, reference: np.ndarray | None) -> np.ndarray:
    """The plan's candidate joint vectors (N, m, n) for N targets (N, 4, 4), NaN where a slot is empty, solved
    in chunks of at most :data:`CHUNK` targets (memory bounded as :func:`solve_closed_form`'s)."""
    parts = [plan.solve(world_T_targets[start:start + CHUNK], reference).joints
             for start in range(0, len(world_T_targets), CHUNK)]
    return parts[0] if len(parts) == 1 else np.concatenate(parts)


def _one_pose_candidates(one_pose) -> Candidates | None:
    """A family's scalar answer for one pose (``OnePose``) as candidates with their labels; None when it has none
    or a valid slot's label is not clear (the array path labels it then)."""
    if one_pose is None:
        return None
    valid = [q is not None for q in one_pose.rows]
    codes = one_pose.code_lists(valid)
    if codes is None:
        return None
    labels = {name: (values, np.array([column], dtype=np.int8))
              for name, values, column in zip(one_pose.names, one_pose.values, codes)}
    return Candidates(one_pose.joints, np.array([valid]), one_pose.singularities, labels=labels)


def joined(parts: list[Verified], dof: int) -> Verified:
    """One :class:`Verified` of consecutive groups of targets."""
    if all(isinstance(part, OnePoseVerified) for part in parts) and len({part.rows.names for part in parts}) == 1:
        table = one_pose_table([part.rows for part in parts], dof)  # one target each: their floats built once
    else:
        offsets = np.cumsum([0] + [len(part.complete) for part in parts])
        table = SolutionTable.concat([part.table.with_targets(part.table.target + offset)
                                      for part, offset in zip(parts, offsets)], dof)
    return Verified(table, np.concatenate([part.complete for part in parts]),
                    np.concatenate([part.nearest for part in parts]),
                    SingularFlags.concat([part.singularities for part in parts]))
