"""The general 6R solver against ik-geo's ``gen_six_dof`` and roboticstoolbox's ``analytic_ik``, same arms, same poses.

    python -m benchmarks.general_6r            # the full run
    python -m benchmarks.general_6r --quick    # tiny sizes: a smoke run

Arms: a seeded random 6R arm with no special geometry (standard DH, no base or tool, so that every library takes
the same table), and Manocha and Canny's 16-solution arm (IEEE Trans. Robot. Autom. 1994, Table I). Joint
vectors are drawn uniformly in ±π; their poses come from the core's FK and go to every library.

Per library and arm: solutions per pose (only those whose FK residual is within 1e-9 of the robot's size and
1e-9 rad, checked here with the core's FK for every library alike), recall (the fraction of poses whose
generating vector is among those, modulo 2π, to 1e-6 rad), and the median and 99th percentile of one call per
pose; for the core also one batched call for all poses (``solve_ik_arrays``), per pose. Repeats are interleaved
and the best repeat kept, so that the load of a shared machine falls on all alike; compare ratios of one run.
roboticstoolbox derives its equations with SymPy once per arm before solving (minutes for a general arm): it
runs in a child process with a time limit, and the derivation time is reported, not counted per pose.
"""

from __future__ import annotations

import argparse
import importlib.util
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Callable

import numpy as np

from service.kinematics import Joint, Robot, forward_kinematics
from service.kinematics._forward import screw_model
from service.kinematics.ik import solve_ik
from service.kinematics.ik import solve_ik_arrays
from service.kinematics.ik import joint_difference
from service.kinematics.ik._verify import residuals

RECALL_TOLERANCE = 1e-6
ACCEPT = 1e-9


def random_general_arm(seed: int) -> Robot:
    rng = np.random.default_rng(seed)
    return Robot([Joint(f"q{i + 1}", "revolute", *rng.uniform(-1, 1, 4)) for i in range(6)],
                 convention="standard", name=f"random general 6R (seed {seed})")


def manocha_canny_arm() -> Robot:
    a, d, alpha = [0.3, 1.0, 0.0, 1.5, 0.0, 0.0], [0.0, 0.0, 0.2, 0.0, 0.0, 0.0], [90, 1, 90, 1, 90, 1]
    return Robot([Joint(f"q{i + 1}", "revolute", a[i], np.radians(alpha[i]), d[i], 0.0) for i in range(6)],
                 convention="standard", name="Manocha-Canny 16-solution arm")


def core_single(robot: Robot) -> Callable[[np.ndarray], np.ndarray]:
    return lambda T: np.array([s.joints for s in solve_ik(robot, T).solutions]).reshape(-1, 6)


def ik_geo_single(robot: Robot) -> Callable[[np.ndarray], np.ndarray] | str:
    """ik-geo's general 6R solver from the screw model; its rotations are read and written transposed."""
    if importlib.util.find_spec("ik_geo") is None:
        return "not installed (pip install ik-geo)"
    from ik_geo import Robot as GeoRobot

    model = screw_model(robot)
    points = np.vstack([np.zeros(3), model.points, model.home[:3, 3]])
    bot = GeoRobot.gen_six_dof(model.directions.tolist(), np.diff(points, axis=0).tolist())
    home_R = model.home[:3, :3]

    def solve(T: np.ndarray) -> np.ndarray:
        found = bot.get_ik((T[:3, :3] @ home_R.T).T.tolist(), T[:3, 3].tolist())
        return np.array([q for q, _least_squares in found], dtype=float).reshape(-1, 6)

    return solve


