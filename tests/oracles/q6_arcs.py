"""The arcs of q6 a UR-type arm's elbow reaches with at its wrist singularity (axis 6 along the parallel axes
2–4), found by the arm's FK alone, independently of the solver.

With the target T held, turning joint 6 from q6 to q6' moves everything before it by ``T · FK(q with q6')⁻¹``;
the elbow reaches the moved point on axis 4 when its distance from axis 2 (normal to the parallel axes) lies
between the difference and the sum of the two planar link lengths. q6' is sampled on a fine grid of [−π, π) and
the arcs are the grid's connected runs.
"""

from __future__ import annotations

import numpy as np

from service.kinematics import Robot, forward_kinematics, joint_screws

#: q6 samples on [−π, π): 0.05° apart
GRID = 7200
#: an arc shorter than this many samples, or a q6 this close to an arc's end, is not resolved by the grid
RESOLVED = 8


def _planar(v: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """The part of v (..., 3) normal to the unit ``axis`` (3,)."""
    return v - (v @ axis)[..., None] * axis


def reachable_sixth(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Which q6 of the grid (GRID,) the elbow reaches with, q1 and q5 held at q's, for the target FK(q)."""
    screws = joint_screws(robot, q)
    axis, points = screws.directions[1], screws.points
    upper = np.linalg.norm(_planar(points[2] - points[1], axis))
    fore = np.linalg.norm(_planar(points[3] - points[2], axis))
    turned = np.repeat(q[None], GRID, axis=0)
    turned[:, 5] = q6_grid()
    moved = screws.world_T_tool @ np.linalg.inv(forward_kinematics(robot, turned))  # (GRID, 4, 4)
    point_on_4 = moved[:, :3, :3] @ points[3] + moved[:, :3, 3]
    reach = np.linalg.norm(_planar(point_on_4 - points[1], axis), axis=-1)
    return (abs(upper - fore) <= reach) & (reach <= upper + fore)


def fk_miss(robot: Robot, solutions: np.ndarray, target: np.ndarray) -> np.ndarray:
    """How far each of the solutions (M, n) misses the target (4, 4) by this test's FK, (M,): the position over the
    arm's size, or the rotation matrix's largest entry, whichever is larger."""
    reached = forward_kinematics(robot, solutions)
    return np.maximum(np.abs(reached[:, :3, 3] - target[:3, 3]).max(axis=1) / robot.characteristic_length,
                      np.abs(reached[:, :3, :3] - target[:3, :3]).max(axis=(1, 2)))


def q6_grid() -> np.ndarray:
    return -np.pi + 2 * np.pi * np.arange(GRID) / GRID


def arcs_of(reachable: np.ndarray) -> list[np.ndarray]:
    """The connected runs of true samples on the circle, each as its sample indices in order."""
    if reachable.all():
        return [np.arange(GRID)]
    start = int(np.argmin(reachable))  # a false sample: no run crosses it
    order = np.roll(np.arange(GRID), -start)
    runs, current = [], []
    for index in order:
        if reachable[index]:
            current.append(index)
        elif current:
            runs.append(np.array(current))
            current = []
    if current:
        runs.append(np.array(current))
    return runs


def arc_holding(arcs: list[np.ndarray], q6: float) -> int | None:
    """The arc whose samples lie within RESOLVED samples of q6 on both sides (q6 clearly inside it), or None."""
    nearest = int(np.rint((q6 + np.pi) / (2 * np.pi) * GRID)) % GRID
    for label, arc in enumerate(arcs):
        members = set(arc.tolist())
        if all((nearest + step) % GRID in members for step in range(-RESOLVED, RESOLVED + 1)):
            return label
    return None


def resolved_wrist_configuration(robot: Robot, rng: np.random.Generator) -> tuple[np.ndarray, list[np.ndarray]]:
    """A random configuration (6,) at the singular wrist (q5 = 0, the others uniform in ±π) whose arcs of q6 the
    grid resolves (each at least 4 RESOLVED samples long, q6 clearly inside one), with those arcs: drawn again
    until one is."""
    while True:
        q = rng.uniform(-np.pi, np.pi, 6)
        q[4] = 0.0
        arcs = arcs_of(reachable_sixth(robot, q))
        if min(len(arc) for arc in arcs) >= 4 * RESOLVED and arc_holding(arcs, q[5]) is not None:
            return q, arcs
