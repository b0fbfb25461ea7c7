"""The core against EAIK, ik-geo and roboticstoolbox-python, side by side in one process and one run.

    python -m benchmarks.core                # the full run (a few minutes)
    python -m benchmarks.core --quick        # tiny sizes: a smoke run

For each robot (PUMA 560, UR5, Stanford; KUKA KR6 on request) it draws seeded joint vectors, makes
their poses with the core's FK, and gives the same poses to every library that
supports the robot. Rows: single-pose IK (one call per pose), batch IK (one
call for N poses), single FK and batch FK. Beside each time: solutions per pose
and recall (the fraction of poses whose generating joint vector is among the
returned solutions, revolute joints modulo 2π). Repeats are interleaved across
libraries and the best repeat is kept, so that the load of a shared machine
falls on all of them alike; ratios are taken within the run.

The whole-answer rows (``answer_ik``: what a request pays in process) run on
the PUMA 560, the UR5 and the KUKA KR6: one pose a call, a handful of poses a
call (:data:`FEW_TARGETS_A_CALL`, a motion planner's few waypoints: EAIK at the
faster of ``IK`` per pose and ``IK_batched`` on one thread), and a batch; and
again on the UR5 and the KUKA KR6
with their parallel axes 1e-5 rad off (:func:`cad_rounded`), as CAD exports and
URDFs leave them: those arms are no longer exactly of their family, the service
refines its closed form onto them, and what a user of such a description pays
is timed beside the exact arm's.
"""

from __future__ import annotations

import argparse
import platform
import sys
import time
import tracemalloc
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Callable

import numpy as np

from service.robots.catalogue import load_catalogue
from service.config import Settings
from service.kinematics import Limits, Robot, forward_kinematics
from service.kinematics.ik import AnswerOptions, IKTargets, answer_ik, cached_plan, solve_ik, solve_ik_batch
from service.kinematics.ik import solve_ik_arrays
from service.kinematics.ik._closed_form import solve_closed_form
from service.kinematics.ik._goals import PoseGoal

from . import anchors

ROBOTS = {"PUMA 560": "puma560_standard", "UR5": "ur5", "Stanford": "spong_ex3_5_stanford",
          "KUKA KR6": "kuka_kr6_r900_2"}
DEFAULT_ROBOTS = ["PUMA 560", "UR5", "Stanford"]
#: How far :func:`cad_rounded` turns each axis parallel to the one before it (radians).
ROUNDING_TILT = 1e-5
RECALL_TOLERANCE = 1e-6  # radians (length units × robot size for prismatic joints)


@dataclass
class Row:
    robot: str
    task: str
    library: str
    seconds_per_item: float | None = None
    solutions_per_pose: float | None = None
    recall: float | None = None
    note: str = ""


@dataclass
class Report:
    rows: list[Row] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    memory: str = ""

    def find(self, robot: str, task: str, library: str) -> Row | None:
        return next((r for r in self.rows if (r.robot, r.task, r.library) == (robot, task, library)), None)


def timing_arguments(prog: str, description: str) -> argparse.ArgumentParser:
    """The options every benchmark script shares: batch and single-pose sizes, interleaved rounds, a quick mode."""
    parser = argparse.ArgumentParser(prog=prog, description=description)
    parser.add_argument("--batch", type=int, default=10_000, help="poses in a batch (default 10,000)")
    parser.add_argument("--single", type=int, default=500, help="poses timed one call at a time (default 500)")
    parser.add_argument("--repeats", type=int, default=5, help="interleaved rounds, best kept (default 5)")
    parser.add_argument("--quick", action="store_true", help="tiny sizes, for a smoke run")
    return parser


def parse_timing_arguments(parser: argparse.ArgumentParser, argv: list[str] | None) -> argparse.Namespace:
    """Parsed options; ``--quick`` shrinks the sizes to a smoke run's."""
    args = parser.parse_args(argv)
    if args.quick:
        args.batch, args.single, args.repeats = 20, 5, 1
    return args


