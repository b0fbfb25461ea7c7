"""Inverse kinematics: every solution, found from the arm's geometry.

The solver reads the joint axes off the robot's product-of-exponentials model, detects the structure
(intersecting and parallel axes, wrists, prismatic joints), and decomposes the problem into geometric
subproblems (Paden–Kahan 1–4, IK-Geo 5 and their prismatic analogues). Arms no family covers fall back to a
bounded numeric search that says it may be incomplete.

One answer, one form: every solver's candidates are verified into a :class:`SolutionTable`
(:func:`~._verify.verify`), selected against the limits (:func:`select`), and held by an :class:`IKAnswer`
(:func:`answer_ik`). :func:`solve_ik`, :func:`solve_ik_batch` and :func:`solve_ik_arrays` are views of it for
Python callers; :func:`estimate` counts a request's cost before any solving.
"""

from ._answer import (DIRECTION, POSE, POSITION, AnswerOptions, IKAnswer, IKOptions, IKTargets, PerTarget,
                      SolverReport, SolveTiming, TargetAnswer, UnsupportedTargetError, answer_ik, coaxial_redundancy)
from ._closed_form import cached_plan, plan_is_kept
from ._cost import SMALL_ROWS, Cost, estimate, is_small
from ._direction import DEFAULT_ROLL_SAMPLES, MAX_ROLL_ROWS, roll_samples, target_kinds
from ._equivalents import (MAX_COMBINATIONS_PER_SOLUTION, combinations_to_rank, enumerable_limit,
                           equivalents_per_solution, worst_answer_per_target)
from ._numeric import NumericOptions
from ._plan import plan_for
from ._redundant import (MAX_FREE_VALUES, FamilyVerified, FreeJoint, NotRedundantError, beyond_reach,
                         free_joints_for, no_solution_detail, solve_free_joint_family)
from ._select import MAX_EQUIVALENTS, NOTE_WORDING, Ordering, Selection, check_ordering, joint_travel, select, travel
from ._solve import (IKArrays, result_of, results_of, solve_direction, solve_ik, solve_ik_arrays, solve_ik_batch,
                     unlimited)
from ._table import SolutionTable
from ._types import IKResult, Singularity, Solution
from ._verify import distance_to_reference, joint_difference, wrap_revolute

__all__ = [
    "DEFAULT_ROLL_SAMPLES",
    "DIRECTION",
    "MAX_COMBINATIONS_PER_SOLUTION",
    "MAX_EQUIVALENTS",
    "MAX_FREE_VALUES",
    "MAX_ROLL_ROWS",
    "NOTE_WORDING",
    "POSE",
    "POSITION",
    "SMALL_ROWS",
    "AnswerOptions",
    "Cost",
    "FamilyVerified",
    "FreeJoint",
    "IKAnswer",
    "IKArrays",
    "IKOptions",
    "IKResult",
    "IKTargets",
    "NotRedundantError",
    "NumericOptions",
    "Ordering",
    "PerTarget",
    "Selection",
    "Singularity",
    "Solution",
    "SolutionTable",
    "SolveTiming",
    "SolverReport",
    "TargetAnswer",
    "UnsupportedTargetError",
    "answer_ik",
    "beyond_reach",
    "cached_plan",
    "check_ordering",
    "coaxial_redundancy",
    "combinations_to_rank",
    "distance_to_reference",
    "enumerable_limit",
    "equivalents_per_solution",
    "estimate",
    "is_small",
    "free_joints_for",
    "joint_difference",
    "joint_travel",
    "no_solution_detail",
    "plan_for",
    "plan_is_kept",
    "result_of",
    "results_of",
    "roll_samples",
    "select",
    "solve_ik",
    "solve_ik_arrays",
    "solve_direction",
    "solve_free_joint_family",
    "solve_ik_batch",
    "target_kinds",
    "travel",
    "unlimited",
    "worst_answer_per_target",
    "wrap_revolute",
]
