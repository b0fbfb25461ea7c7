"""Arms with more or fewer than six joints: the free-joint family of 7-DOF arms and direction targets of 5-DOF arms.

    python -m benchmarks.redundant            # the full run (under a minute)
    python -m benchmarks.redundant --quick    # tiny sizes: a smoke run

Rows, each timed on seeded poses from the arm's own FK and reported as the median and best per request:

* a 7-DOF full pose with its free joint sampled 32 times (the issue's goal: < 20 ms of solve time), without and
  with a reference (the continuous nearest-solution search), on the iiwa 14, the Gen3 and the Panda;
* a 5-DOF position + direction target (SO-101-like arm, jaw axis and roll axis);
* position + direction targets of 6- and 7-DOF arms (PUMA 560, UR5, iiwa 14): the family over the free roll at
  its 36 default rolls, without a reference, and with the generating joint vector as the reference (recall:
  the fraction of poses where it is the first solution, the nearest over the whole family);
* the anchor: the same 7-DOF request at one value of the free joint (one locked 6-DOF solve), in the same run.

Beside each time: solutions per request and recall (the fraction of poses whose generating joint vector is among
the solutions; for the 7-DOF rows its free value is one of the 32 samples).
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from pydantic import TypeAdapter

from service.robots import robot_from_description
from service.robots.schemas import RobotDescription
from service.kinematics import forward_kinematics
from service.kinematics.ik import FreeJoint, solve_direction, solve_free_joint_family
from service.kinematics.ik._redundant import default_free_joints, sample_values

ARMS = Path(__file__).parents[1] / "tests" / "data" / "redundant_and_deficient_arms.json"


def _arm(name: str):
    description = TypeAdapter(RobotDescription).validate_python(
        {"id": name.replace("_", "-"), **json.loads(ARMS.read_text())[name]})
    return robot_from_description(description, max_joints=16)


def _timed(call, count: int) -> tuple[list[float], list]:
    times, answers = [], []
    for index in range(count):
        started = time.perf_counter()
        answers.append(call(index))
        times.append(time.perf_counter() - started)
    return times, answers


def _recovered(solutions: np.ndarray, q: np.ndarray) -> bool:
    if not len(solutions):
        return False
    gap = np.abs(np.angle(np.exp(1j * (solutions - q)))).max(axis=1)
    return bool(gap.min() < 1e-6)


def _row(arm: str, task: str, times: list[float], solutions: float, recall: float) -> str:
    return (f"| {arm} | {task} | {1000 * statistics.median(times):.2f} | {1000 * min(times):.2f} | "
            f"{solutions:.1f} | {'–' if np.isnan(recall) else f'{100 * recall:.0f} %'} |")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--poses", type=int, default=40, help="poses per row")
    parser.add_argument("--samples", type=int, default=32, help="samples of the free joint")
    parser.add_argument("--quick", action="store_true", help="tiny sizes: a smoke run")
    args = parser.parse_args(argv)
    poses = 3 if args.quick else args.poses
    rng = np.random.default_rng(2026)
    print(f"python {platform.python_version()}, numpy {np.__version__}, {platform.machine()}; {poses} poses per row")
    print()
    print("| arm | request | median ms | best ms | solutions | recall |")
    print("| --- | --- | --- | --- | --- | --- |")
    medians = {}
    for name, label in (("iiwa14", "iiwa 14"), ("gen3", "Gen3"), ("panda", "Panda")):
        robot = _arm(name)
        joint = default_free_joints(robot)[0]
        grid = sample_values(robot, joint, args.samples)
        q = np.clip(rng.uniform(-np.pi, np.pi, (poses, robot.dof)), robot.lower, robot.upper)
        q[:, joint] = grid[rng.integers(len(grid), size=poses)]
        targets = forward_kinematics(robot, q)
        free = [FreeJoint(joint, grid)]
        solve_free_joint_family(robot, targets[:1], free, None)  # warm-up: plans for the grid
        one = [FreeJoint(joint, grid[:1])]
        solve_free_joint_family(robot, targets[:1], one, None)
        times, answers = _timed(lambda i: solve_free_joint_family(robot, targets[i:i + 1], one, None), poses)
        medians[(label, None)] = statistics.median(times)
        print(_row(label, f"anchor: full pose, q{joint + 1} at one value", times,
                   float(np.mean([len(a.verified.table) for a in answers])), float("nan")))
        for with_reference in (False, True):
            references = q + rng.uniform(-0.3, 0.3, q.shape) if with_reference else [None] * poses
            times, answers = _timed(lambda i: solve_free_joint_family(robot, targets[i:i + 1], free, references[i]),
                                    poses)
            counts = [len(a.verified.table) for a in answers]
            recall = np.mean([_recovered(a.verified.table.joints, q[i])
                              for i, a in enumerate(answers)])
            task = (f"full pose, q{joint + 1} sampled {args.samples}×" +
                    (", nearest to a reference (continuous search)" if with_reference else ""))
            medians[(label, with_reference)] = statistics.median(times)
            print(_row(label, task, times, float(np.mean(counts)), float(recall)))
    robot = _arm("so101_like")
    q = rng.uniform(-np.pi, np.pi, (poses, 5))
    T = forward_kinematics(robot, q)
    for axis_name, axis in (("jaw axis y", np.array([0.0, 1.0, 0.0])), ("roll axis z", np.array([0.0, 0.0, 1.0]))):
        solve_direction(robot, T[:1, :3, 3], T[:1, :3, :3] @ axis, axis, None)
        times, answers = _timed(lambda i: solve_direction(robot, T[i:i + 1, :3, 3], T[i:i + 1, :3, :3] @ axis, axis,
                                                          None), poses)
        expected = q.copy()
        if answers[0].free_joints:
            expected[:, answers[0].free_joints] = 0.0
        recall = np.mean([_recovered(a.joints[0, :a.count[0]], expected[i]) for i, a in enumerate(answers)])
        print(_row("SO-101-like", f"position + direction, {axis_name}", times,
                   float(np.mean([a.count[0] for a in answers])), float(recall)))
    _roll_family_rows(rng, poses)
    print()
    for (label, with_reference), median in medians.items():
        if with_reference is None:
            continue
        kind = "with a reference" if with_reference else "sampled only"
        print(f"- {label}, {args.samples} samples, {kind}: {median * 1000:.2f} ms of solve time, "
              f"{median / medians[(label, None)]:.1f}x one locked 6-DOF solve (goal: < 20 ms sampled only)")
    return 0


def _roll_family_rows(rng: np.random.Generator, poses: int) -> None:
    """Rows of direction targets on 6- and 7-DOF arms: the family over the free roll (tool axis z)."""
    from service.robots.catalogue import load_catalogue

    catalogue = load_catalogue([Path(__file__).parents[1] / "robots"], max_joints=16)
    axis = np.array([0.0, 0.0, 1.0])
    for label, robot in (("PUMA 560", catalogue.get("puma560_standard").robot), ("UR5", catalogue.get("ur5").robot),
                         ("iiwa 14", _arm("iiwa14"))):
        lower = np.maximum(np.where(np.isfinite(robot.lower), robot.lower, -np.pi), -np.pi)
        upper = np.minimum(np.where(np.isfinite(robot.upper), robot.upper, np.pi), np.pi)
        q = lower + (upper - lower) * rng.uniform(0.05, 0.95, (poses, robot.dof))
        T = forward_kinematics(robot, q)
        solve_direction(robot, T[:1, :3, 3], T[:1, :3, :3] @ axis, axis, None)  # warm-up: the plans
        for with_reference in (False, True):
            def call(i: int):
                return solve_direction(robot, T[i:i + 1, :3, 3], T[i:i + 1, :3, :3] @ axis, axis,
                                       q[i] if with_reference else None)
            times, answers = _timed(call, poses)
            recall = (np.mean([_recovered(a.joints[0, :1], q[i]) for i, a in enumerate(answers)])
                      if with_reference else float("nan"))
            print(_row(label, "position + direction, 36 rolls" + (", the generating vector as reference"
                                                                   if with_reference else ""),
                       times, float(np.mean([a.count[0] for a in answers])), float(recall)))


if __name__ == "__main__":
    sys.exit(main())
