"""Where the time of one pose's whole answer goes, stage by stage, against EAIK's IK of the same pose.

    python -m benchmarks.single_pose_profile                        # PUMA 560, UR5, KUKA KR6; 500 poses each
    python -m benchmarks.single_pose_profile --single 200 --robots UR5

Issue 24 asks for the whole answer of one pose within 10× EAIK and for the profile that bounds it. This script
times the whole answer (``answer_ik``, one pose a call, limits ±π unfiltered as ``benchmarks.core``'s single-pose
row, and the catalogue's limits) and then each stage alone, on the same poses, in the order ``answer_ik`` runs
them for a closed-form arm:

* scalar solve: the family's one-pose path (``plan.solve_one``), every candidate slot on Python floats;
* FK of the candidates: the forward kinematics the FK check runs on them (the core's chain program as straight-line
  float arithmetic, ``tool_columns_scalar_rows``), alone;
* FK check (``verify_one``): that forward kinematics, the residuals, the duplicate scan, the labels, the promise;
* table: the verified rows as a ``SolutionTable`` (``one_pose_table``);
* selection (``select``): the limits, the 2π-equivalents, the order, the counts and notes;
* the rest: the whole answer less the stages above (the targets, the plan's look-up, the parts' assembly, the
  ``IKAnswer``).

Beside them EAIK's ``IK`` of each pose, its solutions turned into an array (what ``benchmarks.core`` times), and the
budget the goal sets, 10× that. The **floor** is what no answer can skip: the solve and the forward kinematics of
every candidate it proposes (each solution is verified by FK before it leaves the service). Where the floor alone is
near or beyond the budget, the goal is out of reach of a core in Python and numpy, whatever the glue.

Stages timed alone run hot (the same few functions in a loop over the poses); inside the answer they run among
the others' code and cost more. So each stage of the floor is also timed **in the answer**: the whole answer again
with that stage's results looked up from a table made beforehand (the scalar solve, keyed by the pose's bytes; the
FK of the candidates, keyed by their rows; the FK check, keyed by the scalar answer it checks), interleaved with
the other rows in each round, the difference being what the stage costs where it runs. A lookup costs a
microsecond or so, so those figures are a little low. Every row is timed with the objects the warm-up left (the
lookups' tables among them) frozen out of the garbage collector's passes (``gc.freeze``, as the service freezes its
start-up objects): kept alive and tracked, the tables would lengthen each pass of the looked-up rows alone.
"""

from __future__ import annotations

import argparse
import gc
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np

from service.config import Settings
from service.kinematics import UNLIMITED, forward_kinematics
from service.kinematics._forward import tool_columns_scalar_rows
from service.kinematics._robot import Robot
from service.kinematics.ik import IKTargets, answer_ik, cached_plan
from service.kinematics.ik import _closed_form, _goals
from service.kinematics.ik._goals import PoseGoal
from service.kinematics.ik._select import select
from service.kinematics.ik._verify import OnePoseVerified, one_pose_table, verify_one
from service.robots.catalogue import load_catalogue

from . import anchors
from .core import (ANSWER_ROBOTS, ROBOTS, answer_options, best_of, machine, parse_timing_arguments,
                   sample_configurations, timing_arguments)

#: The goal of issue 24: the whole answer of one pose within this many times EAIK's ``IK``.
GOAL_RATIO = 10.0
LIMIT_SETTINGS = {"limits ±π, no filter": "open", "catalogue limits": "catalogue"}


@dataclass
class Stage:
    name: str
    alone: float  # µs a pose, timed alone
    in_answer: float | None = None  # µs a pose, what the whole answer saves when the stage is looked up
    indent: int = 1
    floor: bool = False  # part of what every answer pays (the solve, the FK of its candidates)


