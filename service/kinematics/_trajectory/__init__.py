"""Branch-consistent trajectories: joint positions, rates and accelerations along a sequence of poses.

:func:`follow_trajectory` takes samples (time, target pose, optional twist and
acceleration of the tool) and returns, per sample, one joint solution on a
consistent branch with its joint velocities and accelerations. It works in
three passes:

1. **Positions**, batch-solved for every sample at once with
   :func:`~..ik.solve_ik_batch` (vectorised over the samples for the analytic
   families). A sample where the IK reports a free joint (a wrist, shoulder or
   coincident-group singularity) is solved again with the previous sample's
   joints as reference, so the free joint keeps its value instead of jumping
   to 0.
2. **Branch choice**, sample by sample (:func:`._branch._follow`):

   * with ``branch`` (labels to hold, e.g. ``{"assembly_mode": 1}``), the
     solutions whose labels match; where the IK reports a singularity of the
     kind a label names (shoulder, elbow, wrist, the Assur group for
     ``assembly_mode``), the branches meet, so every solution there matches
     that label and the sample reports the held value. When no solution
     matches, the sample continues on the nearest one and says so
     (``status = "branch_unavailable"``);
   * among the candidates, the one nearest (wrap-aware, Euclidean in joint
     space, prismatic moves in units of the robot's size) to the previous
     sample's joints carried forward to this sample's time: by its twist and
     acceleration (q + q̇dt + ½q̈dt², exact inverse rates), or the polynomial
     through the last reached samples (:func:`._continuation._prediction`); at the first
     sample, the one nearest ``reference`` (the first in IK order without
     one). So the sample continues the branch, not the labels: beside a
     fold, where two solutions with the same labels meet, the other one is
     O(dt) from the prediction and the branch's own O(dt²) or less;
   * where the IK's answer leaves that open (no solution near the
     prediction, or two about as near), the prediction is carried onto the
     pose by Newton steps (the core's Gauss–Newton), which adds the branch's
     solution where a search near a singularity missed it; and every chosen
     solution is polished by Newton steps to the rounding of the pose, so a
     near-singular sample is exact to the digits its conditioning allows;
   * revolute joints are unwrapped so that each sample continues from the
     previous one (the first from ``reference``; without one, from its
     (−π, π] value, or the 2π-equivalent that fits the limits);
   * ``branch`` reports the solution's labels, except that a label the
     sample is singular in (or that the IK leaves out) keeps the held value
     or the previous sample's; a held label the solution leaves out does not
     rule it out. ``branch_changed`` is true when the labels differ from the
     previous reached sample's, or when the sample may not continue its
     branch: another solution about as near the prediction
     (:data:`AMBIGUITY_FACTOR`), or none within :data:`JUMP_FACTOR` joint
     steps of it (not reported where held labels chose the jump).
3. **Rates**, vectorised over all reached samples (:mod:`.._rates`):
   ``q̇ = J⁻¹ v``, ``q̈ = J⁻¹ (a − J̇ q̇)`` on the task rows the arm controls.
   For the paper's SCARA (:func:`~.._assur_arm.assur_scara_of`) positions,
   velocities and accelerations come from the RRR Assur group instead, as in
   the paper (two vectorised calls, one per assembly mode); the Jacobian then
   only measures the distance to a singularity and supplies the damped answer.

**Singularities.** A sample is flagged when the IK reports a singular
condition, when the Assur group is not regular, or when its distance to a
singularity (smallest singular value of the scaled task Jacobian, see
:mod:`.._rates`) is below ``singularity_tolerance``. A flagged sample has NaN
rates unless ``damping`` is given, in which case they are damped least squares.

**Collisions.** With ``collisions`` each reached sample carries its clearance, and with its filter the branch
choice takes the collision-free solutions only, reporting a branch change that a collision forces
(:mod:`._collisions`).

Modules: ``_records`` (options and results), ``_path`` (the checks and :func:`follow_trajectory`),
``_free_joints`` (a redundant arm's free joint along the path), ``_continuation`` (prediction, Newton steps,
polish, whole-turn continuity), ``_branch`` (the choice per sample), ``_collisions`` (the collision rule), ``_answer`` (rates and summary).
"""

# also importable from here, as before the split: the branch choice and the redundant arms' path
from ._branch import Tracking, _follow, ambiguous_labels  # noqa: F401
from ._free_joints import follow_free_joints  # noqa: F401
from ._path import follow_trajectory
from ._records import PaperJoints, SampleResult, TrajectoryOptions, TrajectoryResult, TrajectorySummary

__all__ = [
    "PaperJoints",
    "SampleResult",
    "TrajectoryOptions",
    "TrajectoryResult",
    "TrajectorySummary",
    "follow_trajectory",
]