def roboticstoolbox_worker(path: str) -> int:
    """In a child process: derive roboticstoolbox's analytic IK for the arm in ``path`` (an .npz with the DH table,
    poses and repeats), solve every pose, and write the answers and times back into ``path`` + '.out.npz'."""
    from roboticstoolbox import DHRobot, RevoluteDH

    data = np.load(path)
    bot = DHRobot([RevoluteDH(a=a, alpha=al, d=d, offset=th) for a, al, d, th in data["dh"]])
    start = time.perf_counter()
    solver = bot.analytic_ik()
    derivation = time.perf_counter() - start
    targets = data["targets"]
    answers, best = [], None
    for T in targets:
        answers.append(np.asarray(solver.solve(T, joint_limits=False).q, dtype=float).reshape(-1, 6))
    for _ in range(int(data["repeats"])):
        times = np.empty(len(targets))
        for i, T in enumerate(targets):
            begin = time.perf_counter()
            solver.solve(T, joint_limits=False)
            times[i] = time.perf_counter() - begin
        best = times if best is None or np.median(times) < np.median(best) else best
    counts = np.array([len(a) for a in answers])
    np.savez(path + ".out.npz", derivation=derivation, times=best, counts=counts,
             solutions=np.concatenate(answers + [np.zeros((0, 6))]))
    return 0


def roboticstoolbox_rows(robot: Robot, q: np.ndarray, targets: np.ndarray, repeats: int, timeout: float,
                         notes: list[str]) -> dict | None:
    """roboticstoolbox's ``analytic_ik`` run in a child process (its SymPy derivation can take minutes for a
    general arm, so it gets ``timeout`` seconds in all); None, with a note, when it cannot answer."""
    if importlib.util.find_spec("roboticstoolbox") is None or importlib.util.find_spec("sympy") is None:
        notes.append("roboticstoolbox analytic_ik: not installed (pip install 'roboticstoolbox-python[ik]')")
        return None
    with tempfile.TemporaryDirectory() as folder:
        path = str(Path(folder) / "arm.npz")
        np.savez(path, dh=np.stack([robot.a, robot.alpha, robot.d, robot.theta], axis=1), targets=targets,
                 repeats=repeats)
        try:
            subprocess.run([sys.executable, "-m", "benchmarks.general_6r", "--roboticstoolbox-worker", path],
                           check=True, timeout=timeout, capture_output=True)
        except subprocess.TimeoutExpired:
            notes.append(f"roboticstoolbox analytic_ik on {robot.name}: no answer within {timeout:.0f} s "
                         f"(SymPy derivation plus {len(targets)} poses)")
            return None
        except subprocess.CalledProcessError as error:
            reason = error.stderr.decode(errors="replace").strip().splitlines()[-1:] or ["failed"]
            notes.append(f"roboticstoolbox analytic_ik on {robot.name}: {reason[0]}")
            return None
        out = np.load(path + ".out.npz")
        derivation, times, counts, flat = out["derivation"], out["times"], out["counts"], out["solutions"]
    notes.append(f"roboticstoolbox analytic_ik derivation on {robot.name} (SymPy, once per arm, not in the "
                 f"per-pose times): {float(derivation):.1f} s")
    answers = np.split(flat, np.cumsum(counts)[:-1])
    return summary(robot, "roboticstoolbox analytic_ik", answers, q, targets, times)


def verified(robot: Robot, solutions: np.ndarray, target: np.ndarray) -> np.ndarray:
    """The solutions whose FK reproduces the target (the core's acceptance tolerance, for every library)."""
    if not len(solutions):
        return solutions
    position, orientation = residuals(robot, solutions, target)
    return solutions[(position <= ACCEPT * robot.characteristic_length) & (orientation <= ACCEPT)]


def summary(robot: Robot, name: str, answers: list[np.ndarray], q: np.ndarray, targets: np.ndarray,
            times: np.ndarray) -> dict:
    good = [verified(robot, a, T) for a, T in zip(answers, targets)]
    found = sum(bool(len(a)) and np.abs(joint_difference(robot, a, g)).max(axis=1).min() <= RECALL_TOLERANCE
                for a, g in zip(good, q))
    return {"library": name, "solutions": float(np.mean([len(a) for a in good])), "recall": found / len(q),
            "median": float(np.median(times)), "p99": float(np.percentile(times, 99)),
            "raw": float(np.mean([len(a) for a in answers]))}


