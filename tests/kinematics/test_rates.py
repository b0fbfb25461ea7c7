"""Joint rates for every arm: J̇ (analytic), the task rows, q̇ = J⁻¹v and q̈ = J⁻¹(a − J̇q̇), singular samples.

Independent references: central differences of the geometric Jacobian and of forward kinematics, Spong's
closed-form Jacobian of the planar RR arm (Example 3.1), and the normal equations of damped least squares.
"""

from __future__ import annotations

import doctest

import numpy as np
import pytest

from service.robots.catalogue import load_catalogue
from service.config import Settings
from service.kinematics import (Joint, Robot, _rates, forward_kinematics, geometric_jacobian, jacobian_derivative,
                                joint_rates, task_space)
from service.kinematics._rates import task_jacobian
from tests.arms import random_dh_robot

CATALOGUE = load_catalogue([Settings().builtin_robots_dir], max_joints=32)
ROBOT_IDS = sorted(entry.description.id for entry in CATALOGUE.entries())


def robot(robot_id: str) -> Robot:
    return CATALOGUE.get(robot_id).robot


def random_robot(rng: np.random.Generator, convention: str, kinds: str) -> Robot:
    """A random arm with base and tool transforms, so every term of the screw form is exercised."""
    joints = random_dh_robot(rng, convention, kinds).joints
    base, tool = np.eye(4), np.eye(4)
    base[:3, :3] = np.linalg.qr(rng.normal(size=(3, 3)))[0] * [1, 1, 1]
    if np.linalg.det(base[:3, :3]) < 0:
        base[:3, 0] *= -1
    base[:3, 3] = rng.uniform(-1, 1, 3)
    tool[:3, 3] = rng.uniform(-0.3, 0.3, 3)
    return Robot(joints, convention=convention, world_T_base=base, flange_T_tool=tool)


def jacobian_differences(arm: Robot, q: np.ndarray, qd: np.ndarray, h: float) -> np.ndarray:
    """Five-point central difference of J along q + s·q̇: d/dt J(q(t)) at q̇ (error O(h⁴))."""
    J = {k: geometric_jacobian(arm, q + k * h * qd) for k in (-2, -1, 1, 2)}
    return (-J[2] + 8 * J[1] - 8 * J[-1] + J[-2]) / (12 * h)


# ---------------------------------------------------------------------------
# J̇
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("robot_id", ROBOT_IDS)
def test_jacobian_derivative_matches_differences_of_the_jacobian_for_every_catalogue_robot(robot_id):
    arm = robot(robot_id)
    rng = np.random.default_rng(0)
    q = rng.uniform(-np.pi, np.pi, (50, arm.dof))
    qd = rng.uniform(-1, 1, (50, arm.dof))
    scale = max(1.0, arm.characteristic_length)
    # Measured worst: 3.8e-12 (robots in metres) and 3.2e-11 (the Assur SCARA, in mm).
    np.testing.assert_allclose(jacobian_derivative(arm, q, qd), jacobian_differences(arm, q, qd, 1e-3),
                               rtol=0, atol=1e-9 * scale)


@pytest.mark.parametrize("convention", ["standard", "modified", "khalil"])
@pytest.mark.parametrize("kinds", ["RRRRRR", "RPRRPR", "PRPRRP", "RRP"])
def test_jacobian_derivative_matches_differences_for_random_arms_with_base_and_tool(convention, kinds):
    rng = np.random.default_rng(len(kinds) + ord(convention[0]))
    arm = random_robot(rng, convention, kinds)
    q = rng.uniform(-np.pi, np.pi, (40, arm.dof))
    qd = rng.uniform(-2, 2, (40, arm.dof))
    np.testing.assert_allclose(jacobian_derivative(arm, q, qd), jacobian_differences(arm, q, qd, 1e-3),
                               rtol=0, atol=1e-9)


def test_jacobian_derivative_of_the_planar_arm_is_spongs_closed_form():
    """Spong Example 3.1: J_v = [[-a1 s1 - a2 s12, -a2 s12], [a1 c1 + a2 c12, a2 c12]], differentiated by hand."""
    a1, a2 = 1.0, 0.5
    arm = Robot([Joint("q1", "revolute", a1, 0, 0, 0), Joint("q2", "revolute", a2, 0, 0, 0)])
    rng = np.random.default_rng(1)
    for (q1, q2), (w1, w2) in zip(rng.uniform(-3, 3, (20, 2)), rng.uniform(-2, 2, (20, 2))):
        s1, c1, s12, c12 = np.sin(q1), np.cos(q1), np.sin(q1 + q2), np.cos(q1 + q2)
        expected = np.zeros((6, 2))
        expected[0] = [-a1 * c1 * w1 - a2 * c12 * (w1 + w2), -a2 * c12 * (w1 + w2)]
        expected[1] = [-a1 * s1 * w1 - a2 * s12 * (w1 + w2), -a2 * s12 * (w1 + w2)]
        np.testing.assert_allclose(jacobian_derivative(arm, [q1, q2], [w1, w2]), expected, rtol=0, atol=1e-14)