def report_noting_missing_anchors() -> Report:
    """An empty report that names each anchor library that is not installed (it is then skipped)."""
    report = Report()
    for name in anchors.LIBRARIES:
        if not anchors.installed(name):
            report.skipped.append(f"{name}: not installed (pip install -e '.[bench]'), skipped")
    return report


def sample_configurations(robot: Robot, count: int, seed: int) -> np.ndarray:
    """Revolute joints uniform in ±π; prismatic joints uniform within their limits (or 0.1–1 robot sizes)."""
    rng = np.random.default_rng(seed)
    q = rng.uniform(-np.pi, np.pi, (count, robot.dof))
    for i in np.flatnonzero(~robot.is_revolute):
        lower, upper = robot.lower[i], robot.upper[i]
        if not (np.isfinite(lower) and np.isfinite(upper)):
            lower, upper = 0.1 * robot.characteristic_length, robot.characteristic_length
        q[:, i] = rng.uniform(lower, upper, count)
    return q


def recall(robot: Robot, truth: np.ndarray, solutions: list[np.ndarray]) -> tuple[float, float]:
    """(mean solutions per pose, fraction of poses whose generating vector is among the solutions)."""
    tolerance = np.where(robot.is_revolute, RECALL_TOLERANCE, RECALL_TOLERANCE * robot.characteristic_length)
    found = 0
    for q, sols in zip(truth, solutions):
        sols = np.asarray(sols, dtype=float).reshape(-1, robot.dof)
        if len(sols):
            gap = np.abs(sols - q)
            gap = np.where(robot.is_revolute, np.minimum(gap % (2 * np.pi), 2 * np.pi - gap % (2 * np.pi)), gap)
            found += bool(np.any(np.all(gap <= tolerance, axis=1)))
    return float(np.mean([len(np.asarray(s).reshape(-1, robot.dof)) for s in solutions])), found / len(truth)


def best_of(tasks: dict[str, Callable[[], object]], repeats: int) -> dict[str, float]:
    """Best wall time of each task over ``repeats`` rounds, the tasks interleaved within each round."""
    best = {name: float("inf") for name in tasks}
    for _ in range(repeats):
        for name, task in tasks.items():
            start = time.perf_counter()
            task()
            best[name] = min(best[name], time.perf_counter() - start)
    return best


def _core_batch_solutions(robot: Robot, Ts: np.ndarray) -> list[np.ndarray]:
    arrays = solve_ik_arrays(robot, Ts)
    return [arrays.joints[i, :c] for i, c in enumerate(arrays.count.tolist())]


def bench_robot(report: Report, label: str, robot: Robot, args: argparse.Namespace) -> None:
    q_single = sample_configurations(robot, args.single, seed=1)
    q_batch = sample_configurations(robot, args.batch, seed=2)
    T_single, T_batch = forward_kinematics(robot, q_single), forward_kinematics(robot, q_batch)

    libraries: dict[str, anchors.Anchor] = {}
    for name, build in anchors.BUILDERS.items():
        if not anchors.installed(name):
            continue
        built = build(robot)
        if isinstance(built, str):
            report.skipped.append(f"{name} on {label}: {built}")
        else:
            libraries[name] = built
            for note in built.notes:
                report.skipped.append(f"{name} on {label}: {note}")

    # --- single-pose IK: one call per pose
    single: dict[str, Callable[[], list]] = {"core": lambda: [solve_ik(robot, T) for T in T_single]}
    for name, lib in libraries.items():
        if lib.ik_single is not None:
            single[name] = (lambda f: lambda: [f(T) for T in T_single])(lib.ik_single)
    _timed_ik(report, label, "IK, single pose", robot, single, q_single, args.repeats,
              lambda name, out: [np.array([s.joints for s in r.solutions]) for r in out] if name == "core" else out)

    # --- batch IK: one call for N poses
    batch: dict[str, Callable[[], list]] = {
        "core": lambda: _core_batch_solutions(robot, T_batch),
        "core (IKResult objects)": lambda: solve_ik_batch(robot, T_batch),
    }
    for name, lib in libraries.items():
        if lib.ik_batch is not None:
            batch[name] = (lambda f: lambda: f(T_batch))(lib.ik_batch)
    _timed_ik(report, label, f"IK, batch of {args.batch:,}", robot, batch, q_batch, args.repeats,
              lambda name, out: [np.array([s.joints for s in r.solutions]) for r in out]
              if name == "core (IKResult objects)" else out)

    # --- FK
    fk_single = {"core": lambda: [forward_kinematics(robot, q) for q in q_single]}
    fk_batch = {"core": lambda: forward_kinematics(robot, q_batch)}
    for name, lib in libraries.items():
        if lib.fk_single is not None:
            fk_single[name] = (lambda f: lambda: [f(q) for q in q_single])(lib.fk_single)
        if lib.fk_batch is not None:
            fk_batch[name] = (lambda f: lambda: f(q_batch))(lib.fk_batch)
    for task, tasks, count in (("FK, single configuration", fk_single, len(q_single)),
                               (f"FK, batch of {args.batch:,}", fk_batch, len(q_batch))):
        for name, seconds in best_of(tasks, args.repeats).items():
            report.rows.append(Row(label, task, name, seconds / count))


