"""Branch-consistent trajectories: joint positions, rates and accelerations along a sequence of poses.

:func:`follow_trajectory` takes samples (time, target pose, optional twist and
acceleration of the tool) and returns, per sample, one joint solution on a
consistent branch with its joint velocities and accelerations. It works in
three passes:

1. **Positions**, batch-solved for every sample at once with
   :func:`~.ik.solve_ik_batch` (vectorised over the samples for the analytic
   families). A sample where the IK reports a free joint (a wrist, shoulder or
   coincident-group singularity) is solved again with the previous sample's
   joints as reference, so the free joint keeps its value instead of jumping
   to 0.
2. **Branch choice**, sample by sample (:func:`_follow`):

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
     through the last reached samples (:func:`_prediction`); at the first
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
3. **Rates**, vectorised over all reached samples (:mod:`._rates`):
   ``q̇ = J⁻¹ v``, ``q̈ = J⁻¹ (a − J̇ q̇)`` on the task rows the arm controls.
   For the paper's SCARA (:func:`~._assur_arm.assur_scara_of`) positions,
   velocities and accelerations come from the RRR Assur group instead, as in
   the paper (two vectorised calls, one per assembly mode); the Jacobian then
   only measures the distance to a singularity and supplies the damped answer.

**Singularities.** A sample is flagged when the IK reports a singular
condition, when the Assur group is not regular, or when its distance to a
singularity (smallest singular value of the scaled task Jacobian, see
:mod:`._rates`) is below ``singularity_tolerance``. A flagged sample has NaN
rates unless ``damping`` is given, in which case they are damped least squares.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Literal, Mapping

import numpy as np

from ._assur import RRRCase
from ._assur_arm import AssurScara, assur_scara_of
from ._errors import InvalidInputError
from ._limits import Limits, Violation, nearest_fitting_equivalent, violations, within
from ._forward import geometric_jacobian
from ._rates import TaskSpace, joint_rates, rate_residuals, task_jacobian, task_space
from ._robot import Robot, check_joint_values
from ._tolerances import ACCEPT_RESIDUAL, DUPLICATE_TOLERANCE, RATE_SINGULARITY_TOLERANCE
from ._trajectory_collisions import SampleClearance, collision_free_pool, forced_by_collision, sample_clearances
from .collision import CollisionRequest, at_collisions, model_for
from .ik import (
    AnswerOptions,
    IKOptions,
    IKResult,
    IKTargets,
    Singularity,
    answer_ik,
    coaxial_redundancy,
    distance_to_reference,
    free_joints_for,
    joint_difference,
    plan_for,
    result_of,
    solve_ik,
    solve_ik_batch,
    unlimited,
)
from .ik._gauss_newton import gauss_newton
from .ik._goals import PoseGoal
from .ik._types import LabelCodes

__all__ = [
    "PaperJoints",
    "SampleResult",
    "TrajectoryOptions",
    "TrajectoryResult",
    "TrajectorySummary",
    "follow_trajectory",
]

#: The branch labels that a singularity of each kind makes ambiguous (their two values meet there). With the
#: point on the first axis (shoulder "free") the line from the shoulder to the point is that axis, so the
#: elbow's side of it is undefined as well.
LABEL_OF_SINGULARITY = {"shoulder": ("shoulder",), "elbow": ("elbow",), "wrist": ("wrist",),
                        "assur_group": ("assembly_mode",)}
_FREE_SHOULDER_LABELS = ("shoulder", "elbow")


def ambiguous_labels(singularities: list[Singularity]) -> set[str]:
    """The branch labels that do not tell the branches apart at a sample with these singular conditions."""
    labels: set[str] = set()
    for s in singularities:
        labels.update(_FREE_SHOULDER_LABELS if (s.kind, s.relation) == ("shoulder", "free")
                      else LABEL_OF_SINGULARITY.get(s.kind, ()))
    return labels

#: Singularity relations under which the IK sets a free joint (to the reference, here the previous sample).
_FREE_RELATIONS = frozenset({"free", "sum", "difference", "signed_sum", "coincident"})


@dataclass(frozen=True)
class TrajectoryOptions:
    """How to follow a trajectory.

    Attributes
    ----------
    branch : mapping, optional
        Branch labels to hold, as the IK names them (``{"shoulder": "left"}``,
        ``{"assembly_mode": 1}``).
    reference : ndarray, shape (n,), optional
        Joint values the first sample continues from (radians, length units).
    limits : Limits, optional
        Limits to check (default: the robot's).
    singularity_tolerance : float
        Smallest singular value of the scaled task Jacobian below which a
        sample is singular.
    damping : float, optional
        λ for damped least-squares rates at singular samples; None leaves
        their rates NaN.
    ik : IKOptions
        Passed to the position IK.
    free_joints : list of (joint, values or None, samples or None), optional
        A redundant arm's free joints and where to solve them, radians / length units, as single IK takes them
        (:class:`~.ik.AnswerOptions`); None lets the trajectory choose and hold them continuous.
    collisions : CollisionRequest, optional
        Check each sample's joints; with its ``filter``, stay on collision-free solutions
        (:mod:`._trajectory_collisions`).
    """

    branch: Mapping[str, str | int] | None = None
    reference: np.ndarray | None = None
    limits: Limits | None = None
    singularity_tolerance: float = RATE_SINGULARITY_TOLERANCE
    damping: float | None = None
    ik: IKOptions = field(default_factory=IKOptions)
    free_joints: list[tuple[int, list[float] | None, int | None]] | None = None
    collisions: CollisionRequest | None = None


@dataclass(frozen=True)
class PaperJoints:
    """The paper's SCARA joints (θ1, θ2 = θ1 − θ_BC, l3), rates and accelerations, and the group's case."""

    joints: np.ndarray
    velocities: np.ndarray
    accelerations: np.ndarray
    case: str


@dataclass
class SampleResult:
    """One sample of the trajectory. Arrays have shape (n,); rates are NaN where not computed. With a collision
    check, ``clearance`` holds the reached joints' check, and ``collision_forced`` says the sample left its
    branch because the continuation collides."""

    time: float
    status: Literal["ok", "unreachable", "not_found", "branch_unavailable", "no_collision_free_solution"]
    joints: np.ndarray | None = None
    velocities: np.ndarray | None = None
    accelerations: np.ndarray | None = None
    branch: dict = field(default_factory=dict)
    branch_changed: bool = False
    singularities: list[Singularity] = field(default_factory=list)
    distance_to_singularity: float | None = None
    damped: bool = False
    violations: list[Violation] = field(default_factory=list)
    velocity_residual: float | None = None
    acceleration_residual: float | None = None
    paper: PaperJoints | None = None
    clearance: SampleClearance | None = None
    collision_forced: bool = False

    @property
    def reached(self) -> bool:
        return self.joints is not None


@dataclass
class TrajectorySummary:
    """Over the whole trajectory.

    ``largest_joint_step`` (n,) is the largest |q_i(k) − q_i(k−1)| over
    consecutive samples that were both reached (NaN if there are none), and
    ``largest_joint_step_at`` the sample k where it happens. The smallest
    distance to a singularity is over the reached samples. With a collision
    check: the reached samples whose joints collide, those whose branch
    change a collision forced, and the smallest clearance (None without a
    check, or when nothing is checked) and where.
    """

    largest_joint_step: np.ndarray
    largest_joint_step_at: list[int | None]
    smallest_distance_to_singularity: float | None
    smallest_distance_at: int | None
    limit_violations: list[tuple[int, Violation]]
    singular_samples: list[int]
    branch_changes: list[int]
    unreachable_samples: list[int]
    colliding_samples: list[int] = field(default_factory=list)
    collision_branch_changes: list[int] = field(default_factory=list)
    smallest_clearance: float | None = None
    smallest_clearance_at: int | None = None


@dataclass
class TrajectoryResult:
    samples: list[SampleResult]
    summary: TrajectorySummary
    method: str
    structure: str
    complete: bool
    rates: Literal["jacobian", "assur_group"]
    task: TaskSpace
    assur: AssurScara | None


# --------------------------------------------------------------------------
# Validation
# --------------------------------------------------------------------------


def _check_times(times) -> np.ndarray:
    t = np.asarray(times, dtype=float)
    if t.ndim != 1 or len(t) == 0:
        raise InvalidInputError(f"times must be a non-empty list, got shape {t.shape}", location=("samples",))
    bad = np.flatnonzero(~np.isfinite(t))
    if len(bad):
        raise InvalidInputError("time must be finite", location=("samples", int(bad[0]), "time"))
    back = np.flatnonzero(np.diff(t) <= 0.0)
    if len(back):
        k = int(back[0]) + 1
        raise InvalidInputError(f"sample times must increase strictly: sample {k} has time {t[k]:g}, "
                                f"sample {k - 1} has {t[k - 1]:g}", location=("samples", k, "time"))
    return t


def _check_cartesian(values, name: str, count: int, task: TaskSpace) -> tuple[np.ndarray | None, np.ndarray]:
    """(N, 6) with NaN for parts not given; and which samples gave one. Parts the task needs must be given."""
    if values is None:
        return None, np.zeros(count, dtype=bool)
    array = np.array(values, dtype=float)
    if array.shape != (count, 6):
        raise InvalidInputError(f"{name} must have shape ({count}, 6), got {array.shape}", location=(name,))
    given = ~np.isnan(array).all(axis=1)
    if np.isinf(array).any():
        row = int(np.argwhere(np.isinf(array))[0][0])
        raise InvalidInputError(f"{name} must be finite", location=("samples", row, name))
    needs = [("linear", slice(0, 3), task.uses_linear), ("angular", slice(3, 6), task.uses_angular)]
    for part, columns, needed in needs:
        missing = given & np.isnan(array[:, columns]).any(axis=1)
        if needed and missing.any():
            row = int(np.flatnonzero(missing)[0])
            raise InvalidInputError(
                f"this arm's rates are solved on the task rows {', '.join(task.names)}, which need the "
                f"{part} part of the {name}", location=("samples", row, name, part))
    return array, given


def _check_branch(branch: Mapping | None, results: list[IKResult]) -> dict:
    if not branch:
        return {}
    available = {key for result in results for solution in result.solutions for key in solution.branch}
    if any(result.solutions for result in results):
        for key in branch:
            if key not in available:
                names = ", ".join(sorted(available)) or "none"
                raise InvalidInputError(
                    f"this arm's solutions carry the branch labels: {names} (structure {results[0].structure}); "
                    f"{key!r} is not one of them", location=("branch", key))
    return dict(branch)


# --------------------------------------------------------------------------
# Following
# --------------------------------------------------------------------------


def follow_trajectory(robot: Robot, times, world_T_targets, *, constrain_orientation: bool = True,
                      twists=None, accelerations=None,
                      options: TrajectoryOptions | None = None) -> TrajectoryResult:
    """Joint positions, velocities and accelerations on one branch along a sampled tool trajectory.

    Parameters
    ----------
    times : array-like, shape (N,)
        Strictly increasing sample times [s].
    world_T_targets : array-like, shape (N, 4, 4)
        Target poses; only their positions count when ``constrain_orientation`` is false.
    twists : array-like, shape (N, 6), optional
        ``[ṗ; ω]`` of the tool origin in the world frame (length/s, rad/s). A
        row of NaN means no twist for that sample (its rates are NaN); a NaN
        part that the arm's task rows need is an error.
    accelerations : array-like, shape (N, 6), optional
        ``[p̈; ω̇]`` (length/s², rad/s²), the same way. A sample with an
        acceleration needs a twist.
    options : TrajectoryOptions

    Returns
    -------
    TrajectoryResult

    Raises
    ------
    InvalidInputError
        Non-increasing or non-finite times, a twist or acceleration of the
        wrong shape or lacking a part the arm needs, an acceleration without a
        twist, a branch label the arm's solutions do not carry, a reference of
        the wrong length; the location names the sample and field.
    """
    options = options or TrajectoryOptions()
    times = _check_times(times)
    targets = np.asarray(world_T_targets, dtype=float)
    count = len(times)
    if targets.shape != (count, 4, 4):
        raise InvalidInputError(f"expected {count} target poses of shape (4, 4), got shape {targets.shape}",
                                location=("samples",))
    reference = None
    if options.reference is not None:
        try:
            reference = check_joint_values(robot, options.reference)
        except InvalidInputError as error:
            raise error.relocated("reference") from None
    if not np.isfinite(options.singularity_tolerance) or options.singularity_tolerance < 0:
        raise InvalidInputError("singularity_tolerance must be a non-negative number",
                                location=("singularity_tolerance",))
    if options.damping is not None and not (np.isfinite(options.damping) and options.damping > 0):
        raise InvalidInputError("damping must be a positive number", location=("damping",))
    limits = options.limits or Limits.of(robot)
    if options.collisions is not None:
        with at_collisions():
            model_for(robot, options.collisions)  # compiled once, kept: an error in it is the request's

    plan = plan_for(robot, constrain_orientation=constrain_orientation, reference=reference)
    # a redundant arm (issue 14): the free joints held continuous along the path, their rates 0; the ones the
    # request names, where it names them (as single IK takes them). A 7-joint arm whose redundancy is a coaxial
    # pair takes its six-joint closed form instead, unless the request names free joints
    family = None
    if constrain_orientation and (options.free_joints is not None
                                  or (robot.dof > 6 and not coaxial_redundancy(robot))):
        try:
            family = follow_free_joints(robot, targets, reference, options.ik, options.free_joints)
        except InvalidInputError as error:
            raise error.relocated("free_joints") from None
    task = task_space(robot, constrain_orientation=constrain_orientation,
                      free_joints=family[1] if family is not None else
                      plan.free_joints if plan is not None else ())
    twist, has_twist = _check_cartesian(twists, "twist", count, task)
    acceleration, has_acceleration = _check_cartesian(accelerations, "acceleration", count, task)
    orphan = np.flatnonzero(has_acceleration & ~has_twist)
    if len(orphan):
        raise InvalidInputError("an acceleration needs the sample's twist (q̈ = J⁻¹(a − J̇q̇) needs q̇)",
                                location=("samples", int(orphan[0]), "acceleration"))
    results = family[0] if family is not None else solve_ik_batch(
        robot, targets, constrain_orientation=constrain_orientation, reference=reference, options=options.ik)
    held = _check_branch(options.branch, results)

    labels = None
    if plan is not None and robot.dof <= 6:
        labels = plan.label_codes
    samples = _follow(robot, times, targets, results, held, reference, limits, constrain_orientation, options.ik,
                      Tracking(twist, task, labels, acceleration), options.collisions)
    assur = assur_scara_of(robot)
    reached = np.array([k for k, s in enumerate(samples) if s.reached], dtype=int)
    if len(reached):
        _rates_of(robot, samples, reached, targets, twist, acceleration, task, assur, options)
    options.ik.budget.check("the trajectory's rates")
    for sample in samples:
        if sample.reached:
            sample.violations = violations(robot, limits, sample.joints)
    if options.collisions is not None:
        options.ik.budget.check("the collision check")
        reached_samples = [s for s in samples if s.reached]
        checked = sample_clearances(robot, options.collisions, np.array([s.joints for s in reached_samples]))
        for sample, clearance in zip(reached_samples, checked):
            sample.clearance = clearance
    first = results[0]
    return TrajectoryResult(samples, _summary(robot, samples), first.method, first.structure,
                            all(r.complete for r in results), "assur_group" if assur else "jacobian", task, assur)


#: Along a path, how far (rad or length units) and at how many values a redundant arm's free joint is searched
#: around the previous sample's value before its whole family is.
TRACK_WINDOW = 0.25
TRACK_SAMPLES = 9


def follow_free_joints(robot: Robot, world_T_targets: np.ndarray, reference: np.ndarray | None,
                       ik: IKOptions, requested: list | None = None) -> tuple[list[IKResult], list[int]] | None:
    """Per-sample IK results of a redundant arm along a path, with the free joint held continuous.

    ``requested``: the request's free joints, ``(joint, values or None, samples or None)`` entries in radians /
    length units, with the meaning they have in single IK (:func:`~.ik.free_joints_for`): each sample is
    answered over those joints at those values (:func:`~.ik.answer_ik`), nearest the previous sample first.
    Raises :class:`InvalidInputError` (located in the list) for entries single IK refuses.

    The first sample takes the family's solution nearest the reference (over the whole family: sampled, then
    searched continuously) or, without one, the family's first. Each later sample searches the free joint within
    :data:`TRACK_WINDOW` of the previous sample's value (sampled, then continuously) for the solution nearest the
    previous sample's joints, so the free parameter moves only as far as the path needs; where that window cannot
    reach the pose, the whole family is searched. Every sample is answered by :func:`~.ik.answer_ik`, as single IK
    is. Returns (results, free joints), one :class:`IKResult` per sample (nearest first), or None when the arm has
    no single free joint a family covers.
    """
    if requested is not None:
        joints = sorted(f.joint for f in free_joints_for(robot, requested))
        results, previous = [], reference
        for target in np.asarray(world_T_targets, dtype=float):
            ik.budget.check("the trajectory")
            result = _family_result(robot, target, requested, previous, ik)
            if result.solutions:
                previous = np.asarray(result.solutions[0].joints, dtype=float)
            results.append(result)
        return results, joints
    free = free_joints_for(robot, None)
    if free is None or len(free) != 1:
        return None
    joint = free[0].joint
    results = []
    previous = reference
    for target in np.asarray(world_T_targets, dtype=float):
        ik.budget.check("the trajectory")
        result = None
        if previous is not None and results:
            window = np.unique(np.clip(previous[joint] + np.linspace(-TRACK_WINDOW, TRACK_WINDOW, TRACK_SAMPLES),
                                       robot.lower[joint], robot.upper[joint]))
            result = _family_result(robot, target, [(joint, window.tolist(), None)], previous, ik)
        if result is None or not result.solutions:
            result = _family_result(robot, target, None, previous, ik)
        if result.solutions:
            previous = np.asarray(result.solutions[0].joints, dtype=float)
        results.append(result)
    return results, [joint]


def _family_result(robot: Robot, target: np.ndarray, free_joints: list | None, reference: np.ndarray | None,
                   ik: IKOptions) -> IKResult:
    """One pose of a redundant arm answered over its free joint (``free_joints`` as a request gives them, None
    for the default sampling), nearest the reference first."""
    answer = answer_ik(robot, IKTargets.poses(target[None]),
                       AnswerOptions(reference=reference, limits=unlimited(robot), filter_limits=False, search=ik,
                                     free_joints=free_joints, budget=ik.budget))
    return result_of(answer, 0)


def _has_free_joint(result: IKResult) -> bool:
    return any(s.relation in _FREE_RELATIONS for s in result.singularities)


#: Gauss–Newton steps that carry the predicted joints onto a sample's pose (tracking), and that polish the chosen
#: solution to the end of its digits; both stop once a step no longer halves the error.
TRACK_NEWTON_STEPS = 8
POLISH_NEWTON_STEPS = 4
#: The polish leaves joints whose error (normalised, ‖e‖∞) is already at the rounding of the pose (a few ulps).
POLISHED = 4.0 * float(np.finfo(float).eps)
#: A second solution within this factor of the chosen one's distance to the prediction leaves the choice open.
AMBIGUITY_FACTOR = 2.0
#: The chosen solution is off the branch when it is farther from the prediction than this many joint steps.
JUMP_FACTOR = 4.0
#: The prediction is carried onto the pose by Newton steps when no solution of the IK is within this many joint
#: steps of it (or the choice is ambiguous).
TRACK_FACTOR = 0.5
#: Two solutions closer than this (Euclidean, radians or fractions of the robot's size) are one: at a fold
#: (two solutions meeting) the residual grows with the square of the distance, so the FK check accepts a band
#: of about √ACCEPT_RESIDUAL around the solution.
SAME_SOLUTION = float(np.sqrt(ACCEPT_RESIDUAL))


@dataclass(frozen=True)
class Tracking:
    """What the branch following needs besides the IK answers: the twists and accelerations (N, 6) (NaN rows:
    none), the task rows
    the rates are solved on (its ``columns`` are the joints that move), and the labels of a joint vector (M, n)
    as the IK names them (None: no labels). Without it (``_follow(..., tracking=None)``) the choice is from
    the IK's solutions alone, by the previous sample's joints extrapolated."""

    twists: np.ndarray | None
    task: TaskSpace
    label_codes: Callable[[np.ndarray], LabelCodes] | None = None
    accelerations: np.ndarray | None = None


@dataclass
class _Reached:
    """A reached sample on the branch being followed: joints (n,), time, and joint rates (n,) from its twist (and
    acceleration), None where not given."""

    q: np.ndarray
    time: float
    qd: np.ndarray | None = None
    qdd: np.ndarray | None = None


def _rates_at(robot: Robot, q: np.ndarray, twist: np.ndarray | None, acceleration: np.ndarray | None,
              task: TaskSpace) -> tuple[np.ndarray | None, np.ndarray | None]:
    """q̇ = J⁻¹ v and q̈ = J⁻¹ (a − J̇ q̇) at one sample (n,) each, by the exact inverse however near a
    singularity (the twist of a path that stays on a branch has no component the branch cannot make); None
    where not given or not finite."""
    if twist is None:
        return None, None
    rates = joint_rates(robot, q[None], twist[None], None if acceleration is None else acceleration[None], task,
                        tolerance=0.0)
    qd, qdd = rates.velocities[0], rates.accelerations[0]
    return (qd if np.isfinite(qd).all() else None), (qdd if np.isfinite(qdd).all() else None)


def _prediction(history: list[_Reached], time: float, weights: np.ndarray) -> tuple[np.ndarray, float | None]:
    """The joints (n,) expected at ``time`` on the branch the last reached samples ``history`` (oldest first, the
    continuous stretch only) are on, and the size of a joint step there (Euclidean, prismatic joints in units of
    the robot's size; None when nothing tells it).

    With rates at the last sample, its Taylor step ``q̇ dt + ½ q̈ dt²`` (q̈ from its acceleration, or from the
    change of q̇ since the sample before); without, the polynomial through the last (up to three) samples.
    Either is off the branch by O(dt³) (O(dt²) with only q̇ or two samples), while a neighbouring branch that
    meets this one at a fold is O(dt) away."""
    last = history[-1]
    dt = time - last.time
    step = None
    if last.qd is not None and (np.abs(last.qd * dt) * weights).max(initial=0.0) <= 0.5 * np.pi:
        step = last.qd * dt
        qdd = last.qdd
        if qdd is None and len(history) > 1 and history[-2].qd is not None:
            qdd = (last.qd - history[-2].qd) / (last.time - history[-2].time)
        if qdd is not None and (np.abs(0.5 * qdd * dt * dt) * weights).max(initial=0.0) <= 0.5 * np.pi:
            step = step + 0.5 * qdd * dt * dt
    if step is None and len(history) > 1:
        # Lagrange extrapolation through the last samples
        points = history[-3:]
        predicted = np.zeros_like(last.q)
        for i, a in enumerate(points):
            weight = 1.0
            for j, b in enumerate(points):
                if j != i:
                    weight *= (time - b.time) / (a.time - b.time)
            predicted = predicted + weight * a.q
        step = predicted - last.q
    if step is None:
        return last.q, None
    scale = float(np.linalg.norm(step * weights))
    if len(history) > 1:
        scale = max(scale, float(np.linalg.norm((last.q - history[-2].q) * weights)))
    return last.q + step, scale


def _newton(robot: Robot, target: np.ndarray, constrain_orientation: bool, q: np.ndarray, moving: np.ndarray,
            steps: int, budget) -> tuple[np.ndarray, float]:
    """Newton steps (the core's damped Gauss–Newton) from q (n,) onto one pose (4, 4), the joints ``moving``
    (n,) bool only, until a step no longer halves the error; the joints and their error (normalised, ‖e‖∞),
    or q itself when the steps did not lower it."""
    goal = PoseGoal(target[None], constrain_orientation)
    rows = np.zeros(1, dtype=int)
    start = float(np.abs(goal.error(robot, q[None], rows)).max())
    reached = gauss_newton(robot, goal, q[None], rows, steps=steps, tolerance=0.0, contraction=0.5, moving=moving,
                           budget=budget, stage="the trajectory")
    error = float(reached.error[0])
    return (reached.joints[0], error) if np.isfinite(error) and error <= start else (q, start)


def _distance(robot: Robot, q: np.ndarray, reference: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Wrap-aware Euclidean distance in joint space of each row of q (..., n) from ``reference`` (n,), prismatic
    joints in units of the robot's size: unlike the largest single move, it tells apart two solutions that share
    the joint that moves most (a wrist flip beside its twin)."""
    return distance_to_reference(robot, q, reference, norm="l2", weights=weights)


def _labels_of(label_codes, q: np.ndarray) -> dict:
    """The IK's branch labels of one joint vector (n,) (a label whose branches meet there is left out)."""
    if label_codes is None:
        return {}
    return {name: values[int(codes[0])] for name, (values, codes) in label_codes(q[None]).items() if codes[0] >= 0}


def _follow(robot: Robot, times: np.ndarray, targets: np.ndarray, results: list[IKResult], held: dict,
            reference: np.ndarray | None, limits: Limits, constrain_orientation: bool,
            ik_options: IKOptions, tracking: Tracking | None = None,
            collisions: CollisionRequest | None = None) -> list[SampleResult]:
    """Choose one solution per sample (the branch rules of the module docstring).

    Each sample after the first takes the solution nearest to the previous sample's joints carried forward
    (:func:`_prediction`): the continuous branch, whatever its labels. With ``tracking`` the prediction is also
    carried onto the pose by Newton steps, which adds the branch's solution where the IK's answer lacks it, and
    the chosen solution is polished by Newton steps to the end of its digits (near a singularity a closed form
    or a search stops at a residual that leaves the joints off by residual / σmin). A sample whose solution is
    not clearly the continuation (another solution about as near the prediction, or none within a few joint
    steps of it) reports ``branch_changed``, as one whose labels differ from the previous sample's does.
    ``collisions`` with its filter keeps the path on collision-free solutions (:mod:`._trajectory_collisions`).
    """
    weights = np.where(robot.is_revolute, 1.0, 1.0 / robot.characteristic_length)
    moving = np.ones(robot.dof, dtype=bool)
    if tracking is not None:
        moving = np.zeros(robot.dof, dtype=bool)
        moving[tracking.task.columns] = True
    floor = DUPLICATE_TOLERANCE
    history: list[_Reached] = []  # the continuous stretch of reached samples that the next one continues
    to_polish: list[tuple[int, int, list[np.ndarray], np.ndarray]] = []
    listed_rates = _listed_rates(robot, results, tracking)
    previous_branch: dict | None = None
    samples: list[SampleResult] = []
    for k, result in enumerate(results):
        if k % 64 == 0:
            ik_options.budget.check("the trajectory")
        previous = history[-1] if history else None
        predicted, scale = (reference, None) if previous is None else _prediction(history, float(times[k]),
                                                                                  weights)
        rates_of = None if listed_rates is None else listed_rates[k]
        if previous is not None and _has_free_joint(result):
            # the joint the pose leaves free keeps the previous sample's value
            result = solve_ik(robot, targets[k], constrain_orientation=constrain_orientation, reference=previous.q,
                              options=ik_options)
            rates_of = None
        joints = np.array([s.joints for s in result.solutions], dtype=float).reshape(-1, robot.dof)
        branches = [dict(s.branch) for s in result.solutions]
        ambiguous = ambiguous_labels(result.singularities)
        to_prediction = None if predicted is None else _distance(robot, joints, predicted, weights)
        tracked = None
        if tracking is not None and previous is not None and not _has_free_joint(result) and _unclear(
                to_prediction[_matching(branches, held, ambiguous)] if held else to_prediction, scale):
            q_tracked, error = _newton(robot, targets[k], constrain_orientation, predicted, moving,
                                       TRACK_NEWTON_STEPS, ik_options.budget)
            if error <= ACCEPT_RESIDUAL:
                tracked = q_tracked
                if _distance(robot, joints, tracked, weights).min(initial=np.inf) > SAME_SOLUTION:
                    # the branch's solution, which the IK's answer lacks (a search near a singularity can miss it)
                    joints = np.vstack([joints, tracked])
                    branches.append(_labels_of(tracking.label_codes, tracked))
                    to_prediction = np.append(to_prediction, _distance(robot, tracked, predicted, weights))
        if not len(joints):
            # unreachable only where the solver proves it; a search that found nothing says not_found
            samples.append(SampleResult(float(times[k]), "unreachable" if result.complete else "not_found"))
            continue
        matching = _matching(branches, held, ambiguous)
        allowed = matching or list(range(len(joints)))
        collision = collision_free_pool(robot, collisions, joints, allowed)
        pool = collision.pool
        forced = previous is not None and forced_by_collision(collision, allowed, to_prediction)
        distances = None
        choice = pool[0]
        if predicted is not None:
            distances = to_prediction[pool]
            choice = pool[int(np.argmin(distances))]
        q = joints[choice]
        if previous is not None:
            q = _continued(robot, limits, q, previous.q)
        elif reference is not None:
            q = _continued(robot, limits, q, reference)
        elif not within(robot, limits, q):
            fitting = nearest_fitting_equivalent(robot, limits, q)
            q = q if fitting is None else fitting
        if tracking is not None:
            # a joint the IK set free at this sample keeps its value: the polish moves only the determined ones
            polished = moving.copy()
            polished[[x.joints[0] for x in result.singularities if x.relation in _FREE_RELATIONS and x.joints]] = False
            starts = [q]
            if tracked is not None and _distance(robot, tracked, q, weights) <= SAME_SOLUTION:
                # the same solution carried along the path: near a fold it may be the more accurate of the two
                starts.append(_continued(robot, limits, tracked, q))
            to_polish.append((len(samples), k, starts, polished))
        branch = dict(branches[choice])
        # Where two branches meet, IK leaves their label out (or the singularity makes it ambiguous): the
        # trajectory carries the held label, or the previous sample's, through that sample.
        undefined = (ambiguous & branch.keys()) | ({*held, *(previous_branch or {})} - branch.keys())
        for key in undefined:
            if key in held:
                branch[key] = held[key]
            elif previous_branch is not None and key in previous_branch:
                branch[key] = previous_branch[key]
        left_branch = jumped = False
        if previous is not None and distances is not None:
            nearest = float(distances.min())
            apart = _distance(robot, joints[pool], joints[choice], weights) > SAME_SOLUTION
            others = distances[apart].tolist()
            # another solution about as near the prediction: which one continues the branch is not known
            unsure = any(d <= AMBIGUITY_FACTOR * nearest and d > SAME_SOLUTION for d in others)
            # no solution within a few joint steps of the prediction: the branch does not continue here (unless
            # the held labels chose the jump, which the summary's largest step shows)
            jumped = scale is not None and nearest > max(JUMP_FACTOR * scale, floor)
            left_branch = (jumped and not (held and matching)) or (unsure and not jumped)
        status = ("branch_unavailable" if held and not matching
                  else "no_collision_free_solution" if collision.blocked else "ok")
        samples.append(SampleResult(
            float(times[k]), status, q, branch=branch,
            branch_changed=previous is not None and (branch != previous_branch or left_branch or forced),
            singularities=list(result.singularities), collision_forced=forced))
        rates = (None, None)
        if rates_of is not None and choice < len(rates_of[0]):  # a listed solution: rates known (2π-invariant)
            rates = (rates_of[0][choice], rates_of[1][choice])
        elif tracking is not None and tracking.twists is not None and not np.isnan(tracking.twists[k]).all():
            rates = _rates_at(robot, q, tracking.twists[k], None if tracking.accelerations is None or np.isnan(
                tracking.accelerations[k]).all() else tracking.accelerations[k], tracking.task)
        if left_branch or jumped or forced:  # a jump is no base for extrapolating the next step
            history = []
        history = [*history[-2:], _Reached(q, float(times[k]), *rates)]
        previous_branch = branch
    if to_polish:
        _polish(robot, targets, samples, to_polish, constrain_orientation, ik_options)
    return samples


def _matching(branches: list[dict], held: dict, ambiguous: set[str]) -> list[int]:
    """Which solutions' labels agree with the held ones: a label the solution does not carry (its branches meet
    there) or that the sample's singularity makes ambiguous does not rule it out."""
    return [i for i, branch in enumerate(branches)
            if all(branch.get(key, value) == value or key in ambiguous for key, value in held.items())]


def _listed_rates(robot: Robot, results: list[IKResult], tracking: Tracking | None
                  ) -> list[tuple[list, list]] | None:
    """Per sample, the joint rates (q̇ and q̈, each (n,) or None) at each of the IK's solutions, from the sample's
    twist and acceleration by the exact inverse (:func:`_rates_at`), all samples in one vectorised call; None
    without twists."""
    if tracking is None or tracking.twists is None:
        return None
    rows = [(k, s.joints) for k, result in enumerate(results) for s in result.solutions]
    if not rows:
        return [([], [])] * len(results)
    index = np.array([k for k, _ in rows])
    q = np.array([joints for _, joints in rows], dtype=float)
    task, twists = tracking.task, tracking.twists[index]
    if tracking.accelerations is not None and not np.isnan(tracking.accelerations).all():
        rates = joint_rates(robot, q, twists, tracking.accelerations[index], task, tolerance=0.0)
        velocities, accelerations = rates.velocities, rates.accelerations
    else:  # q̇ alone: one linear solve per solution (the exact inverse of the scaled task Jacobian)
        size = robot.characteristic_length  # the scaling of _rates: linear rows over the size, slides times it
        row_scale = np.array([1.0 / size] * 3 + [1.0] * 3)
        column_scale = np.where(robot.is_revolute, 1.0, size)
        Js = task_jacobian(robot, geometric_jacobian(robot, q), task)  # (M, m, k)
        b = np.nan_to_num(row_scale * twists) @ task.basis.T  # (M, m)
        with np.errstate(all="ignore"):
            if task.solve == "exact":
                try:
                    y = np.linalg.solve(Js, b[..., None])[..., 0]
                except np.linalg.LinAlgError:  # an exactly singular one: the pseudo-inverse for all
                    y = np.einsum("nkm,nm->nk", np.linalg.pinv(Js), b)
            else:
                y = np.einsum("nkm,nm->nk", np.linalg.pinv(Js), b)
        velocities = np.zeros((len(q), robot.dof))
        velocities[:, task.columns] = y * column_scale[task.columns]
        missing = (np.isnan(twists).astype(float) @ (task.basis != 0).T.astype(float)).any(axis=1)
        velocities[missing] = np.nan
        accelerations = np.full_like(velocities, np.nan)
    qd_ok = np.isfinite(velocities).all(axis=1)
    qdd_ok = np.isfinite(accelerations).all(axis=1)
    out: list[tuple[list, list]] = [([], []) for _ in results]
    for row, k in enumerate(index.tolist()):
        out[k][0].append(velocities[row] if qd_ok[row] else None)
        out[k][1].append(accelerations[row] if qdd_ok[row] else None)
    return out


def _unclear(distances: np.ndarray, scale: float | None) -> bool:
    """Whether the IK's solutions leave the continuation open, from their distances (m,) to the prediction:
    none, none within half a joint step (the prediction is off the branch by O(dt²) at most), or a second one
    about as near. Then the prediction is carried onto the pose."""
    if not len(distances):
        return True
    distances = np.sort(distances)
    if scale is None or distances[0] > max(TRACK_FACTOR * scale, DUPLICATE_TOLERANCE):
        return True
    return len(distances) > 1 and distances[1] <= AMBIGUITY_FACTOR * distances[0] + SAME_SOLUTION


def _polish(robot: Robot, targets: np.ndarray, samples: list[SampleResult],
            to_polish: list[tuple[int, int, list[np.ndarray], np.ndarray]], constrain_orientation: bool,
            ik_options: IKOptions) -> None:
    """Newton steps on the chosen joints of samples (sample index, target index, starts (n,) each, joints that
    move (n,) bool), all at once per set of moving joints, each sample keeping the start that ends with the
    smallest error (a start's own joints where no step lowers it). Fills ``samples[index].joints``."""
    groups: dict[bytes, list[tuple[int, int, np.ndarray]]] = {}
    for index, k, starts, moving in to_polish:
        for start in starts:
            groups.setdefault(moving.tobytes(), []).append((index, k, start))
    best: dict[int, tuple[float, np.ndarray]] = {}
    for key, rows in groups.items():
        moving = np.frombuffer(key, dtype=bool)
        q = np.array([start for _, _, start in rows])
        goal = PoseGoal(targets[[k for _, k, _ in rows]], constrain_orientation)
        number = np.arange(len(rows))
        before = np.abs(goal.error(robot, q, number)).max(axis=1)
        reached = gauss_newton(robot, goal, q, number, steps=POLISH_NEWTON_STEPS, tolerance=POLISHED, contraction=0.5,
                               moving=moving, budget=ik_options.budget, stage="the trajectory")
        improved = np.isfinite(reached.error) & (reached.error <= before)
        for row, (index, _, start) in enumerate(rows):
            error, joints = (reached.error[row], reached.joints[row]) if improved[row] else (before[row], start)
            if index not in best or error < best[index][0]:
                best[index] = (float(error), joints)
    for index, (_, joints) in best.items():
        samples[index].joints = joints


def _continued(robot: Robot, limits: Limits, q: np.ndarray, previous: np.ndarray) -> np.ndarray:
    """q with each revolute joint moved by whole turns to the value nearest to ``previous``.

    A joint half a turn away has two nearest values; then the one within its
    limits is taken, or else the one nearer to 0.
    """
    difference = joint_difference(robot, q, previous)
    near = previous + difference
    half_turn = robot.is_revolute & (np.abs(np.abs(difference) - np.pi) <= 1e-9)
    if half_turn.any():
        other = near - 2.0 * np.pi * np.sign(difference)
        tolerance = limits.tolerance(robot)
        inside = (near >= limits.lower - tolerance) & (near <= limits.upper + tolerance)
        other_inside = (other >= limits.lower - tolerance) & (other <= limits.upper + tolerance)
        prefer_other = (other_inside & ~inside) | ((other_inside == inside) & (np.abs(other) < np.abs(near)))
        near = np.where(half_turn & prefer_other, other, near)
    return near


def _rates_of(robot: Robot, samples: list[SampleResult], reached: np.ndarray, targets: np.ndarray,
              twist: np.ndarray | None, acceleration: np.ndarray | None, task: TaskSpace,
              assur: AssurScara | None, options: TrajectoryOptions) -> None:
    """Rates of every reached sample at once; fills the samples in place."""
    q = np.array([samples[k].joints for k in reached])
    tw = None if twist is None else twist[reached]
    acc = None if acceleration is None else acceleration[reached]
    group = None
    if assur is not None:
        group = _assur_group(robot, assur, q, np.array([samples[k].branch.get("assembly_mode", 1) for k in reached]),
                             targets[reached], tw, acc)
        q = group["joints"]
    rates = joint_rates(robot, q, tw, acc, task, tolerance=options.singularity_tolerance, damping=options.damping)
    velocities, accelerations = rates.velocities, rates.accelerations
    if group is not None:
        # The group's rates where it is regular and the Jacobian is not near singular; elsewhere the
        # Jacobian's (damped where singular) only when damping was asked for.
        regular = ((group["case"] == RRRCase.REGULAR) & ~rates.singular)[:, None]
        keep = options.damping is not None
        velocities = np.where(regular, group["velocities"], velocities if keep else np.nan)
        accelerations = np.where(regular, group["accelerations"], accelerations if keep else np.nan)
        no_twist = np.ones(len(q), dtype=bool) if tw is None else np.isnan(tw).all(axis=1)
        no_acceleration = np.ones(len(q), dtype=bool) if acc is None else np.isnan(acc).all(axis=1)
        velocities[no_twist] = np.nan
        accelerations[no_twist | no_acceleration] = np.nan
    velocity_residual, acceleration_residual = rate_residuals(robot, q, velocities, accelerations, tw, acc, task)
    tolerance = options.singularity_tolerance
    for row, k in enumerate(reached):
        sample = samples[k]
        sample.joints = q[row]
        sample.velocities, sample.accelerations = velocities[row], accelerations[row]
        sample.distance_to_singularity = float(rates.distance[row])
        sample.damped = bool(rates.damped[row]) and not bool(np.isnan(velocities[row]).all())
        sample.velocity_residual = _finite(velocity_residual[row])
        sample.acceleration_residual = _finite(acceleration_residual[row])
        if group is not None:
            # The group classifies its own singular cases, as in the paper.
            case = RRRCase(int(group["case"][row]))
            sample.singularities = [s for s in sample.singularities if s.kind != "assur_group"]
            if case != RRRCase.REGULAR:
                sample.singularities.append(_group_singularity(assur, case, float(group["reach"][row])))
            theta, thetad, thetadd = assur.paper_from_joints(q[row], velocities[row], accelerations[row])
            sample.paper = PaperJoints(theta, thetad, thetadd, case.name.lower())
        if rates.singular[row]:
            sample.singularities.append(Singularity(
                "jacobian", tuple(int(c) for c in task.columns), "near_singular",
                f"the smallest singular value of the scaled task Jacobian, {rates.distance[row]:.3g}, is below "
                f"{tolerance:g}: joint rates " + ("are damped least squares" if options.damping is not None
                                                  else "are not returned (ask for damping to get them)")))


def _assur_group(robot: Robot, assur: AssurScara, q: np.ndarray, modes: np.ndarray, targets: np.ndarray,
                 twist: np.ndarray | None, acceleration: np.ndarray | None) -> dict:
    """The paper's §3 for every reached sample, both assembly modes at once, picked per sample."""
    points = targets[:, :3, 3]
    zero = np.zeros_like(points)
    velocity = zero if twist is None else np.nan_to_num(twist[:, :3])
    accel = zero if acceleration is None else np.nan_to_num(acceleration[:, :3])
    one, two = (assur.inverse(points, velocity, accel, mode) for mode in (1, 2))
    pick = (modes == 1)[:, None]
    joints = np.where(pick, one.joints, two.joints)
    case = np.where(modes == 1, one.case, two.case)
    assembled = (case == RRRCase.REGULAR) | (case == RRRCase.ALIGNED)
    # The group's θ1 is not wrapped; keep the continuity of the chosen joints (they differ by 2π at most).
    joints = np.where(assembled[:, None], q + joint_difference(robot, np.nan_to_num(joints), q), q)
    reach = np.linalg.norm(assur.to_paper_points(points)[:, :2], axis=-1)
    return {"joints": joints, "case": case, "reach": reach,
            "velocities": np.where(pick, one.velocities, two.velocities),
            "accelerations": np.where(pick, one.accelerations, two.accelerations)}


def _group_singularity(assur: AssurScara, case: RRRCase, reach: float) -> Singularity:
    """The paper's singular cases of the RRR group (``textbook.md`` §4.2 item 6, §4.3), as a report."""
    if case == RRRCase.ALIGNED:
        stretched = reach > 0.5 * (assur.l_AB + assur.l_BC + abs(assur.l_AB - assur.l_BC))
        shape = (f"stretched, |AC| = l_AB + l_BC = {assur.l_AB + assur.l_BC:g}" if stretched
                 else f"folded, |AC| = |l_AB - l_BC| = {abs(assur.l_AB - assur.l_BC):g}")
        return Singularity("assur_group", (1,), "aligned",
                           f"the RRR group is aligned ({shape}): the two assembly modes meet, and beta', beta'' "
                           "(so the joint velocities and accelerations) do not exist")
    if case == RRRCase.COINCIDENT:
        return Singularity("assur_group", (0, 1), "coincident",
                           "the tool point is on the shoulder axis with l_AB = l_BC: the group's point C is "
                           "undefined (increased mobility), joint 1 is free and keeps the previous sample's value")
    return Singularity("assur_group", (0, 1), "unreachable", "the RRR group cannot be assembled within its tolerance")


def _finite(value: float) -> float | None:
    return None if np.isnan(value) else float(value)


def _summary(robot: Robot, samples: list[SampleResult]) -> TrajectorySummary:
    n = robot.dof
    largest = np.full(n, np.nan)
    at: list[int | None] = [None] * n
    for k in range(1, len(samples)):
        if samples[k].reached and samples[k - 1].reached:
            step = np.abs(samples[k].joints - samples[k - 1].joints)
            better = np.isnan(largest) | (step > largest)
            largest = np.where(better, step, largest)
            at = [k if b else a for a, b in zip(at, better)]
    distances = [(s.distance_to_singularity, k) for k, s in enumerate(samples)
                 if s.distance_to_singularity is not None]
    smallest = min(distances) if distances else (None, None)
    clearances = [(s.clearance.clearance, k) for k, s in enumerate(samples)
                  if s.clearance is not None and s.clearance.clearance is not None]
    closest = min(clearances) if clearances else (None, None)
    return TrajectorySummary(
        largest_joint_step=largest,
        largest_joint_step_at=at,
        smallest_distance_to_singularity=smallest[0],
        smallest_distance_at=smallest[1],
        limit_violations=[(k, v) for k, s in enumerate(samples) for v in s.violations],
        singular_samples=[k for k, s in enumerate(samples) if s.singularities],
        branch_changes=[k for k, s in enumerate(samples) if s.branch_changed],
        unreachable_samples=[k for k, s in enumerate(samples) if not s.reached],
        colliding_samples=[k for k, s in enumerate(samples) if s.clearance is not None and s.clearance.colliding],
        collision_branch_changes=[k for k, s in enumerate(samples) if s.collision_forced],
        smallest_clearance=closest[0],
        smallest_clearance_at=closest[1],
    )
