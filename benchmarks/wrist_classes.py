"""The spherical-wrist closed forms against EAIK on the classes it covers: the same poses, solutions and recall.

    python -m benchmarks.wrist_classes            # the full run
    python -m benchmarks.wrist_classes --quick    # tiny sizes: a smoke run

One arm per class the service solves in closed form since issue 10 (a published KUKA table for the offset
shoulder with parallel elbow, seeded random DH tables for the others), each a plain standard DH table without
base or tool so that EAIK's ``DhRobot`` takes it too. Rows: single-pose IK (one call per pose) and batch IK
(one call for N poses), timed as in :mod:`benchmarks.core` (interleaved repeats, best kept), with solutions per
pose and recall beside each time.

EAIK 1.2.2 flags every root of its general spherical-wrist family (``6R-SPHERICAL_NO_PARALLEL_NO_INTERSECTING``)
as least-squares (``is_LS``), exact or not. Its answers are therefore counted twice, from the same timed calls:
as its API states them (roots with ``is_LS`` false) and as they are (roots its arm reaches to 1e-9 by the
core's FK, checked outside the timing).
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from service.kinematics import Joint, Robot, forward_kinematics
from service.kinematics.ik import solve_ik
from service.kinematics.ik import cached_plan, solve_ik_arrays

from . import anchors
from .core import (Report, Row, best_of, format_report, machine, parse_timing_arguments, recall,
                   report_noting_missing_anchors, sample_configurations, timing_arguments)

DEG = np.pi / 180


def _robot(rows) -> Robot:
    return Robot([Joint(f"q{i + 1}", "revolute", a, alpha, d, theta) for i, (a, alpha, d, theta) in enumerate(rows)])


def kuka_kr6_r900_2() -> Robot:
    """KUKA KR 6 R900-2 from ROS-Industrial's OPW parameters (kuka_experimental, opw_parameters_kr6r900_2.yaml):
    a1 0.025, a2 −0.025, b 0, c1 0.400, c2 0.455, c3 0.420, c4 0.090 (tests/data/opw_arms.json)."""
    return _robot([(0.025, -90 * DEG, 0.400, 0), (0.455, 0, 0, -90 * DEG), (0.025, -90 * DEG, 0, 0),
                   (0, 90 * DEG, 0.420, 0), (0, -90 * DEG, 0, 0), (0, 0, 0.090, 0)])


def _random(kind: str, seed: int) -> Robot:
    rng = np.random.default_rng(seed)

    def free():
        return (rng.uniform(0.1, 0.5), rng.uniform(0.3, 2.8) * rng.choice([-1, 1]), rng.uniform(0.1, 0.5),
                rng.uniform(-np.pi, np.pi))

    twist = rng.uniform(0.3, 2.8)
    wrist = [(0.0, twist, rng.uniform(0.1, 0.5), 0.0), (0.0, -twist, 0.0, 0.0), free()]
    if kind == "intersecting_elbow":
        return _robot([free(), (0.0, rng.uniform(0.3, 2.8), rng.uniform(0.1, 0.5), 0.0), free()] + wrist)
    if kind == "skew":
        return _robot([free(), free(), free()] + wrist)
    # the wrist at the base, then three skew axes
    return _robot([(0.0, twist, rng.uniform(0.1, 0.5), 0.0), (0.0, -twist, 0.0, 0.0), free(), free(), free(),
                   free()])


ARMS = {
    "KUKA KR 6 R900-2": kuka_kr6_r900_2,
    "random intersecting elbow": lambda: _random("intersecting_elbow", 1),
    "random skew axes": lambda: _random("skew", 2),
    "random wrist at the base": lambda: _random("base", 3),
}


def _verified(robot: Robot, Q: np.ndarray, T: np.ndarray) -> np.ndarray:
    """The rows of Q (m, n), in the core's joint variables, whose FK reaches T to 1e-9 (relative, and radians)."""
    if not len(Q):
        return Q
    reached = forward_kinematics(robot, Q)
    position = np.linalg.norm(reached[:, :3, 3] - T[:3, 3], axis=-1) / robot.characteristic_length
    rotation = np.linalg.norm(reached[:, :3, :3] - T[:3, :3], axis=(-2, -1))
    return Q[(position <= 1e-9) & (rotation <= 1e-9)]


def bench_arm(report: Report, label: str, robot: Robot, args: argparse.Namespace) -> None:
    q_single, q_batch = sample_configurations(robot, args.single, 1), sample_configurations(robot, args.batch, 2)
    T_single, T_batch = forward_kinematics(robot, q_single), forward_kinematics(robot, q_batch)
    single = {"core": lambda: [solve_ik(robot, T) for T in T_single]}
    batch = {"core": lambda: solve_ik_arrays(robot, T_batch)}
    bot = None
    if anchors.installed("EAIK"):
        from eaik.IK_DH import DhRobot
        bot = DhRobot(robot.alpha.copy(), robot.a.copy(), robot.d.copy())
        report.skipped.append(f"EAIK on {label}: family {bot.getKinematicFamily()}; IK_batched with its default "
                              "worker threads")
        single["EAIK"] = lambda: [bot.IK(T) for T in T_single]
        batch["EAIK"] = lambda: bot.IK_batched(T_batch)

    def core_single(out):
        return [np.array([s.joints for s in r.solutions]) for r in out]

    def core_batch(out):
        return [out.joints[i, :c] for i, c in enumerate(out.count.tolist())]

    def eaik_stated(out, Ts):
        return [np.asarray(r.Q, float).reshape(-1, robot.dof)[~np.asarray(r.is_LS, bool)] - robot.theta for r in out]

    def eaik_exact(out, Ts):
        return [_verified(robot, np.asarray(r.Q, float).reshape(-1, robot.dof) - robot.theta, T)
                for r, T in zip(out, Ts)]

    for task, tasks, truth, Ts, to_core in (("IK, single pose", single, q_single, T_single, core_single),
                                           (f"IK, batch of {args.batch:,}", batch, q_batch, T_batch, core_batch)):
        outputs = {name: run() for name, run in tasks.items()}  # untimed: warm-up and the answers
        times = best_of(tasks, args.repeats)
        per_pose, found = recall(robot, truth, to_core(outputs["core"]))
        report.rows.append(Row(label, task, "core", times["core"] / len(truth), per_pose, found))
        if "EAIK" in tasks:
            for name, convert in (("EAIK (is_LS false)", eaik_stated), ("EAIK (FK-verified roots)", eaik_exact)):
                per_pose, found = recall(robot, truth, convert(outputs["EAIK"], Ts))
                report.rows.append(Row(label, task, name, times["EAIK"] / len(truth), per_pose, found))


def main(argv: list[str] | None = None) -> int:
    args = parse_timing_arguments(timing_arguments("python -m benchmarks.wrist_classes", __doc__.splitlines()[0]), argv)
    report = report_noting_missing_anchors()
    structures = []
    for label, build in ARMS.items():
        robot = build()
        structures.append(f"- {label}: {cached_plan(robot, constrain_orientation=True, reference=None).structure}")
        bench_arm(report, label, robot, args)
    print(f"machine: {machine()}")
    print(f"sizes: batch {args.batch:,}, single {args.single:,} poses, best of {args.repeats} interleaved rounds\n")
    print("classes (the core's structure for each arm):")
    print("\n".join(structures) + "\n")
    print(format_report(report))
    if report.skipped:
        print("\nnotes:")
        print("\n".join(f"- {line}" for line in report.skipped))
    return 0


if __name__ == "__main__":
    sys.exit(main())