def measure(robot: Robot, name: str, solve: Callable[[np.ndarray], np.ndarray], q: np.ndarray,
            targets: np.ndarray, repeats: int) -> dict:
    answers = [solve(T) for T in targets]  # warm-up, and the answers for recall
    best = None
    for _ in range(repeats):
        times = np.empty(len(targets))
        for i, T in enumerate(targets):
            start = time.perf_counter()
            solve(T)
            times[i] = time.perf_counter() - start
        best = times if best is None or np.median(times) < np.median(best) else best
    return summary(robot, name, answers, q, targets, best)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--poses", type=int, default=300, help="poses per arm for the single-pose rows")
    parser.add_argument("--batch", type=int, default=5000, help="poses in the batched core call")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--anchor-poses", type=int, default=100, help="poses given to the (slower) anchors")
    parser.add_argument("--roboticstoolbox-timeout", type=float, default=900.0,
                        help="seconds roboticstoolbox gets per arm, its SymPy derivation included")
    parser.add_argument("--no-roboticstoolbox", action="store_true", help="skip roboticstoolbox")
    parser.add_argument("--quick", action="store_true", help="tiny sizes, roboticstoolbox skipped")
    parser.add_argument("--roboticstoolbox-worker", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.roboticstoolbox_worker:
        return roboticstoolbox_worker(args.roboticstoolbox_worker)
    if args.quick:
        args.poses, args.batch, args.repeats, args.anchor_poses, args.no_roboticstoolbox = 10, 50, 1, 5, True
    print(f"# General 6R IK: core vs ik-geo gen_six_dof vs roboticstoolbox analytic_ik\n\n"
          f"python {platform.python_version()}, numpy {np.__version__}, {platform.machine()}; "
          f"{args.poses} poses per arm (anchors: {args.anchor_poses}), best of {args.repeats} repeats\n")
    print("| arm | library | solutions / pose (verified) | returned / pose | recall | median single (ms) | "
          "p99 single (ms) | batch (ms / pose) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    notes: list[str] = []
    for robot in (random_general_arm(2026), manocha_canny_arm()):
        rng = np.random.default_rng(1)
        q = rng.uniform(-np.pi, np.pi, (max(args.poses, args.batch), 6))
        targets = forward_kinematics(robot, q)
        rows = [measure(robot, "core", core_single(robot), q[:args.poses], targets[:args.poses], args.repeats)]
        start = time.perf_counter()
        solve_ik_arrays(robot, targets[:args.batch])
        rows[0]["batch"] = (time.perf_counter() - start) / args.batch
        n = args.anchor_poses
        solve = ik_geo_single(robot)
        if isinstance(solve, str):
            notes.append(f"ik-geo gen_six_dof: {solve}")
        else:
            rows.append(measure(robot, "ik-geo gen_six_dof", solve, q[:n], targets[:n], args.repeats))
        if not args.no_roboticstoolbox:
            row = roboticstoolbox_rows(robot, q[:n], targets[:n], args.repeats, args.roboticstoolbox_timeout, notes)
            if row is not None:
                rows.append(row)
        for row in rows:
            batch = f"{1e3 * row['batch']:.3f}" if "batch" in row else "—"
            print(f"| {robot.name} | {row['library']} | {row['solutions']:.2f} | {row['raw']:.2f} | "
                  f"{100 * row['recall']:.1f} % | {1e3 * row['median']:.3f} | {1e3 * row['p99']:.3f} | {batch} |")
        core = rows[0]["median"]
        for row in rows[1:]:
            notes.append(f"{robot.name}: median single-pose time {row['library']} / core = {row['median'] / core:.1f}")
    print()
    for note in notes:
        print(f"- {note}")
    print("- goal: general 6R median ≤ 1 ms per pose single (this run: see the core rows)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
