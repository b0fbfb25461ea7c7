"""How many IK solutions per pose the published joint limits keep (prints figures; not a test).

For each robot, seeded random joint vectors uniform within the robot's published limits go through forward
kinematics; inverse kinematics then returns every solution, and the robot's limits are applied as the service
applies them (filtering, and expansion of joints whose range spans more than 2π). The figures are solutions per
pose after the limits (mean, min, max), next to the mathematical count without limits.

    python benchmarks/limits_counts.py [--poses 1000] [--seed 0]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from service.robots.catalogue import load_catalogue  # noqa: E402
from service.kinematics import Limits, forward_kinematics  # noqa: E402
from service.kinematics.ik import AnswerOptions, IKTargets, answer_ik, solve_ik_batch  # noqa: E402

ROBOTS = {
    "puma560_standard": "PUMA 560, standard DH (Corke's frames)",
    "puma560_modified": "PUMA 560, Craig's modified DH",
    "ur5": "UR5, ±360° on every joint",
    "spong_ex3_5_stanford": "Stanford arm (slide 0.3048–1.27 m)",
}


def counts(robot, poses: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Per pose: solutions kept, distinct IK branches kept, solutions without limits; and truncated poses."""
    rng = np.random.default_rng(seed)
    q = rng.uniform(robot.lower, robot.upper, (poses, robot.dof))
    targets = np.array([forward_kinematics(robot, row) for row in q])
    results = solve_ik_batch(robot, targets)
    answer = answer_ik(robot, IKTargets.poses(targets), AnswerOptions(limits=Limits.of(robot), max_equivalents=100_000))
    kept = answer.solutions.counts(poses).tolist()
    raw = [len(result.solutions) for result in results]
    branches = (np.array(raw) - answer.rejected.counts(poses)).tolist()
    truncated = int(answer.truncated.sum())
    return np.array(kept), np.array(branches), np.array(raw), truncated


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=1000)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    catalogue = load_catalogue([ROOT / "robots"], max_joints=32)
    print(f"{args.poses} poses per robot from joint vectors uniform within the published limits (seed {args.seed})")
    print("kept: solutions per pose within the limits, 2π-equivalents counted separately; branches: how many of "
          "the distinct\nsolutions without limits have at least one equivalent within the limits")
    print(f"{'robot':<22} {'kept: mean':>10} {'min':>4} {'max':>4}   {'branches: mean':>14} {'min':>4} {'max':>4}"
          f"   {'no limits: mean':>15} {'min':>4} {'max':>4}")
    for robot_id, description in ROBOTS.items():
        robot = catalogue.get(robot_id).robot
        assert np.isfinite(robot.lower).all() and np.isfinite(robot.upper).all(), robot_id
        kept, branches, raw, truncated = counts(robot, args.poses, args.seed)
        assert branches.min() >= 1, "the generating vector is within the limits, so at least one branch is kept"
        assert truncated == 0
        print(f"{robot_id:<22} {kept.mean():>10.2f} {kept.min():>4} {kept.max():>4}   {branches.mean():>14.2f} "
              f"{branches.min():>4} {branches.max():>4}   {raw.mean():>15.2f} {raw.min():>4} {raw.max():>4}"
              f"   {description}")


if __name__ == "__main__":
    main()
