"""Carrying the branch forward from one sample to the next: the reached samples' history, the joints it predicts
at the next time, Newton steps onto a pose, the polish of the chosen joints, whole-turn continuity, and the rates
at the IK's solutions that the prediction uses."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from .._forward import geometric_jacobian
from .._limits import Limits
from .._linear import solve_each
from .._rates import TaskSpace, joint_rates, task_jacobian
from .._robot import Robot
from ..ik import IKOptions, IKResult, distance_to_reference, joint_difference
from ..ik._gauss_newton import gauss_newton
from ..ik._goals import PoseGoal
from ..ik._types import LabelCodes
from ._records import SampleResult

#: Gauss–Newton steps that carry the predicted joints onto a sample's pose (tracking), and that polish the chosen
#: solution to the end of its digits; both stop once a step no longer halves the error.
TRACK_NEWTON_STEPS = 8
POLISH_NEWTON_STEPS = 4
#: The polish leaves joints whose error (normalised, ‖e‖∞) is already at the rounding of the pose (a few ulps).
POLISHED = 4.0 * float(np.finfo(float).eps)


@dataclass(frozen=True)
class Tracking:
    """What the branch following needs besides the IK answers: the twists and accelerations (N, 6) (NaN rows:
    none), the task rows the rates are solved on (its ``columns`` are the joints that move), and the labels of a
    joint vector (M, n) as the IK names them (None: no labels). Without it (``_follow(..., tracking=None)``) the choice is from
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
                y = solve_each(Js, b[..., None])[..., 0]
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
        bounds = limits.widened(robot)
        inside = (near >= bounds.lower) & (near <= bounds.upper)
        other_inside = (other >= bounds.lower) & (other <= bounds.upper)
        prefer_other = (other_inside & ~inside) | ((other_inside == inside) & (np.abs(other) < np.abs(near)))
        near = np.where(half_turn & prefer_other, other, near)
    return near