@dataclass
class Profile:
    robot: str
    poses: int
    declined: int  # poses the scalar path declined (not clearly generic): answered on arrays, left out here
    candidates: float  # the scalar path's valid slots a pose: the rows the FK check runs on
    whole: dict[str, float]  # limit setting → µs a pose
    stages: list[Stage]
    selection: dict[str, float]  # limit setting → µs a pose
    fk_per_candidate: float  # µs
    eaik: float | None  # µs a pose, or None when EAIK is missing or does not take the arm
    eaik_note: str = ""

    def floor(self, in_answer: bool) -> float:
        """The scalar solve and the forward kinematics of its candidates, µs a pose, alone or in the answer."""
        return sum(stage.in_answer if in_answer else stage.alone for stage in self.stages if stage.floor)


def profile_robot(label: str, robot: Robot, poses: int, repeats: int) -> Profile:
    """The whole answer of each of ``poses`` poses and its stages, best of ``repeats`` interleaved rounds."""
    q = sample_configurations(robot, poses, seed=5)
    T = forward_kinematics(robot, q)
    plan = cached_plan(robot, constrain_orientation=True, reference=None)
    if plan is None or not hasattr(plan, "solve_one"):
        raise SystemExit(f"{label}: no closed form with a one-pose path ({type(plan).__name__})")
    one_poses = [plan.solve_one(pose, None) for pose in T]
    kept = [index for index, one_pose in enumerate(one_poses) if one_pose is not None]
    T, one_poses = T[kept], [one_poses[index] for index in kept]
    goals = [PoseGoal(pose[None]) for pose in T]
    verified = [verify_one(robot, goal, one_pose, None) for goal, one_pose in zip(goals, one_poses)]
    rows = [[joints for joints in one_pose.rows if joints is not None] for one_pose in one_poses]
    kept_rows = [v.rows for v in verified if v is not None]
    tables = [one_pose_table([r], robot.dof) for r in kept_rows]
    singles = [IKTargets.poses(pose[None]) for pose in T]
    options = {name: answer_options(robot, setting) for name, setting in LIMIT_SETTINGS.items()}
    open_name = next(iter(LIMIT_SETTINGS))

    def selected(option) -> Callable[[], object]:
        limits = option.limits
        return lambda: [select(robot, table, 1, limits, filter_limits=option.filter_limits, reference=None,
                               ordering=option.ordering, max_equivalents=option.max_equivalents, budget=UNLIMITED)
                        for table in tables]

    def whole(option) -> Callable[[], object]:
        return lambda: [answer_ik(robot, t, option) for t in singles]

    # in the answer: the whole answer again, stages looked up from tables (made on the warm-up pass)
    solve = Lookup(type(plan), "solve_one", lambda self, pose, reference=None: pose.tobytes())
    check = Lookup(_closed_form, "verify_one", lambda robot, goal, one_pose, reference=None: id(one_pose),
                   _fresh_verified)
    # (the solve looked up, each pose's scalar answer is one object, and so is each of its rows)
    fk = Lookup(_goals, "tool_columns_scalar_rows", lambda robot, rows: tuple(map(id, rows)))

    def whole_with(*lookups: Lookup) -> Callable[[], object]:
        run = whole(options[open_name])

        def looked_up() -> object:
            with _looked_up(lookups):
                return run()
        return looked_up

    tasks: dict[str, Callable[[], object]] = {
        **{f"whole {name}": whole(option) for name, option in options.items()},
        "whole, solve looked up": whole_with(solve),
        "whole, solve and FK looked up": whole_with(solve, fk),
        "whole, solve and check looked up": whole_with(solve, check),
        "scalar solve": lambda: [plan.solve_one(pose, None) for pose in T],
        "FK of the candidates": lambda: [tool_columns_scalar_rows(robot, r) for r in rows],
        "FK check": lambda: [verify_one(robot, goal, one_pose, None) for goal, one_pose in zip(goals, one_poses)],
        "table": lambda: [one_pose_table([r], robot.dof) for r in kept_rows],
        **{f"selection {name}": selected(option) for name, option in options.items()},
    }
    eaik, eaik_note = _eaik(robot)
    if eaik is not None:
        tasks["EAIK"] = lambda: [eaik(pose) for pose in T]
    for task in tasks.values():  # warm-up, and the lookups' tables
        task()
    count = max(len(T), 1)
    gc.freeze()  # what the warm-up left (the lookups' tables too) out of the collector's passes, as the service's
    try:         # start-up objects are: tables kept alive would lengthen every pass of the looked-up rows alone
        per_pose = {name: value / count * 1e6 for name, value in best_of(tasks, repeats).items()}
    finally:
        gc.unfreeze()
    whole_open = per_pose[f"whole {open_name}"]
    without_solve = per_pose["whole, solve looked up"]
    without_solve_and_fk = per_pose["whole, solve and FK looked up"]
    without_solve_and_check = per_pose["whole, solve and check looked up"]
    candidates = sum(len(r) for r in rows) / count
    stages = [Stage("scalar solve (plan.solve_one)", per_pose["scalar solve"], whole_open - without_solve,
                    floor=True),
              Stage("FK check (verify_one)", per_pose["FK check"], without_solve - without_solve_and_check),
              Stage("FK of the candidates (the chain program on floats)", per_pose["FK of the candidates"],
                    without_solve - without_solve_and_fk, 2, floor=True),
              Stage("the rest: table, selection, targets, plan look-up, assembly, IKAnswer",
                    whole_open - per_pose["scalar solve"] - per_pose["FK check"], without_solve_and_check),
              Stage("table (one_pose_table)", per_pose["table"], None, 2),
              Stage(f"selection (select), {open_name}", per_pose[f"selection {open_name}"], None, 2)]
    return Profile(label, count, poses - len(kept), candidates,
                   {name: per_pose[f"whole {name}"] for name in LIMIT_SETTINGS}, stages,
                   {name: per_pose[f"selection {name}"] for name in LIMIT_SETTINGS},
                   per_pose["FK of the candidates"] / max(candidates, 1e-9), per_pose.get("EAIK"), eaik_note)


