"""Inverse kinematics: every solution, found from the arm's geometry.

The solver reads the joint axes off the robot's product-of-exponentials
model, detects the structure (intersecting and parallel axes, wrists,
prismatic joints), and decomposes the problem into geometric subproblems
(Paden–Kahan 1–4, IK-Geo 5 and their prismatic analogues). Arms no family covers fall
back to a bounded numeric search that says it may be incomplete.
"""

from ._arrays import IKArrays, solve_ik_arrays
from ._numeric import NumericOptions
from ._plan import plan_for
from ._select import MAX_EQUIVALENTS, Ordering, Selected, Selection, check_ordering, joint_travel, select, travel
from ._select_arrays import SolutionTable, select_arrays
from ._solve import IKOptions, results_from_arrays, solve_ik, solve_ik_batch, unreachable_details
from ._types import IKResult, Singularity, Solution
from ._verify import distance_to_reference, joint_difference, wrap_revolute

__all__ = [
    "IKArrays",
    "MAX_EQUIVALENTS",
    "IKOptions",
    "IKResult",
    "NumericOptions",
    "Ordering",
    "Selected",
    "Selection",
    "Singularity",
    "Solution",
    "SolutionTable",
    "check_ordering",
    "distance_to_reference",
    "joint_difference",
    "joint_travel",
    "plan_for",
    "results_from_arrays",
    "select",
    "select_arrays",
    "solve_ik",
    "solve_ik_arrays",
    "solve_ik_batch",
    "travel",
    "unreachable_details",
    "wrap_revolute",
]
