"""Not a timing: how often the general 6R solver hands a near-singular pose to the numeric search, and whether any
answer breaks its promise there (issue 22.6).

    python -m benchmarks.general_6r_singular            # the full run: 21 configurations per arm
    python -m benchmarks.general_6r_singular --quick    # tiny sizes: a smoke run

Arms: the catalogue's general 6R arms (the xArm 6), Manocha and Canny's 16-solution arm and seeded random 6R arms
(those of :mod:`benchmarks.general_6r`). Per arm, configurations where det J changes sign along a random segment
are found by bisection, kept where σmin/σmax of the Jacobian is below 1e-6, and moved by δ ∈ {0, 1e-12, 1e-9,
1e-6, 1e-3} along that segment; the target is their FK. Per request: did the numeric search answer (the general
solver could not promise every solution), and is the promise kept (api.md): never ``unreachable``, and a
``complete`` answer holds the generating configuration within 1e-6 rad, or reports a singularity and holds it
(within 2e-6 at a fold) when asked again with it as the reference.
"""

from __future__ import annotations

import argparse

import numpy as np

from service.config import BUILTIN_ROBOTS_DIR
from service.kinematics import Robot, forward_kinematics, geometric_jacobian
from service.kinematics.ik import joint_difference
from service.kinematics.ik._answer import AnswerOptions, IKTargets, answer_ik
from service.kinematics.ik._plan import plan_for
from service.kinematics.ik._solve import result_of, unlimited
from service.robots.catalogue import load_catalogue

from .general_6r import manocha_canny_arm, random_general_arm

DELTAS = (0.0, 1e-12, 1e-9, 1e-6, 1e-3)
SINGULAR_RATIO = 1e-6
FOLDS = {"boundary", "stretched", "folded", "stretched_or_folded"}


def arms() -> dict[str, Robot]:
    """The general 6R arms of the run, by name."""
    catalogue = load_catalogue([BUILTIN_ROBOTS_DIR], max_joints=32)
    chosen = {entry.description.id: entry.robot for entry in catalogue.entries()
              if entry.robot.dof == 6 and _is_general(entry.robot)}
    chosen["manocha_canny"] = manocha_canny_arm()
    for seed in (1, 2, 3):
        chosen[f"random_{seed}"] = random_general_arm(seed)
    return chosen


def _is_general(robot: Robot) -> bool:
    plan = plan_for(robot, constrain_orientation=True, reference=None)
    return plan is not None and plan.structure == "general_6r"


def singular_configuration(robot: Robot, rng: np.random.Generator) -> tuple[np.ndarray, float, np.ndarray]:
    """A configuration with det J = 0 (bisection along the first random segment on which it changes sign), its
    σmin/σmax, and the segment's unit direction."""
    while True:
        start, end = rng.uniform(-np.pi, np.pi, (2, 6))
        det = lambda t: np.linalg.det(geometric_jacobian(robot, start + t * (end - start)))  # noqa: E731
        low, high = 0.0, 1.0
        if np.sign(det(low)) != np.sign(det(high)):
            break
    for _ in range(60):
        middle = 0.5 * (low + high)
        low, high = (middle, high) if np.sign(det(middle)) == np.sign(det(low)) else (low, middle)
    q = start + low * (end - start)
    sigma = np.linalg.svd(geometric_jacobian(robot, q[None])[0], compute_uv=False)
    return q, float(sigma[-1] / sigma[0]), (end - start) / np.linalg.norm(end - start)


def _answer(robot: Robot, target: np.ndarray, reference: np.ndarray | None):
    options = AnswerOptions(reference=reference, limits=unlimited(robot), filter_limits=False, free_joints=None)
    return result_of(answer_ik(robot, IKTargets.poses(target[None]), options), 0)


def _nearest(robot: Robot, result, q: np.ndarray) -> float:
    solutions = np.array([s.joints for s in result.solutions]).reshape(-1, robot.dof)
    return float(np.abs(joint_difference(robot, solutions, q)).max(axis=1).min()) if len(solutions) else np.inf


def promise_kept(robot: Robot, q: np.ndarray, target: np.ndarray, result) -> bool:
    """The promise of one answer (see the module docstring)."""
    if result.status == "unreachable":
        return False
    if not result.complete or _nearest(robot, result, q) <= 1e-6:
        return True
    if not result.singularities:
        return False
    tolerance = 2e-6 if any(s.relation in FOLDS for s in result.singularities) else 1e-6
    return _nearest(robot, _answer(robot, target, q), q) <= tolerance


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--configurations", type=int, default=21, help="singular configurations per arm")
    parser.add_argument("--quick", action="store_true", help="2 configurations of 2 arms")
    args = parser.parse_args(argv)
    count = 2 if args.quick else args.configurations
    chosen = arms()
    if args.quick:
        chosen = dict(list(chosen.items())[:2])
    print("| arm | requests | numeric search | false promises |")
    print("| --- | ---: | ---: | ---: |")
    totals = np.zeros(3, dtype=int)
    for name, robot in chosen.items():
        rng = np.random.default_rng(7)
        row = np.zeros(3, dtype=int)
        found = 0
        while found < count:
            q_singular, ratio, direction = singular_configuration(robot, rng)
            if ratio >= SINGULAR_RATIO:
                continue
            found += 1
            for delta in DELTAS:
                q = q_singular + delta * direction
                target = forward_kinematics(robot, q)
                result = _answer(robot, target, None)
                row += (1, result.method == "numeric", not promise_kept(robot, q, target, result))
        print(f"| {name} | {row[0]} | {row[1]} | {row[2]} |")
        totals += row
    print(f"| all | {totals[0]} | {totals[1]} | {totals[2]} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