@dataclass
class Lookup:
    """``owner.name`` answered from ``table``, its results by ``key(*arguments)`` (made on the first call with each
    key), while :func:`_looked_up` holds it; ``fresh`` (or None) makes each answer a new object of the stored one
    (an object the answer changes, as a lazily built table)."""

    owner: object
    name: str
    key: Callable[..., object]
    fresh: Callable[[object], object] | None = None
    table: dict = field(default_factory=dict)

    def bound_to(self, original: Callable) -> Callable:
        def looked_up(*args, **kwargs):
            found = self.key(*args, **kwargs)
            if found not in self.table:
                self.table[found] = original(*args, **kwargs)
            return self.table[found] if self.fresh is None else self.fresh(self.table[found])
        return looked_up


@contextmanager
def _looked_up(lookups: tuple[Lookup, ...]) -> Iterator[None]:
    """Within, each of ``lookups`` answers in place of its function; afterwards the functions are as they were."""
    saved = []
    for lookup in lookups:
        original, own = getattr(lookup.owner, lookup.name), lookup.name in vars(lookup.owner)
        saved.append((lookup, original, own))
        setattr(lookup.owner, lookup.name, lookup.bound_to(original))
    try:
        yield
    finally:
        for lookup, original, own in reversed(saved):
            if own:
                setattr(lookup.owner, lookup.name, original)
            else:
                delattr(lookup.owner, lookup.name)


def _fresh_verified(verified: OnePoseVerified | None) -> OnePoseVerified | None:
    """A new :class:`OnePoseVerified` of the same rows (its table not yet built), as ``verify_one`` returns."""
    if verified is None:
        return None
    return OnePoseVerified(verified.rows, verified.dof, verified.complete, verified.nearest, verified.singularities)


