"""Inverse kinematics: every solution, found from the arm's geometry.

The solver reads the joint axes off the robot's product-of-exponentials
model, detects the structure (intersecting and parallel axes, wrists,
prismatic joints), and decomposes the problem into geometric subproblems
(Paden–Kahan 1–4, IK-Geo 5 and their prismatic analogues). Arms no family covers fall
back to a bounded numeric search that says it may be incomplete.
"""

from ._answer import (DIRECTION, POSE, POSITION, AnswerOptions, IKAnswer, IKTargets, PerTarget, SolverReport,
                      SolveTiming, TargetAnswer, UnsupportedTargetError, answer_ik, plans_are_kept,
                      solutions_per_target)
from ._arrays import IKArrays, arrays_from_results, cached_plan, solve_ik_arrays
from ._direction import solve_direction, target_kinds
from ._numeric import NumericOptions
from ._plan import plan_for
from ._position_search import search_position
from ._redundant import (MAX_FREE_VALUES, FamilyAnswer, FreeJoint, NotRedundantError, beyond_reach, follow_free_joints,
                         free_joints_for, no_solution_detail, solve_free_joint_family)
from ._select import (MAX_COMBINATIONS_PER_SOLUTION, MAX_EQUIVALENTS, NOTE_WORDING, Ordering, Selected, Selection,
                      SolutionTable, check_ordering, combinations_to_rank, enumerable_limit, joint_travel, select,
                      select_arrays, travel)
from ._solve import IKOptions, results_from_arrays, solve_ik, solve_ik_batch, unreachable_details
from ._types import IKResult, Singularity, Solution
from ._verify import distance_to_reference, joint_difference, wrap_revolute

__all__ = [
    "MAX_COMBINATIONS_PER_SOLUTION",
    "combinations_to_rank",
    "enumerable_limit",
    "AnswerOptions",
    "DIRECTION",
    "IKAnswer",
    "IKTargets",
    "POSE",
    "POSITION",
    "SolveTiming",
    "SolverReport",
    "TargetAnswer",
    "UnsupportedTargetError",
    "answer_ik",
    "plans_are_kept",
    "solutions_per_target",
    "arrays_from_results",
    "FamilyAnswer",
    "FreeJoint",
    "NotRedundantError",
    "IKArrays",
    "MAX_EQUIVALENTS",
    "NOTE_WORDING",
    "PerTarget",
    "MAX_FREE_VALUES",
    "IKOptions",
    "IKResult",
    "NumericOptions",
    "Ordering",
    "Selected",
    "Selection",
    "Singularity",
    "Solution",
    "SolutionTable",
    "beyond_reach",
    "cached_plan",
    "check_ordering",
    "follow_free_joints",
    "free_joints_for",
    "no_solution_detail",
    "solve_direction",
    "solve_free_joint_family",
    "target_kinds",
    "distance_to_reference",
    "joint_difference",
    "joint_travel",
    "plan_for",
    "results_from_arrays",
    "search_position",
    "select",
    "select_arrays",
    "solve_ik",
    "solve_ik_arrays",
    "solve_ik_batch",
    "travel",
    "unreachable_details",
    "wrap_revolute",
]