ANSWER_ROBOTS = ["PUMA 560", "UR5", "KUKA KR6"]
#: The two limit settings of the whole-answer rows: ±π with no filter lists each configuration once, as EAIK does;
#: the catalogue's limits add what a request pays for them (2π-equivalents of ±360° joints, rejected solutions).
OPEN_LIMITS = "limits ±π, no filter"
ANSWER_LIMITS = {OPEN_LIMITS: "open", "catalogue limits": "catalogue"}
#: the arms whose whole answer is timed again as CAD exports state them (:func:`cad_rounded`)
ROUNDED_ROBOTS = ["UR5", "KUKA KR6"]
ANSWER_SINGLE_TASK, ANSWER_BATCH_TASK = "IK answer, {limits}, single pose", "IK answer, {limits}, batch of {batch:,}"
#: a motion planner's handful of waypoints in one call: the whole answer of that many targets a call, per pose
ANSWER_FEW_TASK = "IK answer, {limits}, {few} targets a call"
#: a motion planner's single pose: its solutions nearest first to the joints it holds (each pose's own, moved a
#: little); EAIK's anchor sorts its solutions by the same distance, as its user has to
ANSWER_NEAREST_TASK = "IK answer, {limits}, single pose, nearest first to a reference"
#: how far (radians, standard deviation per joint) a nearest-first row's reference is from the pose's own joints
REFERENCE_SPREAD = 0.05
FEW_TARGETS_A_CALL = 4
WHOLE_ANSWER = "core"  # the row the others are compared with: answer_ik, solve + select
SOLVE_ONLY_SINGLE = "core, solve only (solve_closed_form: solve + FK check)"
SOLVE_ONLY = "core, solve only (solve_ik_arrays)"
EAIK_THREADS = (1, 2, 4)


def cad_rounded(robot: Robot) -> Robot:
    """``robot`` (a DH table) with each twist of 0 or π moved by :data:`ROUNDING_TILT`, alternately up and down:
    the axes that were parallel are 1e-5 rad off, as a CAD export or a URDF written to a few decimals leaves them,
    and every other value as it stands."""
    joints, sign = [], 1.0
    for joint in robot.joints:
        alpha = joint.alpha
        if abs(np.sin(alpha)) < 1e-9:
            alpha, sign = alpha + sign * ROUNDING_TILT, -sign
        joints.append(replace(joint, alpha=alpha))
    return Robot(joints, name=f"{robot.name}, rounded", convention=robot.convention,
                 world_T_base=robot.world_T_base, flange_T_tool=robot.flange_T_tool)


def rounded_label(label: str) -> str:
    return f"{label}, parallel axes 1e-5 rad off"


def answer_options(robot: Robot, limits: str) -> AnswerOptions:
    """The options of a whole-answer row: ``"open"`` (±π, flagged rather than filtered) or ``"catalogue"``."""
    if limits == "open":
        return AnswerOptions(limits=Limits(np.full(robot.dof, -np.pi), np.full(robot.dof, np.pi)),
                             filter_limits=False)
    return AnswerOptions(limits=Limits.of(robot))