def test_jacobian_derivative_shapes_and_linearity_in_the_rates():
    arm = robot("puma560_modified")
    rng = np.random.default_rng(2)
    q, qd = rng.uniform(-2, 2, (7, 6)), rng.uniform(-1, 1, (7, 6))
    batch = jacobian_derivative(arm, q, qd)
    assert batch.shape == (7, 6, 6) and jacobian_derivative(arm, q[0], qd[0]).shape == (6, 6)
    np.testing.assert_allclose(jacobian_derivative(arm, q[3], qd[3]), batch[3], rtol=0, atol=1e-15)
    np.testing.assert_allclose(jacobian_derivative(arm, q, -2.5 * qd), -2.5 * batch, rtol=0, atol=1e-14)
    assert np.all(jacobian_derivative(arm, q, np.zeros_like(qd)) == 0.0)


# ---------------------------------------------------------------------------
# Task rows
# ---------------------------------------------------------------------------


@pytest.mark.parametrize(("robot_id", "orientation", "free", "names", "solve"), [
    ("puma560_modified", True, (), ("vx", "vy", "vz", "wx", "wy", "wz"), "exact"),
    ("ur5", True, (), ("vx", "vy", "vz", "wx", "wy", "wz"), "exact"),
    ("puma560_modified", False, (3, 4, 5), ("vx", "vy", "vz"), "exact"),
    ("spong_ex3_6_scara_rrpr", True, (), ("vx", "vy", "vz", "wz"), "exact"),
    ("spong_ex3_6_scara_rrpr", False, (3,), ("vx", "vy", "vz"), "exact"),
    ("assur001_scara_rrp", False, (), ("vx", "vy", "vz"), "exact"),
    ("assur001_scara_rrp", True, (), ("vx", "vy", "vz", "wz"), "least_squares"),
    ("spong_ex3_1_planar_rr", False, (), ("vx", "vy"), "exact"),
    ("spong_ex3_1_planar_rr", True, (), ("vx", "vy", "wz"), "least_squares"),
    ("spong_ex3_2_cylindrical_rpp", False, (), ("vx", "vy", "vz"), "exact"),
    ("ex004_3_spherical_rrpr", True, (), ("vx", "vy", "vz", "wx", "wy", "wz"), "least_squares"),
])
def test_task_rows_follow_the_documented_rule(robot_id, orientation, free, names, solve):
    task = task_space(robot(robot_id), constrain_orientation=orientation, free_joints=free)
    assert task.names == names and task.solve == solve
    assert list(task.columns) == [i for i in range(robot(robot_id).dof) if i not in free]
    np.testing.assert_allclose(task.basis @ task.basis.T, np.eye(len(names)), atol=1e-15)


def test_task_rows_of_a_tilted_scara_are_along_its_axis():
    """A SCARA whose axes are tilted: the angular row is ω·u with u the (up-pointing) axis, named by it."""
    base = np.eye(4)
    c, s = np.cos(0.4), np.sin(0.4)
    base[:3, :3] = [[1, 0, 0], [0, c, -s], [0, s, c]]
    scara = Robot([Joint("t1", "revolute", 1.0, 0, 0, 0), Joint("t2", "revolute", 0.8, np.pi, 0, 0),
                   Joint("d3", "prismatic", 0, 0, 0, 0), Joint("t4", "revolute", 0, 0, 0.2, 0)], world_T_base=base)
    task = task_space(scara, constrain_orientation=True)
    np.testing.assert_allclose(task.basis[3], [0, 0, 0, 0, -s, c], atol=1e-15)
    assert task.names[3] == "w·[0, -0.389418, 0.921061]"


# ---------------------------------------------------------------------------
# Rates
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("robot_id", ["puma560_modified", "ur5", "spong_ex3_5_stanford", "spong_ex3_6_scara_rrpr",
                                      "assur001_scara_rrp", "spong_ex3_1_planar_rr", "ex004_3_spherical_rrpr"])
