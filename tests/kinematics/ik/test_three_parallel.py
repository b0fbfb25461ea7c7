"""Three consecutive parallel axes anywhere in a 6R chain, in closed form (ik/_three_parallel*.py, ik/_reversed.py).

Seeded random arms of each class, each stated in the three DH conventions with a base and a tool, with
anti-parallel axes among the parallel ones: the generating joint vector of every pose from the arm's own FK is
among the solutions (revolute joints modulo 2π), every solution reproduces its target by an FK computed here,
no such pose is answered unreachable, and stretched or folded poses report the elbow singularity.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from service.kinematics import CONVENTIONS, Joint, Robot, forward_kinematics
from service.kinematics.ik import joint_difference, solve_ik, solve_ik_arrays
from service.kinematics.ik import cached_plan
from service.kinematics.ik._plan import geometry_of

from tests.arms import THREE_PARALLEL_CASES as CASES, random_three_parallel_arm
from tests.ik_helpers import SAME

POSES = 1000


def _hits(robot: Robot, joints: np.ndarray, valid: np.ndarray, q: np.ndarray, tolerance: float) -> np.ndarray:
    gap = np.abs(joint_difference(robot, joints, q[:, None, :])).max(axis=-1)
    return (valid & (gap <= tolerance)).any(axis=1)


def _fk_misses(robot: Robot, joints: np.ndarray, valid: np.ndarray, targets: np.ndarray) -> np.ndarray:
    """Position and orientation misses of every valid solution, by an FK of this test."""
    T = forward_kinematics(robot, joints[valid])
    goal = np.broadcast_to(targets[:, None], joints.shape[:2] + (4, 4))[valid]
    position = np.linalg.norm(T[:, :3, 3] - goal[:, :3, 3], axis=-1) / robot.characteristic_length
    orientation = np.linalg.norm(T[:, :3, :3] - goal[:, :3, :3], axis=(-2, -1))
    return np.maximum(position, orientation)


def test_the_three_conventions_state_the_same_arm():
    q = np.random.default_rng(1).uniform(-np.pi, np.pi, (20, 6))
    for case in CASES:
        poses = [forward_kinematics(random_three_parallel_arm(case, c, seed=7), q) for c in CONVENTIONS]
        assert np.allclose(poses[0], poses[1], atol=1e-12) and np.allclose(poses[0], poses[2], atol=1e-12)


@pytest.mark.parametrize("convention", CONVENTIONS)
@pytest.mark.parametrize("case", sorted(CASES))
def test_every_pose_from_the_arms_fk_gets_its_generating_vector_back(case, convention):
    structure = CASES[case][0]
    for seed in (11, 12):
        robot = random_three_parallel_arm(case, convention, seed)
        plan = cached_plan(robot, constrain_orientation=True, reference=None)
        assert plan is not None and plan.structure == structure
        q = np.random.default_rng(seed).uniform(-np.pi, np.pi, (POSES // 2, 6))
        targets = forward_kinematics(robot, q)
        found = solve_ik_arrays(robot, targets)
        assert found.structure == structure
        assert (found.count >= 1).all()  # no pose of the arm's own FK is unreachable
        assert found.count.max() <= plan.generic_count == 8
        assert _hits(robot, found.joints, found.valid, q, SAME).all()
        assert _fk_misses(robot, found.joints, found.valid, targets).max() <= 1e-9


@pytest.mark.parametrize("case", sorted(CASES))
def test_single_poses_are_complete_and_analytic(case):
    """One pose at a time (the path a single request takes): complete, analytic, the generating vector back."""
    robot = random_three_parallel_arm(case, "modified", seed=21)
    q = np.random.default_rng(21).uniform(-np.pi, np.pi, (25, 6))
    for row, T in zip(q, forward_kinematics(robot, q)):
        result = solve_ik(robot, T)
        assert result.status == "ok" and result.complete and result.method == "analytic"
        assert result.structure == CASES[case][0]
        solutions = np.array([s.joints for s in result.solutions])
        assert _hits(robot, solutions[None], np.ones((1, len(solutions)), bool), row[None], SAME).all()


def _in_line_value(robot: Robot, middle: int) -> float:
    """The value of the middle parallel joint that puts the three parallel axes in one plane, stretched."""
    model = geometry_of(robot).model
    w = model.directions[middle]
    def planar(x):
        return x - (x @ w) * w
    beyond = planar(model.points[middle + 1] - model.points[middle])
    before = planar(model.points[middle] - model.points[middle - 1])
    return float(np.arctan2(np.cross(beyond, before) @ w, beyond @ before))


@pytest.mark.parametrize("case", sorted(CASES))
def test_stretched_and_folded_poses_report_the_elbow_and_keep_their_vector(case):
    robot = random_three_parallel_arm(case, "standard", seed=31)
    middle = CASES[case][3]
    rng = np.random.default_rng(31)
    q = rng.uniform(-np.pi, np.pi, (200, 6))
    stretched = _in_line_value(robot, middle)
    q[:100, middle] = stretched
    q[100:, middle] = stretched + np.pi
    targets = forward_kinematics(robot, q)
    found = solve_ik_arrays(robot, targets)
    assert (found.count >= 1).all()
    # a double root is known to about the square root of the error upstream of it: subproblem 6's roots are
    # good to ~1e-12 rad in the chain, so the two elbow roots may split by ~1e-5 rad (both FK-verified to 1e-9)
    assert _hits(robot, found.joints, found.valid, q, 1e-4).all()
    assert _fk_misses(robot, found.joints, found.valid, targets).max() <= 1e-9
    kinds = [{s.relation for s in found.singularities[row] if s.kind == "elbow"} for row in range(len(q))]
    assert all(k <= {"stretched"} for k in kinds[:100]) and all(k <= {"folded"} for k in kinds[100:])
    assert all(kinds)


@pytest.mark.parametrize("case", sorted(CASES))
def test_poses_with_joints_at_special_values_are_reached(case):
    """Joints snapped to 0, ±π/2, π (singular and special poses): never unreachable, every solution verified,
    and the generating vector back wherever no joint was reported free."""
    robot = random_three_parallel_arm(case, "khalil", seed=41)
    rng = np.random.default_rng(41)
    q = rng.uniform(-np.pi, np.pi, (400, 6))
    snap = rng.random(q.shape) < 0.4
    q[snap] = rng.choice([0.0, np.pi / 2, -np.pi / 2, np.pi], snap.sum())
    targets = forward_kinematics(robot, q)
    found = solve_ik_arrays(robot, targets)
    assert (found.count >= 1).all()
    assert _fk_misses(robot, found.joints, found.valid, targets).max() <= 1e-9
    free = np.array([any(s.relation in ("free", "sum", "signed_sum") for s in found.singularities[row])
                     for row in range(len(q))])
    assert _hits(robot, found.joints, found.valid, q, 1e-6)[~free].all()


def test_the_ur_type_is_still_its_own_family():
    robot = random_three_parallel_arm("skew_wrist_234", "standard", seed=51)
    a = robot.a.copy()
    a[4] = 0.0
    joints = [Joint(j.name, j.kind, a[i], j.alpha, j.d, j.theta) for i, j in enumerate(robot.joints)]
    ur_like = Robot(joints, world_T_base=robot.world_T_base, flange_T_tool=robot.flange_T_tool)
    assert cached_plan(ur_like, constrain_orientation=True, reference=None).structure == "three_parallel"


@pytest.mark.parametrize("case", sorted(CASES))
def test_the_generic_count_of_eight_is_reached(case):
    """8 distinct FK-verified solutions for some pose of some arm of the class: the bound 4 × 2 is attained."""
    for seed in range(60, 70):
        robot = random_three_parallel_arm(case, "standard", seed)
        q = np.random.default_rng(seed).uniform(-np.pi, np.pi, (300, 6))
        if solve_ik_arrays(robot, forward_kinematics(robot, q)).count.max() == 8:
            return
    pytest.fail("no pose with 8 solutions")


def _labels_of_generating_vector(robot: Robot, q: np.ndarray) -> list[dict]:
    found = solve_ik_arrays(robot, forward_kinematics(robot, q))
    gap = np.abs(joint_difference(robot, found.joints, q[:, None, :])).max(axis=-1)
    slot = np.argmin(np.where(found.valid, gap, np.inf), axis=1)
    rows = np.arange(len(q))
    return [{name: values[codes[row, slot[row]]] for name, (values, codes) in found.labels.items()
             if codes[row, slot[row]] >= 0} for row in rows]


@pytest.mark.parametrize("case", sorted(CASES))
def test_branch_labels_mean_the_same_in_every_convention(case):
    q = np.random.default_rng(81).uniform(-np.pi, np.pi, (200, 6))
    labels = [_labels_of_generating_vector(random_three_parallel_arm(case, c, seed=81), q) for c in CONVENTIONS]
    assert labels[0] == labels[1] == labels[2]
    if CASES[case][1] == (0, 1):  # axes 1-3 along the base z: no up in their plane, so no elbow label
        assert not any("elbow" in row for row in labels[0])
    else:
        assert all("elbow" in row for row in labels[0])
        assert {row["elbow"] for row in labels[0]} == {"up", "down"}


UR_TABLES = json.loads((Path(__file__).resolve().parents[2] / "data" / "ur_dh_tables.json").read_text())


@pytest.mark.parametrize("name", sorted(UR_TABLES["arms"]))
def test_published_ur_tables_and_their_skew_wrist_variants(name):
    """The UR arms as Universal Robots publishes them (three_parallel), and the same arm with its wrist axes 5 and
    6 offset by a 2 cm link (three_parallel_skew_wrist): 1,000 poses each, every generating vector back."""
    table = UR_TABLES["arms"][name]
    for offset, structure in ((0.0, "three_parallel"), (0.02, "three_parallel_skew_wrist")):
        a = list(table["a"])
        a[4] = offset
        robot = Robot([Joint(f"j{i + 1}", "revolute", a[i], UR_TABLES["alpha"][i], table["d"][i], 0.0)
                       for i in range(6)])
        q = np.random.default_rng(91).uniform(-np.pi, np.pi, (POSES, 6))
        targets = forward_kinematics(robot, q)
        found = solve_ik_arrays(robot, targets)
        assert found.structure == structure
        assert (found.count >= 1).all() and _hits(robot, found.joints, found.valid, q, SAME).all()
        assert _fk_misses(robot, found.joints, found.valid, targets).max() <= 1e-9


@pytest.mark.parametrize("case", ["at_end_456", "at_base_123"])
def test_axis_one_parallel_to_the_triple_is_a_free_base_with_verified_representatives(case):
    """Where joints 2 and 3 turn the parallel axes 4–6 parallel to axis 1 (joints 4 and 5 turn axis 6 parallel
    to axes 1–3 in the base case), four axes are parallel: a one-parameter self-motion. Every such pose is
    reached, its solutions verified, and the singularity reported with the joints it frees."""
    from service.kinematics.ik.subproblems import subproblem_2_chain

    for seed in range(100, 140):
        robot = random_three_parallel_arm(case, "standard", seed)
        m = geometry_of(robot).model
        # (turning joint, turning joint, the axis turned, the axis it is turned parallel to)
        order = (1, 2, 3, 0) if case.startswith("at_end") else (3, 4, 5, 0)
        turn = subproblem_2_chain(m.directions[order[0]], m.directions[order[1]], m.directions[order[2]],
                                  m.directions[order[3]])
        if turn.exact[0]:
            break
    q = np.random.default_rng(seed).uniform(-np.pi, np.pi, (40, 6))
    q[:, order[0]], q[:, order[1]] = turn.theta1[0], turn.theta2[0]
    targets = forward_kinematics(robot, q)
    found = solve_ik_arrays(robot, targets, reference=np.full(6, 0.3))
    assert (found.count >= 1).all()
    assert _fk_misses(robot, found.joints, found.valid, targets).max() <= 1e-9
    freed = {(s.joints, s.relation) for row in range(len(q)) for s in found.singularities[row]}
    expected = (0, 3, 4, 5) if case.startswith("at_end") else (0, 1, 2, 5)
    assert (expected, "free") in freed


@pytest.mark.parametrize("case", sorted(CASES))
def test_a_sweep_towards_the_stretched_elbow_down_to_1e_12(case):
    """The middle parallel joint ε from stretched, ε = 1e-2 … 1e-12: always reached, every solution verified, and
    the generating vector back: exactly while the two elbow roots are apart, within the split of a double root
    (1e-4) once they are not."""
    robot = random_three_parallel_arm(case, "modified", seed=61)
    middle = CASES[case][3]
    q = np.random.default_rng(61).uniform(-np.pi, np.pi, (11, 6))
    q[:, middle] = _in_line_value(robot, middle) + 10.0 ** -np.arange(2, 13)
    targets = forward_kinematics(robot, q)
    found = solve_ik_arrays(robot, targets)
    assert (found.count >= 1).all()
    assert _fk_misses(robot, found.joints, found.valid, targets).max() <= 1e-9
    assert _hits(robot, found.joints[:3], found.valid[:3], q[:3], SAME).all()  # ε = 1e-2 … 1e-4
    assert _hits(robot, found.joints, found.valid, q, 1e-4).all()


def _axis_six_on_axis_one(robot: Robot, rng: np.random.Generator) -> np.ndarray | None:
    """A configuration whose axis 6 lies on axis 1 (Gauss–Newton on joints 2–5 from random starts), or None."""
    from service.kinematics.ik._screws import chain_rotation, move_point

    m = geometry_of(robot).model
    def residual(q):
        direction = chain_rotation(m.directions[:5], m.is_revolute[:5], q[None, :5])[0] @ m.directions[5]
        point = move_point(m.directions[:5], m.points[:5], m.is_revolute[:5], q[None, :5], m.points[5])[0]
        return np.r_[np.cross(direction, m.directions[0]), np.cross(point - m.points[0], m.directions[0])]
    for _ in range(30):
        q = rng.uniform(-np.pi, np.pi, 6)
        for _ in range(50):
            f = residual(q)
            J = np.stack([(residual(q + 1e-7 * np.eye(6)[j]) - f) / 1e-7 for j in range(1, 5)], 1)
            q[1:5] -= np.linalg.lstsq(J, f, rcond=None)[0]
        if np.abs(residual(q)).max() < 1e-13:
            return q
    return None


def test_axis_six_on_axis_one_frees_the_sum_of_joints_one_and_six():
    """The skew-wrist class's shoulder singularity: axis 6 on axis 1, where subproblem 6 leaves q1 free. q1 takes
    the reference value, q6 the rest of the sum, and the pose is reached."""
    robot = random_three_parallel_arm("skew_wrist_234", "standard", seed=0)
    q = _axis_six_on_axis_one(robot, np.random.default_rng(0))
    assert q is not None
    target = forward_kinematics(robot, q[None])
    found = solve_ik_arrays(robot, target, reference=np.full(6, 0.3))
    assert found.count[0] >= 1
    assert _fk_misses(robot, found.joints, found.valid, target).max() <= 1e-9
    assert np.allclose(found.joints[0, :found.count[0], 0], 0.3)
    flags = {(s.kind, s.joints, s.relation) for s in found.singularities[0]}
    assert flags & {("shoulder", (0, 5), "sum"), ("shoulder", (0, 5), "difference")}
