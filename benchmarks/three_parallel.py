"""The closed forms for three parallel axes anywhere in a 6R chain, against EAIK on the classes it covers.

    python -m benchmarks.three_parallel             # the full run
    python -m benchmarks.three_parallel --quick     # tiny sizes: a smoke run

One seeded random arm per class, given as a plain standard DH table (no base, tool or angle offsets, so that
every library takes the same table), after the catalogue UR5 (today's UR-type family) as the anchor. The rows
are those of :mod:`benchmarks.core`: the same poses to every library that supports the arm, solutions per pose
and recall beside the times. EAIK 1.2.2 has closed forms for
axes 2 ∥ 3 ∥ 4 (its THREE_INNER_PARALLEL, any wrist), 3 ∥ 4 ∥ 5 (reversed) and 1 ∥ 2 ∥ 3 with axes 5 and 6
meeting (THREE_PARALLEL_TWO_INTERSECTING); it says which arms it cannot solve.
"""

from __future__ import annotations

import sys

import numpy as np

from service.robots.catalogue import load_catalogue
from service.config import Settings
from service.kinematics import Robot
from service.kinematics._robot import Joint
from service.kinematics.ik import cached_plan

from .core import (bench_robot, format_report, machine, parse_timing_arguments,
                   report_noting_missing_anchors, timing_arguments)

#: class label → (0-based standard-DH twists set to 0 (parallel axes i+1, i+2), link lengths set to 0)
CLASSES = {
    "2∥3∥4, skew wrist": ((1, 2), ()),
    "3∥4∥5, skew shoulder": ((2, 3), ()),
    "3∥4∥5, axes 1, 2 meet": ((2, 3), (0,)),
    "4∥5∥6": ((3, 4), ()),
    "1∥2∥3": ((0, 1), ()),
    "1∥2∥3, axes 5, 6 meet": ((0, 1), (4,)),
}


def class_arm(label: str, seed: int = 5) -> Robot:
    parallel, meeting = CLASSES[label]
    rng = np.random.default_rng(seed)
    alpha = rng.choice([-1, 1], 6) * rng.uniform(0.3, 2.8, 6)
    a, d = rng.uniform(-0.4, 0.4, 6), rng.uniform(-0.4, 0.4, 6)
    alpha[list(parallel)] = 0.0
    a[list(meeting)] = 0.0
    return Robot([Joint(f"j{i + 1}", "revolute", a[i], alpha[i], d[i], 0.0) for i in range(6)], name=label)


def main(argv: list[str] | None = None) -> int:
    args = parse_timing_arguments(timing_arguments("python -m benchmarks.three_parallel", __doc__.splitlines()[0]), argv)
    report = report_noting_missing_anchors()
    # today's UR-type family on the catalogue UR5, as the anchor of "the speed of today's families"
    bench_robot(report, "UR5 (three_parallel)", load_catalogue([Settings().builtin_robots_dir], max_joints=32)
                .get("ur5").robot, args)
    for label in CLASSES:
        robot = class_arm(label)
        plan = cached_plan(robot, constrain_orientation=True, reference=None)
        report.skipped.append(f"core on {label}: family {plan.structure if plan else 'none (numeric)'}")
        bench_robot(report, label, robot, args)
    print(f"machine: {machine()}")
    print(f"sizes: batch {args.batch:,}, single {args.single:,} poses, best of {args.repeats} interleaved rounds\n")
    print(format_report(report))
    print("\nnotes:")
    print("\n".join(f"- {line}" for line in report.skipped))
    return 0


if __name__ == "__main__":
    sys.exit(main())
