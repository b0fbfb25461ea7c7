"""Position-only targets whose held joints make them unreachable: search every joint before saying so.

An arm with more than three joints answers a position-only target with the
extra joints held at the reference (or 0). When that leaves the point out of
reach, other values of those joints may still reach it, so ``unreachable``
would be a false promise. This module decides such targets: beyond the arm's
reach sphere the point is outside the workspace (a proof); otherwise a bounded
numeric search over every joint returns the reachable solutions nearest the
held values, marked incomplete.
"""

from __future__ import annotations

import numpy as np

from .._robot import Robot
from ._redundant import beyond_reach
from ._solve import IKOptions, _numeric
from ._types import IKResult


def search_position(robot: Robot, world_T_target: np.ndarray, held: list[int], reference: np.ndarray | None,
                    options: IKOptions) -> IKResult:
    """The answer for a position-only target (4, 4) that the held joints ``held`` could not reach."""
    names = ", ".join(f"q{i + 1}" for i in held)
    if bool(beyond_reach(robot, world_T_target[:3, 3])):
        return IKResult(status="unreachable", solutions=[], method="analytic", structure="reach_sphere",
                        complete=True, free_joints=list(held),
                        detail="The target position is outside the workspace (farther from the base than the arm "
                               "can reach).")
    anchor = np.zeros(robot.dof) if reference is None else np.asarray(reference, dtype=float)
    result = _numeric(robot, world_T_target, False, anchor, options)
    if result.solutions:
        result.detail = (f"The position is out of reach with {names} held at the reference values (or 0); a "
                         f"numeric search over every joint found these solutions, nearest the held values first. "
                         f"It cannot promise that every solution was found. " + result.detail).strip()
    else:
        result.detail = (f"The position is out of reach with {names} held at the reference values (or 0), and a "
                         f"numeric search over every joint found no solution; it lies within the arm's reach "
                         f"sphere, so it is not proven outside the workspace. " + result.detail).strip()
    result.free_joints = []
    return result
