"""Inverse kinematics: every solution, found from the arm's geometry.

The solver reads the joint axes off the robot's product-of-exponentials
model, detects the structure (intersecting and parallel axes, wrists,
prismatic joints), and decomposes the problem into geometric subproblems
(Paden–Kahan 1–4 and their prismatic analogues). Arms no family covers fall
back to a bounded numeric search that says it may be incomplete.
"""

from ._numeric import NumericOptions
from ._plan import plan_for
from ._select import MAX_EQUIVALENTS, Ordering, Selected, Selection, check_ordering, joint_travel, select, travel
from ._solve import IKOptions, solve_ik, solve_ik_batch
from ._types import IKResult, Singularity, Solution
from ._verify import distance_to_reference, joint_difference, wrap_revolute

__all__ = [
    "MAX_EQUIVALENTS",
    "IKOptions",
    "IKResult",
    "NumericOptions",
    "Ordering",
    "Selected",
    "Selection",
    "Singularity",
    "Solution",
    "check_ordering",
    "distance_to_reference",
    "joint_difference",
    "joint_travel",
    "plan_for",
    "select",
    "solve_ik",
    "solve_ik_batch",
    "travel",
    "wrap_revolute",
]
