"""The entry point: the samples checked (times, twists, accelerations, held labels), the positions solved for
every sample at once, then the branch followed (:mod:`._branch`) and the answer assembled (:mod:`._answer`)."""

from __future__ import annotations

from typing import Mapping

import numpy as np

from .._assur_arm import assur_scara_of
from .._errors import InvalidInputError
from .._limits import Limits, violations
from .._rates import TaskSpace, task_space
from .._robot import Robot, check_joint_values
from ..collision import at_collisions, model_for
from ..ik import IKResult, coaxial_redundancy, plan_for, solve_ik_batch
from ._collisions import sample_clearances
from ._answer import _rates_of, _summary
from ._branch import _follow
from ._continuation import Tracking
from ._free_joints import follow_free_joints
from ._records import TrajectoryOptions, TrajectoryResult


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
