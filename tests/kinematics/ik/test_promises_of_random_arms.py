"""Every pose of a random DH arm of two to six joints, from the arm's own FK, is never said unreachable, and a
complete answer lists the configuration it came from (or reports the singularity or the free joints that make
it one member of a family).

The arms are drawn as a cell programmer's inline tables are: twists of 0, ±90°, 180° or any angle, offsets of 0,
0.2, 0.3 or any length, a slide now and then, in both DH conventions, so that points land exactly on axes and
slides run parallel. A hostile probe found one pose in 25 of such arms answered `unreachable`: a point on an
axis judged against rounding dust instead of the arm (subproblem 1 with both of its vectors ~0), a joint the
position leaves free held at 0 although the orientation fixes it (a roll or a two-axis wrist cannot take it up),
two parallel slides taken as independent, and a point on joint 3's axis taken as placed by joints 2 and 3.
"""

from __future__ import annotations

import numpy as np
import pytest

from service.kinematics import Joint, Robot, forward_kinematics
from service.kinematics.ik import distance_to_reference, solve_ik

H = np.pi / 2


def _random_arm(rng: np.random.Generator, n: int) -> Robot:
    while True:
        convention = str(rng.choice(["standard", "modified"]))
        joints = [Joint(f"q{i}", "prismatic" if rng.random() < 0.15 else "revolute",
                        float(rng.choice([0, 0, 0.3, rng.uniform(-1, 1)])),
                        float(rng.choice([0, H, -H, np.pi, rng.uniform(-np.pi, np.pi)])),
                        float(rng.choice([0, 0, 0.2, rng.uniform(-1, 1)])),
                        float(rng.choice([0, 0, H, rng.uniform(-np.pi, np.pi)]))) for i in range(n)]
        rows = range(n - 1) if convention == "standard" else range(1, n)
        twist = [abs(joints[i].alpha) % np.pi for i in rows]
        if any(abs(joints[i].a) < 1e-3 and min(t, np.pi - t) < 1e-3 for i, t in zip(rows, twist)):
            continue  # coaxial neighbours: their own tests (the coaxial family)
        return Robot(joints, name="random arm", convention=convention)


def _distance(robot: Robot, a: np.ndarray, b: np.ndarray) -> float:
    return float(distance_to_reference(robot, a, b))


@pytest.mark.parametrize("seed", [1, 2])
def test_fk_poses_of_random_arms_are_never_unreachable(seed):
    rng = np.random.default_rng(seed)
    complete = 0
    for trial in range(350):
        robot = _random_arm(rng, int(rng.integers(2, 7)))
        q = rng.uniform(-np.pi, np.pi, robot.dof)
        q[~robot.is_revolute] = rng.uniform(-0.5, 0.5, int((~robot.is_revolute).sum()))
        result = solve_ik(robot, forward_kinematics(robot, q))
        context = (seed, trial, robot.convention, robot.joints, q.tolist(), result.structure, result.detail)
        assert result.status != "unreachable", context
        if result.complete and not result.singularities and not result.free_joints:  # else a family's member
            complete += 1
            assert min(_distance(robot, s.joints, q) for s in result.solutions) <= 1e-6, context
    assert complete > 200  # most answers are closed forms' promises, held here


@pytest.mark.parametrize("convention, rows, q", [
    ("standard", [("revolute", 0, H, 0), ("revolute", 0, H, 0.2)], [0.5, 0.5]),  # a point on axis 1, exactly
    ("modified", [("revolute", 0.3, 0, 0), ("revolute", 0, H, 0)], [0.3, 2.04]),
    ("standard", [("prismatic", 0.3, 0, 0), ("prismatic", 0, -2.813376761287988, 0), ("revolute", 0, H, 0),
                  ("revolute", 0, 0, 0)], [0.5] * 4),  # two parallel slides
    ("modified", [("revolute", 0, 0, 0), ("revolute", 0.3, H, 0), ("revolute", 0, H, 0.2), ("revolute", 0, H, 0),
                  ("revolute", 0, H, 0)], [0.5] * 5),  # the wrist point on joint 3's axis
    ("modified", [("revolute", 0, 0, 0), ("revolute", 0, H, 0), ("revolute", 0, H, 0), ("revolute", 0, H, 0),
                  ("prismatic", 0.3, 0, 0), ("prismatic", 0, H, 0)], [0.5] * 6),
])
def test_the_probes_arms_reach_their_own_poses(convention, rows, q):
    robot = Robot([Joint(f"q{i}", kind, a, alpha, d, 0.0) for i, (kind, a, alpha, d) in enumerate(rows)],
                  name="probe", convention=convention)
    q = np.array(q)
    result = solve_ik(robot, forward_kinematics(robot, q))
    assert result.status == "ok", (result.structure, result.detail)
    if result.complete and not result.singularities and not result.free_joints:
        assert min(_distance(robot, s.joints, q) for s in result.solutions) <= 1e-6
