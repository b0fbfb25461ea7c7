"""The answer's assembly once the branch is chosen: the rates of every reached sample at once (the Jacobian's,
or the paper's Assur group for its SCARA), the group's singular cases, and the summary over the trajectory."""

from __future__ import annotations

import numpy as np

from .._assur import RRRCase
from .._assur_arm import AssurScara
from .._rates import TaskSpace, joint_rates, rate_residuals
from .._robot import Robot
from ..ik import Singularity, joint_difference
from ._records import PaperJoints, SampleResult, TrajectoryOptions, TrajectorySummary


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