def answer_solutions(answer) -> list[np.ndarray]:
    """An :class:`IKAnswer`'s kept solutions, one array (m, n) per target."""
    table = answer.solutions
    start, stop = table.bounds(len(answer))
    return [table.joints[a:b] for a, b in zip(start.tolist(), stop.tolist())]


def bench_whole_answer(report: Report, label: str, robot: Robot, args: argparse.Namespace,
                       limit_settings: dict[str, str] = ANSWER_LIMITS) -> None:
    """What a request pays in process: ``answer_ik`` (solve + FK check + select) one pose per call and N poses in
    one call, with ±π limits and no filter (each configuration once, as in EAIK) and with the catalogue limits
    (``limit_settings``: both by default), beside the solve alone and EAIK at its best (``IK`` per pose;
    ``IK_batched`` at the fastest of 1/2/4 threads), on targets from joint vectors over the whole ±π range. Recall
    is measured on the ±π rows, where every generating vector is a solution to list."""
    q_single = sample_configurations(robot, args.single, seed=5)
    q_batch = sample_configurations(robot, args.batch, seed=6)
    T_single, T_batch = forward_kinematics(robot, q_single), forward_kinematics(robot, q_batch)
    singles = [IKTargets.poses(T[None]) for T in T_single]
    references = q_single + np.random.default_rng(7).normal(0.0, REFERENCE_SPREAD, q_single.shape)
    few = FEW_TARGETS_A_CALL
    fews = [IKTargets.poses(T_single[start:start + few]) for start in range(0, len(T_single), few)]
    batch_targets = IKTargets.poses(T_batch)
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    goals = [PoseGoal(T[None]) for T in T_single]
    eaik = None
    if anchors.installed("EAIK"):
        built = anchors.eaik(robot)
        if isinstance(built, str):  # not a plain standard DH table: from the screw model
            built = anchors.eaik_screws(robot)
        eaik = built if isinstance(built, anchors.Anchor) else None
        if eaik is None:
            report.skipped.append(f"EAIK on {label} (whole answer): {built}")
    for limits_name, limits in limit_settings.items():
        options = answer_options(robot, limits)
        single: dict[str, Callable[[], list]] = {
            WHOLE_ANSWER: lambda o=options: [answer_ik(robot, t, o) for t in singles]}
        a_few: dict[str, Callable[[], list]] = {WHOLE_ANSWER: lambda o=options: [answer_ik(robot, t, o) for t in fews]}
        nearest_options = [replace(options, reference=reference) for reference in references]
        nearest: dict[str, Callable[[], list]] = {
            WHOLE_ANSWER: lambda o=nearest_options: [answer_ik(robot, t, each) for t, each in zip(singles, o)]}
        batch: dict[str, Callable[[], object]] = {
            WHOLE_ANSWER: lambda o=options: answer_ik(robot, batch_targets, o),
            SOLVE_ONLY: lambda: solve_ik_arrays(robot, T_batch)}
        if plan is not None:
            single[SOLVE_ONLY_SINGLE] = lambda: [solve_closed_form(robot, plan, g, None) for g in goals]
        if eaik is not None:
            single["EAIK"] = lambda: [eaik.ik_single(T) for T in T_single]
            a_few["EAIK (IK)"] = single["EAIK"]  # its best for a handful: IK per pose, or IK_batched on one thread
            nearest["EAIK"] = lambda: [nearest_first(eaik.ik_single(T), reference)
                                       for T, reference in zip(T_single, references)]
            a_few["EAIK (IK_batched)"] = lambda: [solution for start in range(0, len(T_single), few)
                                                  for solution in eaik.ik_batch_threads(T_single[start:start + few], 1)]
            for threads in EAIK_THREADS:
                batch[f"EAIK ({threads})"] = (lambda k: lambda: eaik.ik_batch_threads(T_batch, k))(threads)
        solutions = {  # untimed: warm-up, and the answers for the solution counts and recall
            WHOLE_ANSWER: ([s for a in single[WHOLE_ANSWER]() for s in answer_solutions(a)],
                           [s for a in a_few[WHOLE_ANSWER]() for s in answer_solutions(a)],
                           answer_solutions(batch[WHOLE_ANSWER]()),
                           [s for a in nearest[WHOLE_ANSWER]() for s in answer_solutions(a)])}
        if eaik is not None:
            solutions["EAIK"] = (single["EAIK"](), a_few["EAIK (IK_batched)"](),
                                 batch[f"EAIK ({EAIK_THREADS[-1]})"](), nearest["EAIK"]())
        for task in (*single.values(), *a_few.values(), *batch.values(), *nearest.values()):
            task()
        single_task = ANSWER_SINGLE_TASK.format(limits=limits_name)
        few_task = ANSWER_FEW_TASK.format(limits=limits_name, few=few)
        batch_task = ANSWER_BATCH_TASK.format(limits=limits_name, batch=args.batch)
        nearest_task = ANSWER_NEAREST_TASK.format(limits=limits_name)
        for kind, (task, tasks, truth) in enumerate(((single_task, single, q_single), (few_task, a_few, q_single),
                                                     (batch_task, batch, q_batch),
                                                     (nearest_task, nearest, q_single))):
            best = best_of(tasks, args.repeats)
            eaik_rows = {name: seconds for name, seconds in best.items() if name.startswith("EAIK (")}
            if eaik_rows:  # EAIK at its best: its fastest call (thread count, or IK against IK_batched)
                fastest = min(eaik_rows, key=eaik_rows.get)
                best = {name: s for name, s in best.items() if name not in eaik_rows}
                best["EAIK"] = eaik_rows[fastest]
                each = ", ".join(f"{k[6:-1]}: {v / len(truth) * 1e6:.2f}" for k, v in eaik_rows.items())
                report.skipped.append(f"EAIK on {label}, {task}: fastest {fastest[6:-1]} (µs per pose: {each})")
            for name, seconds in best.items():
                per_pose = found = None
                if name in solutions:
                    got = solutions[name][kind]
                    per_pose, found = recall(robot, truth, got)
                    if limits != "open":
                        found = None
                report.rows.append(Row(label, task, name, seconds / len(truth), per_pose, found))