@pytest.mark.parametrize("orientation", [True, False])
def test_velocities_and_accelerations_come_back_from_the_twist_they_produce(robot_id, orientation):
    """v = J q̇ and a = J q̈ + J̇ q̇ (J̇ by differences of J, not by the code under test) give q̇ and q̈ back.

    This holds for least squares too: a twist the arm produces is reproduced exactly.
    """
    arm = robot(robot_id)
    free = tuple(range(3, arm.dof)) if not orientation else ()
    task = task_space(arm, constrain_orientation=orientation, free_joints=free)
    rng = np.random.default_rng(3)
    q = rng.uniform(-2.5, 2.5, (30, arm.dof))
    q[:, ~arm.is_revolute] = rng.uniform(0.2, 0.6, (30, (~arm.is_revolute).sum())) * arm.characteristic_length
    qd, qdd = rng.uniform(-1, 1, (2, 30, arm.dof))
    qd[:, list(free)] = 0.0
    qdd[:, list(free)] = 0.0
    J = geometric_jacobian(arm, q)
    twist = np.einsum("nij,nj->ni", J, qd)
    accel = np.einsum("nij,nj->ni", J, qdd) + np.einsum("nij,nj->ni", jacobian_differences(arm, q, qd, 1e-3), qd)
    rates = joint_rates(arm, q, twist, accel, task, tolerance=1e-6)
    ok = ~rates.singular
    assert ok.sum() >= 25
    scale = np.where(arm.is_revolute, 1.0, arm.characteristic_length)
    worst = np.abs(rates.velocities[ok] - qd[ok]) / scale / np.maximum(1.0, 1.0 / rates.distance[ok, None])
    assert worst.max() < 1e-12
    worst = np.abs(rates.accelerations[ok] - qdd[ok]) / scale / np.maximum(1.0, 1.0 / rates.distance[ok, None])
    assert worst.max() < 1e-8  # the differences of J carry ~1e-10 of error
    assert np.nanmax(rates.velocity_residual[ok]) < 1e-13
    assert np.all(np.isnan(rates.velocities[~ok]))


def test_missing_rows_are_not_needed_for_a_position_target():
    """A position-only target needs only the linear part: an angular part of NaN is fine and not checked."""
    arm = robot("assur001_scara_rrp")
    task = task_space(arm, constrain_orientation=False)
    q = np.array([[0.3, -1.2, 80.0]])
    twist = np.concatenate([geometric_jacobian(arm, q)[0, :3] @ [0.1, 0.2, -3.0], [np.nan] * 3])[None]
    rates = joint_rates(arm, q, twist, None, task)
    np.testing.assert_allclose(rates.velocities[0], [0.1, 0.2, -3.0], rtol=1e-13)
    assert np.isnan(rates.accelerations).all() and np.isnan(rates.acceleration_residual).all()
    twist[0, 0] = np.nan  # a needed component missing: no rates for that sample
    assert np.isnan(joint_rates(arm, q, twist, None, task).velocities).all()


def planar_sigma_min(q2: float, a1: float = 1.0, a2: float = 0.5) -> float:
    """Smallest singular value of Spong's planar J_v (position rows) divided by L = a1 + a2, at q1 = 0."""
    J = np.array([[-a2 * np.sin(q2), -a2 * np.sin(q2)], [a1 + a2 * np.cos(q2), a2 * np.cos(q2)]])
    return float(np.linalg.svd(J / (a1 + a2), compute_uv=False)[-1])


def test_distance_to_a_singularity_of_the_planar_arm_and_the_singular_flag():
    arm = robot("spong_ex3_1_planar_rr")
    task = task_space(arm, constrain_orientation=False)
    q2 = np.array([1.0, 0.1, 1e-3, 1e-4, 0.0, -0.3])  # σ_min ≈ 0.21·|q2| near 0
    q = np.stack([np.zeros_like(q2), q2], axis=-1)
    twist = np.tile([0.0, 0.2, 0.0, np.nan, np.nan, np.nan], (len(q2), 1))
    rates = joint_rates(arm, q, twist, None, task, tolerance=1e-4)
    np.testing.assert_allclose(rates.distance, [planar_sigma_min(v) for v in q2], rtol=1e-12, atol=1e-17)
    np.testing.assert_array_equal(rates.singular, [False, False, False, True, True, False])
    assert np.isnan(rates.velocities[rates.singular]).all() and not rates.damped.any()
    assert np.isfinite(rates.velocities[~rates.singular]).all()


def test_damped_least_squares_only_when_asked_and_only_at_singular_samples():
    arm = robot("spong_ex3_1_planar_rr")
    task = task_space(arm, constrain_orientation=False)
    q = np.array([[0.0, 0.0], [0.0, 1e-5], [0.4, 1.2]])
    twist = np.array([[0.0, 0.3, 0.2, np.nan, np.nan, np.nan]] * 3)  # v_z is not a task row: ignored
    accel = np.array([[0.1, -0.2, 0.0, np.nan, np.nan, np.nan]] * 3)
    lam = 0.05
    rates = joint_rates(arm, q, twist, accel, task, damping=lam)
    np.testing.assert_array_equal(rates.damped, [True, True, False])
    Js = task_jacobian(arm, geometric_jacobian(arm, q), task)
    L = arm.characteristic_length
    for row in (0, 1):  # the normal equations of min ‖Js y − b‖² + λ²‖y‖²
        y = np.linalg.solve(Js[row].T @ Js[row] + lam**2 * np.eye(2), Js[row].T @ (twist[row, :2] / L))
        np.testing.assert_allclose(rates.velocities[row], y, rtol=1e-12)
        b = (accel[row, :3] - jacobian_derivative(arm, q[row], y)[:3] @ y)[:2] / L
        np.testing.assert_allclose(rates.accelerations[row],
                                   np.linalg.solve(Js[row].T @ Js[row] + lam**2 * np.eye(2), Js[row].T @ b),
                                   rtol=1e-12)
    exact = np.linalg.solve(geometric_jacobian(arm, q[2])[:2], twist[2, :2])
    np.testing.assert_allclose(rates.velocities[2], exact, rtol=1e-13)
    assert rates.velocity_residual[0] > 1e-3  # the damped answer does not reproduce the twist, and says so


