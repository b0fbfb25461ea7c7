"""The skew-axes-with-slide closed forms (RRP, RPR, PRR positioners), alone and with a spherical wrist.

    python -m benchmarks.slide_classes            # the full run
    python -m benchmarks.slide_classes --quick    # tiny sizes: a smoke run

One seeded random standard DH arm per class (no library anchor solves these in closed form: EAIK and IK-Geo
take revolute chains only), with the KUKA KR 6 R900-2 (offset shoulder, parallel elbow, spherical wrist) timed in
the same run as the anchor. Rows: single-pose IK (one ``solve_ik`` call per pose) and batch IK (one
``solve_ik_arrays`` call for N poses), timed as in :mod:`benchmarks.core` (interleaved repeats, best kept), with
solutions per pose and recall beside each time. 3-DOF arms get position targets, 6-DOF arms pose targets.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from service.kinematics import Joint, Robot, forward_kinematics
from service.kinematics.ik import solve_ik
from service.kinematics.ik import cached_plan, solve_ik_arrays

from .core import (Report, Row, best_of, format_report, machine, parse_timing_arguments, recall,
                   sample_configurations, timing_arguments)
from .wrist_classes import kuka_kr6_r900_2


def _random(kinds: str, seed: int, wrist: bool) -> Robot:
    """Three skew rows of the given joint kinds (slides with a 0–1 m travel), then a spherical wrist if asked."""
    rng = np.random.default_rng(seed)

    def free():
        return (rng.uniform(0.1, 0.5), rng.uniform(0.3, 2.8) * rng.choice([-1, 1]), rng.uniform(0.1, 0.5),
                rng.uniform(-np.pi, np.pi))

    rows, twist = [free(), free(), free()], rng.uniform(0.3, 2.8)
    if wrist:
        rows += [(0.0, twist, rng.uniform(0.1, 0.5), 0.0), (0.0, -twist, 0.0, 0.0), free()]
        kinds += "RRR"
    return Robot([Joint(f"q{i + 1}", "revolute", *row) if k == "R" else
                  Joint(f"q{i + 1}", "prismatic", *row, lower=0.0, upper=1.0)
                  for i, (row, k) in enumerate(zip(rows, kinds))])


def _telescoping(seed: int) -> Robot:
    """Two skew revolute joints, a spherical wrist over joints 3–5, a slide (0–1 m) as joint 6."""
    rng = np.random.default_rng(seed)

    def free():
        return (rng.uniform(0.1, 0.5), rng.uniform(0.3, 2.8) * rng.choice([-1, 1]), rng.uniform(0.1, 0.5),
                rng.uniform(-np.pi, np.pi))

    twist = rng.uniform(0.3, 2.8)
    rows = [free(), free(), (0.0, twist, rng.uniform(0.1, 0.5), 0.0), (0.0, -twist, 0.0, 0.0), free(), free()]
    return Robot([Joint(f"q{i + 1}", "revolute", *row) for i, row in enumerate(rows[:5])]
                 + [Joint("q6", "prismatic", *rows[5], lower=0.0, upper=1.0)])


ARMS = {
    "KUKA KR 6 R900-2 (anchor)": kuka_kr6_r900_2,
    **{f"random {kinds}": (lambda kinds=kinds, seed=seed: _random(kinds, seed, False))
       for seed, kinds in enumerate(("RRP", "RPR", "PRR"))},
    **{f"random {kinds} + wrist": (lambda kinds=kinds, seed=seed: _random(kinds, 10 + seed, True))
       for seed, kinds in enumerate(("RRP", "RPR", "PRR"))},
    "random RR + wrist + slide": lambda: _telescoping(20),
}


def bench_arm(report: Report, label: str, robot: Robot, args: argparse.Namespace) -> None:
    pose = robot.dof == 6
    q_single, q_batch = sample_configurations(robot, args.single, 1), sample_configurations(robot, args.batch, 2)
    T_single, T_batch = forward_kinematics(robot, q_single), forward_kinematics(robot, q_batch)
    tasks = {
        "IK, single pose": (lambda: [solve_ik(robot, T, constrain_orientation=pose) for T in T_single], q_single,
                            lambda out: [np.array([s.joints for s in r.solutions]) for r in out]),
        f"IK, batch of {args.batch:,}": (lambda: solve_ik_arrays(robot, T_batch, constrain_orientation=pose),
                                         q_batch, lambda out: [out.joints[i, :c] for i, c in
                                                               enumerate(out.count.tolist())]),
    }
    for task, (run, truth, solutions) in tasks.items():
        output = run()  # untimed: warm-up and the answers
        seconds = best_of({"core": run}, args.repeats)["core"]
        per_pose, found = recall(robot, truth, solutions(output))
        report.rows.append(Row(label, task, "core", seconds / len(truth), per_pose, found))


def main(argv: list[str] | None = None) -> int:
    args = parse_timing_arguments(timing_arguments("python -m benchmarks.slide_classes", __doc__.splitlines()[0]), argv)
    report, structures = Report(), []
    for label, build in ARMS.items():
        robot = build()
        plan = cached_plan(robot, constrain_orientation=robot.dof == 6, reference=None)
        structures.append(f"- {label}: {plan.structure}")
        bench_arm(report, label, robot, args)
    print(f"machine: {machine()}")
    print(f"sizes: batch {args.batch:,}, single {args.single:,} poses, best of {args.repeats} interleaved rounds\n")
    print("classes (the core's structure for each arm):")
    print("\n".join(structures) + "\n")
    print(format_report(report))
    return 0


if __name__ == "__main__":
    sys.exit(main())