def _eaik(robot: Robot) -> tuple[Callable[[np.ndarray], np.ndarray] | None, str]:
    """EAIK's ``IK`` of one pose as ``benchmarks.core`` times it (its result as an array), or None and why not."""
    if not anchors.installed("EAIK"):
        return None, "EAIK: not installed (pip install -e '.[bench]'), skipped"
    built = anchors.eaik(robot)
    if isinstance(built, str):
        built = anchors.eaik_screws(robot)
    if isinstance(built, str):
        return None, f"EAIK: {built}"
    return built.ik_single, ""


def format_profile(profile: Profile) -> str:
    open_name = next(iter(LIMIT_SETTINGS))
    whole = profile.whole[open_name]

    def ratio(microseconds: float) -> str:
        return f"{microseconds / profile.eaik:.1f}" if profile.eaik else ""

    def row(name: str, alone: float, in_answer: float | None = None, indent: int = 0) -> str:
        situ = "" if in_answer is None else f"{in_answer:.1f}"
        share = in_answer if in_answer is not None else alone  # where it runs, when measured there
        return f"| {'  ' * indent}{name} | {alone:.1f} | {situ} | {share / whole:.2f} | {ratio(share)} |"

    lines = [f"**{profile.robot}**: {profile.poses} poses, {profile.candidates:.2f} candidates a pose checked by FK"
             + (f" ({profile.declined} more declined by the scalar path, left out)" if profile.declined else ""),
             "", "| stage | µs a pose, alone | µs a pose, in the answer | share of the whole answer | × EAIK |",
             "|---|---:|---:|---:|---:|", row(f"whole answer (answer_ik), {open_name}", whole, whole)]
    lines += [row(stage.name, stage.alone, stage.in_answer, stage.indent) for stage in profile.stages]
    for name, microseconds in profile.whole.items():
        if name != open_name:
            lines.append(row(f"whole answer (answer_ik), {name}", microseconds, microseconds))
            lines.append(row(f"selection (select), {name}", profile.selection[name], indent=1))
    if profile.eaik:
        lines.append(row("EAIK IK (its solutions as an array)", profile.eaik, profile.eaik))
    lines.append("")
    lines.append(f"- FK of one candidate on floats, alone: {profile.fk_per_candidate:.2f} µs")
    alone, in_answer = profile.floor(False), profile.floor(True)
    floor = f"{alone:.1f} µs alone, {in_answer:.1f} in the answer"
    if profile.eaik:
        budget = GOAL_RATIO * profile.eaik
        lines.append(f"- the goal's budget ({GOAL_RATIO:g}× EAIK): {budget:.1f} µs; the whole answer "
                     f"{whole / profile.eaik:.1f}× EAIK")
        lines.append(f"- the floor (the scalar solve + the FK of its candidates): {floor}; "
                     f"{alone / profile.eaik:.1f}× / {in_answer / profile.eaik:.1f}× EAIK, "
                     f"{alone / budget:.2f} / {in_answer / budget:.2f} of the budget")
    else:
        lines.append(f"- the floor (the scalar solve + the FK of its candidates): {floor} ({profile.eaik_note})")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser: argparse.ArgumentParser = timing_arguments("python -m benchmarks.single_pose_profile",
                                                       __doc__.splitlines()[0])
    parser.add_argument("--robots", nargs="*", default=ANSWER_ROBOTS, choices=list(ROBOTS),
                        help=f"default: {', '.join(ANSWER_ROBOTS)}")
    args = parse_timing_arguments(parser, argv)
    catalogue = load_catalogue([Settings().builtin_robots_dir], max_joints=32)
    print(f"machine: {machine()}")
    print(f"{args.single:,} poses a robot (joint vectors uniform in ±π), one call a pose, best of {args.repeats} "
          f"interleaved rounds\n")
    for label in args.robots:
        print(format_profile(profile_robot(label, catalogue.get(ROBOTS[label]).robot, args.single, args.repeats)))
        print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