def nearest_first(solutions: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Solutions (m, n) ordered by their largest joint travel from ``reference`` (n,), the nearest first: the
    answer's own order under the default ``linf`` norm, for an anchor that lists them in its own order."""
    return solutions[np.argsort(np.abs(solutions - reference).max(axis=1), kind="stable")]


def _timed_ik(report: Report, label: str, task: str, robot: Robot, tasks: dict[str, Callable[[], list]],
              truth: np.ndarray, repeats: int, to_solutions: Callable[[str, list], list[np.ndarray]]) -> None:
    counts = {}
    for name, run in tasks.items():  # one untimed call each: warm-up and the solutions for recall
        counts[name] = recall(robot, truth, to_solutions(name, run()))
    for name, seconds in best_of(tasks, repeats).items():
        per_pose, found = counts[name]
        report.rows.append(Row(label, task, name, seconds / len(truth), per_pose, found))


def peak_memory(robot: Robot, poses: int) -> str:
    """Peak traced allocation while solving a batch of ``poses`` targets with the array API."""
    T = forward_kinematics(robot, sample_configurations(robot, poses, seed=3))
    solve_ik_arrays(robot, T[:10])  # plan built outside the measurement
    tracemalloc.start()
    tracemalloc.reset_peak()
    start = time.perf_counter()
    arrays = solve_ik_arrays(robot, T)
    elapsed = time.perf_counter() - start
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    result_bytes = sum(a.nbytes for a in (arrays.joints, arrays.valid, arrays.count, arrays.position,
                                          arrays.orientation))
    return (f"peak traced memory for a {poses:,}-pose batch (PUMA 560, solve_ik_arrays): {peak / 2**20:.0f} MiB "
            f"({peak / poses:.0f} bytes per pose; the result itself is {result_bytes / 2**20:.0f} MiB); "
            f"{elapsed:.2f} s with tracing on")


def format_report(report: Report) -> str:
    lines = ["| robot | task | library | µs per item | × core | solutions per pose | recall |",
             "|---|---|---|---:|---:|---:|---:|"]
    for row in report.rows:
        core = report.find(row.robot, row.task, "core")
        ratio = row.seconds_per_item / core.seconds_per_item if core and core.seconds_per_item else None
        lines.append("| " + " | ".join([
            row.robot, row.task, row.library, f"{row.seconds_per_item * 1e6:.2f}",
            "" if ratio is None or row.library == "core" else f"{ratio:.2f}",
            "" if row.solutions_per_pose is None else f"{row.solutions_per_pose:.2f}",
            "" if row.recall is None else f"{row.recall:.3f}"]) + " |")
    return "\n".join(lines)


def targets(report: Report, batch: int) -> list[str]:
    """The issue's targets, each a ratio from this run."""
    out = []

    def ratio(robot: str, task: str, a: str, b: str) -> float | None:
        x, y = report.find(robot, task, a), report.find(robot, task, b)
        return None if x is None or y is None else x.seconds_per_item / y.seconds_per_item

    checks = []
    for robot in ("PUMA 560", "UR5"):
        checks += [
            (f"batch IK per pose, core / EAIK IK_batched ({robot})", ratio(robot, f"IK, batch of {batch:,}", "core", "EAIK"), "<=", 1.0),
            # issue 16: one pose per call, as motion planners call it
            (f"single-pose IK, core / EAIK IK ({robot})", ratio(robot, "IK, single pose", "core", "EAIK"), "<=", 10.0),
            (f"single-pose IK, roboticstoolbox analytic / core ({robot})",
             ratio(robot, "IK, single pose", "roboticstoolbox", "core"), ">=", 3.0),
            (f"batch FK per configuration, core / roboticstoolbox ETS.eval ({robot})",
             ratio(robot, f"FK, batch of {batch:,}", "core", "roboticstoolbox"), "<=", 1.0),
        ]
    for robot in ANSWER_ROBOTS:  # issue 24: what a request pays, against EAIK at its best
        for limits_name, limits in ANSWER_LIMITS.items():
            if limits != "open":
                continue
            checks += [
                (f"single-pose whole answer (answer_ik), {limits_name}, core / EAIK IK ({robot})",
                 ratio(robot, ANSWER_SINGLE_TASK.format(limits=limits_name), WHOLE_ANSWER, "EAIK"), "<=", 10.0),
                (f"batch whole answer per pose, {limits_name}, core / EAIK IK_batched at its best ({robot})",
                 ratio(robot, ANSWER_BATCH_TASK.format(limits=limits_name, batch=batch), WHOLE_ANSWER, "EAIK"),
                 "<=", 1.5)]
        few_task = ANSWER_FEW_TASK.format(limits=OPEN_LIMITS, few=FEW_TARGETS_A_CALL)
        few_ratio, single_ratio = (ratio(robot, task, WHOLE_ANSWER, "EAIK") for task in (
            few_task, ANSWER_SINGLE_TASK.format(limits=OPEN_LIMITS)))
        if few_ratio is not None and single_ratio is not None:
            out.append(f"- whole answer per pose, {FEW_TARGETS_A_CALL} targets a call, {OPEN_LIMITS}, core / EAIK at "
                       f"its best ({robot}): {few_ratio:.2f} (single pose: {single_ratio:.2f}; no target of its own)")
        nearest_ratio = ratio(robot, ANSWER_NEAREST_TASK.format(limits=OPEN_LIMITS), WHOLE_ANSWER, "EAIK")
        if nearest_ratio is not None:
            out.append(f"- single-pose whole answer nearest first to a reference, {OPEN_LIMITS}, core / EAIK IK and "
                       f"a sort by the same distance ({robot}): {nearest_ratio:.2f} (no target of its own)")
    open_single = ANSWER_SINGLE_TASK.format(limits=OPEN_LIMITS)
    for robot in ROUNDED_ROBOTS:  # no target: what a CAD-rounded description costs against the exact arm
        rounded, exact = report.find(rounded_label(robot), open_single, WHOLE_ANSWER), report.find(
            robot, open_single, WHOLE_ANSWER)
        if rounded is not None and exact is not None:
            out.append(f"- single-pose whole answer, {OPEN_LIMITS}, arm with parallel axes 1e-5 rad off / the exact "
                       f"arm, core ({robot}): {rounded.seconds_per_item / exact.seconds_per_item:.2f} (no target)")
    batch_task = ANSWER_BATCH_TASK.format(limits="catalogue limits", batch=batch)
    checks.append(("whole in-process IK answer / solve alone, catalogue limits (PUMA 560)",
                   ratio("PUMA 560", batch_task, WHOLE_ANSWER, SOLVE_ONLY), "<=", 1.5))
    for name, value, sense, bound in checks:
        if value is None:
            out.append(f"- {name}: not measured (library not installed or arm not supported)")
        else:
            met = value <= bound if sense == "<=" else value >= bound
            out.append(f"- {name}: {value:.2f} (target {sense} {bound:g}: {'met' if met else 'NOT met'})")
    return out


def machine() -> str:
    cpu = "unknown CPU"
    try:
        cpu = next(line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text().splitlines()
                   if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    import os
    return (f"{cpu}, {os.cpu_count()} logical CPUs, Python {platform.python_version()}, "
            f"numpy {np.__version__}, {platform.system()} {platform.release()}")


def main(argv: list[str] | None = None) -> int:
    parser = timing_arguments("python -m benchmarks.core", __doc__.splitlines()[0])
    parser.add_argument("--memory-poses", type=int, default=100_000, help="poses in the memory run (0: skip)")
    parser.add_argument("--robots", nargs="*", default=DEFAULT_ROBOTS, choices=list(ROBOTS),
                        help=f"default: {', '.join(DEFAULT_ROBOTS)}")
    parser.add_argument("--answer-robots", nargs="*", default=ANSWER_ROBOTS, choices=list(ROBOTS),
                        help=f"the whole-answer rows' arms (default: {', '.join(ANSWER_ROBOTS)})")
    parser.add_argument("--rounded-robots", nargs="*", default=ROUNDED_ROBOTS, choices=list(ROBOTS),
                        help=f"the whole-answer rows' arms again with parallel axes 1e-5 rad off, ±π limits only "
                             f"(default: {', '.join(ROUNDED_ROBOTS)})")
    args = parse_timing_arguments(parser, argv)
    if args.quick:
        args.memory_poses = 200

    catalogue = load_catalogue([Settings().builtin_robots_dir], max_joints=32)
    report = report_noting_missing_anchors()
    for label in args.robots:
        bench_robot(report, label, catalogue.get(ROBOTS[label]).robot, args)
    for label in args.answer_robots:
        bench_whole_answer(report, label, catalogue.get(ROBOTS[label]).robot, args)
    for label in args.rounded_robots:
        bench_whole_answer(report, rounded_label(label), cad_rounded(catalogue.get(ROBOTS[label]).robot), args,
                           {OPEN_LIMITS: ANSWER_LIMITS[OPEN_LIMITS]})
    if args.memory_poses:
        report.memory = peak_memory(catalogue.get(ROBOTS["PUMA 560"]).robot, args.memory_poses)

    print(f"machine: {machine()}")
    print(f"sizes: batch {args.batch:,}, single {args.single:,} poses, best of {args.repeats} interleaved rounds\n")
    print(format_report(report))
    print("\ntargets (ratios from this run):")
    print("\n".join(targets(report, args.batch)))
    if report.memory:
        print(f"\nmemory: {report.memory}")
    if report.skipped:
        print("\nnotes:")
        print("\n".join(f"- {line}" for line in report.skipped))
    return 0


if __name__ == "__main__":
    sys.exit(main())