def test_docstring_examples():
    assert doctest.testmod(_rates, raise_on_error=False).failed == 0


# ---------------------------------------------------------------------------
# Along smooth paths: rates against central differences of the position IK
# ---------------------------------------------------------------------------

#: robot id → (start configuration, rotation axes k1, k2 of the path's orientation (k2 None: about k1 only)).
SMOOTH_PATHS = {
    "puma560_modified": ([0.3, -0.6, 0.4, 0.5, 0.8, -0.3], [0, 0, 1], [1, 0, 0]),
    "ur5": ([0.3, -1.0, 1.2, -0.6, 1.1, 0.4], [0, 0, 1], [1, 0, 0]),
    "spong_ex3_5_stanford": ([0.3, 0.9, 0.8, 0.5, 0.8, -0.3], [0, 0, 1], [1, 0, 0]),
    "spong_ex3_6_scara_rrpr": ([0.4, -0.9, 0.3, 0.5], [0, 0, 1], None),  # a SCARA turns about z only
}

#: Worst disagreement measured (25 points of t in [0, 6] s, h = 1e-3 s, five-point stencils; rad/s, rad/s²,
#: m/s, m/s²): velocities ≤ 1.0e-12, accelerations ≤ 3.6e-9 (rounding of the second difference, ~eps·|q|/h²).
#:   puma560_modified        q̇ 6.0e-13   q̈ 2.1e-9
#:   ur5                     q̇ 1.0e-12   q̈ 3.6e-9
#:   spong_ex3_5_stanford    q̇ 6.3e-13   q̈ 1.9e-9
#:   spong_ex3_6_scara_rrpr  q̇ 9.0e-13   q̈ 2.4e-9
FD_STEP = 1e-3


@pytest.mark.parametrize("robot_id", sorted(SMOOTH_PATHS))
def test_rates_along_a_smooth_path_match_differences_of_the_position_ik(robot_id):
    """The path has an exact twist and acceleration (tests/oracles/paths.py); positions come from the IK alone.

    Each of 25 points t is surrounded by t ± h, t ± 2h in one trajectory, so the branch is the same for all
    five; q̇ and q̈ at t are compared with the five-point differences of the joint positions.
    """
    from service.kinematics import TrajectoryOptions, follow_trajectory
    from tests.oracles.paths import wobble

    arm = robot(robot_id)
    q0, k1, k2 = SMOOTH_PATHS[robot_id]
    centres = np.linspace(0.0, 6.0, 25)
    times = (centres[:, None] + FD_STEP * np.arange(-2, 3)).ravel()
    poses, twists, accelerations = wobble(times, forward_kinematics(arm, np.array(q0)),
                                          0.04 * arm.characteristic_length, k1, k2)
    result = follow_trajectory(arm, times, poses, twists=twists, accelerations=accelerations,
                               options=TrajectoryOptions(reference=np.array(q0)))
    assert result.rates == "jacobian" and result.task.solve == "exact"
    assert not result.summary.singular_samples and not result.summary.branch_changes
    q = np.array([s.joints for s in result.samples]).reshape(25, 5, arm.dof)
    centre = [s for k, s in enumerate(result.samples) if k % 5 == 2]
    qd = np.array([s.velocities for s in centre])
    qdd = np.array([s.accelerations for s in centre])
    h = FD_STEP
    first = (-q[:, 4] + 8 * q[:, 3] - 8 * q[:, 1] + q[:, 0]) / (12 * h)
    second = (-q[:, 4] + 16 * q[:, 3] - 30 * q[:, 2] + 16 * q[:, 1] - q[:, 0]) / (12 * h * h)
    assert np.abs(qd).max() > 0.1 and np.abs(qdd).max() > 0.1  # the path really moves every sample
    assert np.abs(first - qd).max() < 1e-11
    assert np.abs(second - qdd).max() < 2e-8
    assert max(s.velocity_residual for s in centre) < 1e-14
    assert max(s.acceleration_residual for s in centre) < 1e-14
