"""Tests of the RRR Assur group and the SCARA built on it (textbook.md §4).

Golden data: ``tests/data/assur_spiral_tables.json``, the two tables of
textbook.md §4.4 transcribed verbatim (6 significant digits).
"""

from __future__ import annotations

import doctest
import json
from pathlib import Path

import numpy as np
import pytest

from service.kinematics import InvalidInputError, _assur, _assur_functions
from service.kinematics._assur import (
    RRRCase,
    angle_function,
    assur_scara_forward,
    assur_scara_inverse,
    distance_function,
    rrr_group,
)
from service.kinematics._tolerances import SINGULARITY_TOLERANCE
from tests.ik_helpers import wrapped
from tests.oracles.paths import spiral

DATA = json.loads((Path(__file__).resolve().parents[1] / "data" / "assur_spiral_tables.json").read_text())
L_OA = float(DATA["lengths_mm"]["l_OA"])
L_AB = float(DATA["lengths_mm"]["l_AB"])
L_BC = float(DATA["lengths_mm"]["l_BC"])
COLUMNS = DATA["columns"][1:]  # theta1 ... l3dd, attribute names of AssurScaraSolution

# The tables are printed to 6 significant digits, so a printed value v carries
# a rounding error of up to 5e-6·|v| (e.g. 1.38218 ± 5e-6). Compare with
# |actual - expected| <= 1e-6 + 5e-6·|expected|: the absolute term covers
# values below 1 (0.305078 ± 5e-7) and the printed zeros.
TABLE_ATOL = 1e-6
TABLE_RTOL = 5e-6


def solve_spiral(t, mode):
    D, Dd, Ddd = spiral(t)
    return assur_scara_inverse(D, Dd, Ddd, L_OA, L_AB, L_BC, mode)


def test_spiral_path_in_data_file_is_the_one_tested():
    path = DATA["path"]
    assert (path["x_D"], path["y_D"], path["z_D"]) == ("100 + 20*sin(pi*t/2)", "-20*cos(pi*t/2)", "50 + 10*t")
    assert (L_OA, L_AB, L_BC) == (150.0, 80.0, 50.0)


# ---------------------------------------------------------------------------
# Golden tables (textbook.md §4.4)
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("mode", [1, 2])
def test_spiral_table_all_columns(mode):
    rows = np.array(DATA["tables"][f"mode_{mode}"]["rows"], dtype=float)
    assert rows.shape == (9, 10)
    np.testing.assert_array_equal(rows[:, 0], np.arange(9.0))
    solution = solve_spiral(rows[:, 0], mode)  # one batched call, N = 9
    assert np.all(solution.regular)
    for j, name in enumerate(COLUMNS, start=1):
        np.testing.assert_allclose(
            getattr(solution, name), rows[:, j], rtol=TABLE_RTOL, atol=TABLE_ATOL, err_msg=f"column {name}"
        )
    # Values below 1e-13 were printed as 0: hold the printed zeros to that.
    actual = np.stack([getattr(solution, name) for name in COLUMNS], axis=-1)
    assert np.all(np.abs(actual[rows[:, 1:] == 0.0]) < 1e-12)


@pytest.mark.parametrize("mode", [1, 2])
def test_spiral_forward_of_inverse_reproduces_path(mode):
    t = np.linspace(0.0, 8.0, 801)
    D, _, _ = spiral(t)
    solution = solve_spiral(t, mode)
    assert np.all(solution.regular)
    D_back = assur_scara_forward(solution.theta1, solution.theta2, solution.l3, L_OA, L_AB, L_BC)
    np.testing.assert_allclose(D_back, D, rtol=0, atol=1e-12)
    # The elbow lies at l_AB from the shoulder axis and l_BC from C.
    np.testing.assert_allclose(np.linalg.norm(solution.B, axis=-1), L_AB, rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(D[:, :2] - solution.B, axis=-1), L_BC, rtol=0, atol=1e-12)
    # Constant sign of theta2 in each mode along the whole path.
    assert np.all(np.sign(solution.theta2) == (1.0 if mode == 1 else -1.0))


def test_batched_equals_one_sample_at_a_time():
    t = np.array([0.0, 0.37, 1.0, 2.5, 7.9])
    D, Dd, Ddd = spiral(t)
    batch = assur_scara_inverse(D, Dd, Ddd, L_OA, L_AB, L_BC, 1)
    for i in range(len(t)):
        single = assur_scara_inverse(D[i], Dd[i], Ddd[i], L_OA, L_AB, L_BC, 1)
        assert single.theta1.shape == ()
        np.testing.assert_allclose(single.q, batch.q[i], rtol=0, atol=1e-15)
        np.testing.assert_allclose(single.qd, batch.qd[i], rtol=0, atol=1e-14)
        np.testing.assert_allclose(single.qdd, batch.qdd[i], rtol=0, atol=1e-13)


# ---------------------------------------------------------------------------
# Derivatives: finite differences and an independent Jacobian solution
# ---------------------------------------------------------------------------

def spiral_differences(t, mode, h, stencil):
    """Central differences of the position solution q(t) = (θ1, θ2, l3) along the spiral.

    stencil 3: (q(t+h) - q(t-h))/2h and (q(t+h) - 2q(t) + q(t-h))/h², errors
    O(h²) in truncation plus ~eps·|q|/h and ~4·eps·|q|/h² in rounding.
    stencil 5: the fourth-order five-point formulas, errors O(h⁴).
    """
    q = {k: solve_spiral(t + k * h, mode).q for k in (-2, -1, 0, 1, 2)}
    if stencil == 3:
        return (q[1] - q[-1]) / (2 * h), (q[1] - 2 * q[0] + q[-1]) / h**2
    first = (-q[2] + 8 * q[1] - 8 * q[-1] + q[-2]) / (12 * h)
    second = (-q[2] + 16 * q[1] - 30 * q[0] + 16 * q[-1] - q[-2]) / (12 * h * h)
    return first, second


# (stencil, step for q', tolerance for q', step for q'', tolerance for q'').
# Measured worst disagreements on 801 points of t in [0, 8], both modes:
# 3-point: 1.1e-9 (q', h = 1e-5) and 3.2e-7 (q'', h = 3e-4, rounding of l3 ~ 100 mm);
# 5-point: 2.4e-11 (q', h = 1e-3) and 2.7e-9 (q'', h = 5e-3).
FD_CASES = [(3, 1e-5, 1e-8, 3e-4, 1e-6), (5, 1e-3, 1e-10, 5e-3, 1e-8)]


@pytest.mark.parametrize(("stencil", "h1", "tol1", "h2", "tol2"), FD_CASES)
@pytest.mark.parametrize("mode", [1, 2])
def test_spiral_derivatives_match_central_finite_differences(mode, stencil, h1, tol1, h2, tol2):
    t = np.linspace(0.0, 8.0, 801)
    exact = solve_spiral(t, mode)
    qd_fd, _ = spiral_differences(t, mode, h1, stencil)
    _, qdd_fd = spiral_differences(t, mode, h2, stencil)
    np.testing.assert_allclose(exact.qd, qd_fd, rtol=0, atol=tol1)
    np.testing.assert_allclose(exact.qdd, qdd_fd, rtol=0, atol=tol2)


def scara_jacobian(q, qd):
    """J = dD/dq and its time derivative for D = FK(θ1, θ2, l3), paper convention."""
    a, b = L_AB, L_BC
    t1, t2 = q[..., 0], q[..., 1]
    w1, w12 = qd[..., 0], qd[..., 0] - qd[..., 1]
    s1, c1 = np.sin(t1), np.cos(t1)
    s12, c12 = np.sin(t1 - t2), np.cos(t1 - t2)
    zero = np.zeros_like(t1)
    J = np.stack(
        (
            np.stack((-a * s1 - b * s12, b * s12, zero), axis=-1),
            np.stack((a * c1 + b * c12, -b * c12, zero), axis=-1),
            np.stack((zero, zero, zero - 1.0), axis=-1),
        ),
        axis=-2,
    )
    Jd = np.stack(
        (
            np.stack((-a * c1 * w1 - b * c12 * w12, b * c12 * w12, zero), axis=-1),
            np.stack((-a * s1 * w1 - b * s12 * w12, b * s12 * w12, zero), axis=-1),
            np.stack((zero, zero, zero), axis=-1),
        ),
        axis=-2,
    )
    return J, Jd


def jacobian_rates(q, Dd, Ddd):
    """q' = J⁻¹ D', q'' = J⁻¹ (D'' - J' q'), computed independently of the group."""
    J, _ = scara_jacobian(q, np.zeros_like(q))
    qd = np.linalg.solve(J, Dd[..., None])[..., 0]
    _, Jd = scara_jacobian(q, qd)
    qdd = np.linalg.solve(J, (Ddd - np.einsum("...ij,...j->...i", Jd, qd))[..., None])[..., 0]
    return qd, qdd


@pytest.mark.parametrize("mode", [1, 2])
def test_spiral_derivatives_match_jacobian_solution(mode):
    t = np.linspace(0.0, 8.0, 801)
    D, Dd, Ddd = spiral(t)
    solution = assur_scara_inverse(D, Dd, Ddd, L_OA, L_AB, L_BC, mode)
    qd, qdd = jacobian_rates(solution.q, Dd, Ddd)
    np.testing.assert_allclose(solution.qd, qd, rtol=0, atol=1e-12)
    np.testing.assert_allclose(solution.qdd, qdd, rtol=0, atol=1e-12)


@pytest.mark.parametrize("mode", [1, 2])
def test_random_targets_derivatives_match_jacobian_solution(mode):
    rng = np.random.default_rng(0)
    n = 500
    radius = rng.uniform(31.0, 129.0, n)
    angle = rng.uniform(-np.pi, np.pi, n)
    D = np.stack((radius * np.cos(angle), radius * np.sin(angle), rng.uniform(0.0, 140.0, n)), axis=-1)
    Dd = rng.normal(0.0, 50.0, (n, 3))
    Ddd = rng.normal(0.0, 200.0, (n, 3))
    solution = assur_scara_inverse(D, Dd, Ddd, L_OA, L_AB, L_BC, mode)
    assert np.all(solution.regular)
    qd, qdd = jacobian_rates(solution.q, Dd, Ddd)
    np.testing.assert_allclose(solution.qd, qd, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(solution.qdd, qdd, rtol=1e-9, atol=1e-9)


def test_group_with_both_outer_joints_moving_matches_finite_differences():
    # The SCARA keeps A fixed; here A moves too, so the A' and A'' terms of
    # eqs. 7-8 and the relative derivatives of Figs. 2-3 are exercised.
    def paths(t):
        A = np.stack((1.0 + 0.3 * np.sin(t), -0.5 + 0.2 * np.cos(1.7 * t)), axis=-1)
        Ad = np.stack((0.3 * np.cos(t), -0.34 * np.sin(1.7 * t)), axis=-1)
        Add = np.stack((-0.3 * np.sin(t), -0.578 * np.cos(1.7 * t)), axis=-1)
        B = np.stack((4.0 + np.cos(0.8 * t), 1.0 + 0.5 * np.sin(1.3 * t)), axis=-1)
        Bd = np.stack((-0.8 * np.sin(0.8 * t), 0.65 * np.cos(1.3 * t)), axis=-1)
        Bdd = np.stack((-0.64 * np.cos(0.8 * t), -0.845 * np.sin(1.3 * t)), axis=-1)
        return A, Ad, Add, B, Bd, Bdd

    t = np.linspace(0.0, 10.0, 201)
    h1, h2 = 1e-5, 1e-4
    for mode in (1, 2):
        def group(tt):
            return rrr_group(*paths(tt), 3.0, 2.5, mode)

        s = group(t)
        assert np.all(s.regular)
        np.testing.assert_allclose(np.linalg.norm(s.C - paths(t)[0], axis=-1), 3.0, atol=1e-13)
        np.testing.assert_allclose(np.linalg.norm(s.C - paths(t)[3], axis=-1), 2.5, atol=1e-13)
        plus1, minus1, plus2, minus2 = group(t + h1), group(t - h1), group(t + h2), group(t - h2)
        for pos, vel, acc in (("C", "Cd", "Cdd"), ("phi", "phid", "phidd"), ("beta", "betad", "betadd")):
            fd1 = (getattr(plus1, pos) - getattr(minus1, pos)) / (2 * h1)
            fd2 = (getattr(plus2, pos) - 2 * getattr(s, pos) + getattr(minus2, pos)) / h2**2
            np.testing.assert_allclose(getattr(s, vel), fd1, rtol=0, atol=1e-8, err_msg=vel)
            np.testing.assert_allclose(getattr(s, acc), fd2, rtol=0, atol=1e-6, err_msg=acc)


def test_angle_and_distance_functions_match_finite_differences_across_x_zero():
    # The vector sweeps through x = 0 (both signs of y) and through every quadrant.
    def vec(t):
        x = 2.0 * np.cos(t) + 0.3 * np.sin(3.0 * t)
        y = 1.5 * np.sin(t) + 0.2
        xd = -2.0 * np.sin(t) + 0.9 * np.cos(3.0 * t)
        yd = 1.5 * np.cos(t)
        xdd = -2.0 * np.cos(t) - 2.7 * np.sin(3.0 * t)
        ydd = -1.5 * np.sin(t)
        return x, y, xd, yd, xdd, ydd

    t = np.linspace(0.05, 6.2, 300)
    h1, h2 = 1e-5, 1e-4
    r = angle_function(*vec(t))

    def theta(tt):
        return np.arctan2(vec(tt)[1], vec(tt)[0])

    fd1 = wrapped(theta(t + h1) - theta(t - h1)) / (2 * h1)
    fd2 = (wrapped(theta(t + h2) - theta(t)) - wrapped(theta(t) - theta(t - h2))) / h2**2
    np.testing.assert_allclose(r.thetad, fd1, rtol=0, atol=1e-8)
    np.testing.assert_allclose(r.thetadd, fd2, rtol=0, atol=1e-5)

    x, y, xd, yd, xdd, ydd = vec(t)
    zero = np.zeros_like(t)
    Pt = np.stack((x, y), axis=-1)
    origin = np.stack((zero, zero), axis=-1)
    dist = distance_function(origin, origin, origin, Pt, np.stack((xd, yd), -1), np.stack((xdd, ydd), -1))

    def length(tt):
        return np.hypot(vec(tt)[0], vec(tt)[1])

    np.testing.assert_allclose(dist.l, length(t), atol=1e-15)
    np.testing.assert_allclose(dist.ld, (length(t + h1) - length(t - h1)) / (2 * h1), rtol=0, atol=1e-8)
    fd2_l = (length(t + h2) - 2 * length(t) + length(t - h2)) / h2**2
    np.testing.assert_allclose(dist.ldd, fd2_l, rtol=0, atol=1e-6)


# ---------------------------------------------------------------------------
# Assembly mode and sign of theta2
# ---------------------------------------------------------------------------


def test_mode_1_gives_positive_theta2_mode_2_negative_on_random_targets():
    rng = np.random.default_rng(0)
    n = 2000
    radius = rng.uniform(30.0 + 1e-3, 130.0 - 1e-3, n)
    angle = rng.uniform(-np.pi, np.pi, n)
    D = np.stack((radius * np.cos(angle), radius * np.sin(angle), rng.uniform(0.0, 150.0, n)), axis=-1)
    zero = np.zeros_like(D)
    for mode, sign in ((1, 1.0), (2, -1.0)):
        s = assur_scara_inverse(D, zero, zero, L_OA, L_AB, L_BC, mode)
        assert np.all(s.regular)
        assert np.all(np.sign(s.theta2) == sign)
        assert np.all((s.theta2 > -np.pi) & (s.theta2 <= np.pi))
        D_back = assur_scara_forward(s.theta1, s.theta2, s.l3, L_OA, L_AB, L_BC)
        np.testing.assert_allclose(D_back, D, rtol=0, atol=1e-11)


def test_two_modes_are_mirror_images_about_the_line_to_the_target():
    D = np.array([[70.0, 40.0, 80.0]])
    zero = np.zeros_like(D)
    m1 = assur_scara_inverse(D, zero, zero, L_OA, L_AB, L_BC, 1)
    m2 = assur_scara_inverse(D, zero, zero, L_OA, L_AB, L_BC, 2)
    direction = np.arctan2(40.0, 70.0)
    np.testing.assert_allclose(m1.theta1 - direction, direction - m2.theta1, atol=1e-14)
    np.testing.assert_allclose(m1.theta2, -m2.theta2, atol=1e-14)


# ---------------------------------------------------------------------------
# Singular and special cases of the group
# ---------------------------------------------------------------------------


def _still(n):
    return np.zeros((n, 2))


def test_group_aligned_stretched_gives_c_and_flags_derivatives():
    rng = np.random.default_rng(0)
    n = 50
    direction = rng.uniform(-np.pi, np.pi, n)
    unit = np.stack((np.cos(direction), np.sin(direction)), axis=-1)
    A = rng.normal(0.0, 10.0, (n, 2))
    B = A + (L_AB + L_BC) * unit
    velocity = rng.normal(0.0, 5.0, (n, 2))
    s = rrr_group(A, velocity, _still(n), B, velocity, _still(n), L_AB, L_BC, 1)
    assert np.all(s.case == RRRCase.ALIGNED)
    assert np.all(s.aligned & s.singular & ~s.regular)
    np.testing.assert_allclose(s.beta, 0.0, atol=0)
    np.testing.assert_allclose(s.C, A + L_AB * unit, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(B - s.C, axis=-1), L_BC, atol=1e-12)
    for name in ("betad", "betadd", "phid", "phidd", "Cd", "Cdd"):
        assert np.all(np.isnan(getattr(s, name))), name
    # theta and the distance are still defined.
    assert np.all(np.isfinite(s.thetad)) and np.all(np.isfinite(s.l_ABdd))


def test_group_aligned_folded_beta_zero_when_l_ac_longer():
    # |AB| = l_AC - l_BC: C is beyond B on the ray from A, beta = 0.
    A = np.array([[5.0, -3.0]])
    B = A + np.array([[0.0, L_AB - L_BC]])
    s = rrr_group(A, _still(1), _still(1), B, _still(1), _still(1), L_AB, L_BC, 2)
    assert s.case.tolist() == [RRRCase.ALIGNED]
    assert s.beta[0] == 0.0
    np.testing.assert_allclose(s.C, A + np.array([[0.0, L_AB]]), atol=1e-12)
    assert np.isnan(s.Cd).all() and np.isnan(s.Cdd).all()


def test_group_aligned_folded_beta_pi_when_l_ac_shorter():
    # |AB| = l_BC - l_AC: C is behind A, beta = pi, the same point in both modes.
    A = np.array([0.0, 0.0])
    B = np.array([2.0, 0.0])
    for mode in (1, 2):
        s = rrr_group(A, [0, 0], [0, 0], B, [1, 1], [0, 0], 3.0, 5.0, mode)
        assert int(s.case) == RRRCase.ALIGNED
        np.testing.assert_allclose(s.beta, np.pi, atol=0)
        np.testing.assert_allclose(s.C, [-3.0, 0.0], atol=1e-12)
        assert np.isnan(s.Cd).all()


def test_group_near_alignment_inside_tolerance_and_outside():
    A = np.zeros(2)
    reach = 7.0
    for scale, expected in (
        (1.0 + 1e-10, RRRCase.ALIGNED),  # outside by rounding-level amounts: clipped
        (1.0 - 1e-10, RRRCase.ALIGNED),
        (1.0 + 1e-4, RRRCase.UNREACHABLE),
        (1.0 - 1e-4, RRRCase.REGULAR),
    ):
        s = rrr_group(A, A, A, [reach * scale, 0.0], [0.0, 1.0], [0.0, 0.0], 3.0, 4.0, 1)
        assert int(s.case) == expected, scale
    # Just inside the band the derivatives are finite and large, not NaN.
    s = rrr_group(A, A, A, [reach * (1 - 1e-4), 0.0], [1.0, 0.0], [0.0, 0.0], 3.0, 4.0, 1)
    assert np.isfinite(s.betad) and abs(s.betad) > 10.0


def test_group_tolerance_band_is_the_documented_one():
    # 1 - |P/Q| just above / below SINGULARITY_TOLERANCE (l_AC = 3, l_BC = 4).
    A = np.zeros(2)
    for factor, expected in (
        (-3.0, RRRCase.REGULAR),
        (-0.3, RRRCase.ALIGNED),
        (0.3, RRRCase.ALIGNED),
        (3.0, RRRCase.UNREACHABLE),
    ):
        excess = factor * SINGULARITY_TOLERANCE
        u = 1.0 + excess
        # Solve (9 + l² - 16) / (6 l) = u for l > 0.
        l = 3.0 * u + np.sqrt(9.0 * u * u + 7.0)
        s = rrr_group(A, A, A, [l, 0.0], A, A, 3.0, 4.0, 1)
        assert int(s.case) == expected, excess
        np.testing.assert_allclose(s.cos_beta, u, rtol=0, atol=1e-14)


def test_group_coincident_points_with_equal_lengths():
    A = np.array([[1.0, 2.0], [1.0, 2.0]])
    B = A + np.array([[0.0, 0.0], [1e-12, 0.0]])  # exactly and numerically coincident
    s = rrr_group(A, _still(2), _still(2), B, [[1, 0], [1, 0]], _still(2), 5.0, 5.0, 1)
    assert s.case.tolist() == [RRRCase.COINCIDENT] * 2
    assert np.all(s.coincident & s.singular)
    for name in ("C", "Cd", "Cdd", "phi", "phid", "phidd", "beta", "theta"):
        assert np.all(np.isnan(getattr(s, name))), name
    np.testing.assert_allclose(s.l_AB, [0.0, 1e-12], rtol=0, atol=1e-15)


def test_group_coincident_points_with_unequal_lengths_is_unreachable():
    s = rrr_group([1.0, 2.0], [0, 0], [0, 0], [1.0, 2.0], [0, 0], [0, 0], 5.0, 4.0, 1)
    assert int(s.case) == RRRCase.UNREACHABLE
    assert np.isnan(s.C).all()


def test_group_unreachable_outside_and_inside_the_annulus():
    A = np.zeros((2, 2))
    B = np.array([[7.5, 0.0], [0.0, 0.5]])  # beyond l_AC + l_BC = 7; inside |l_AC - l_BC| = 1
    s = rrr_group(A, A, A, B, A, A, 3.0, 4.0, 2)
    assert s.case.tolist() == [RRRCase.UNREACHABLE] * 2
    assert np.all(s.unreachable & ~s.singular)
    assert s.cos_beta[0] > 1.0 and s.cos_beta[1] < -1.0
    for name in ("C", "Cd", "Cdd", "phi", "beta", "betad"):
        assert np.all(np.isnan(getattr(s, name))), name
    np.testing.assert_allclose(s.l_AB, [7.5, 0.5])
    np.testing.assert_allclose(s.theta, [0.0, np.pi / 2])


def test_group_mixed_batch_classifies_each_sample_and_leaves_regular_ones_alone():
    B = np.array([[6.0, 0.0], [10.0, 0.0], [0.0, 0.0], [11.0, 0.0]])
    Bd = np.array([[0.0, 1.0]] * 4)
    A = np.zeros(2)  # (2,) broadcasts against (4, 2)
    s = rrr_group(A, A, A, B, Bd, A, 5.0, 5.0, 1)
    assert s.C.shape == (4, 2) and s.phi.shape == (4,)
    assert s.case.tolist() == [RRRCase.REGULAR, RRRCase.ALIGNED, RRRCase.COINCIDENT, RRRCase.UNREACHABLE]
    single = rrr_group(A, A, A, B[0], Bd[0], A, 5.0, 5.0, 1)
    np.testing.assert_array_equal(s.C[0], single.C)
    np.testing.assert_array_equal(s.Cdd[0], single.Cdd)
    np.testing.assert_allclose(s.C[0], [3.0, 4.0], atol=1e-14)
    np.testing.assert_allclose(s.C[1], [5.0, 0.0], atol=1e-14)


def test_angle_function_null_vector_is_flagged():
    r = angle_function([0.0, 1e-12, 1e-6, 0.0], [0.0, 0.0, 0.0, -3.0], 1.0, 2.0, 0.0, 0.0)
    assert r.is_null.tolist() == [True, True, False, False]
    assert np.isnan(r.theta[:2]).all() and np.isnan(r.thetad[:2]).all() and np.isnan(r.thetadd[:2]).all()
    np.testing.assert_allclose(r.theta[2:], [0.0, -np.pi / 2], atol=0)
    # With a zero tolerance only the exact null vector is flagged.
    assert angle_function(1e-12, 0.0, 0.0, 1e-12, 0.0, 0.0, tolerance=0.0).is_null.item() is False


def test_distance_function_zero_distance_is_flagged():
    r = distance_function([[1.0, 1.0], [1.0, 1.0]], [0, 0], [0, 0], [[1.0, 1.0], [4.0, 5.0]], [1, 0], [0, 0])
    assert r.is_zero.tolist() == [True, False]
    assert r.l[0] == 0.0 and np.isnan(r.ld[0]) and np.isnan(r.ldd[0])
    np.testing.assert_allclose([r.l[1], r.ld[1]], [5.0, 0.6])


# ---------------------------------------------------------------------------
# Singular cases of the SCARA
# ---------------------------------------------------------------------------


def test_scara_stretched_and_folded_are_aligned():
    angle = np.array([0.3, -2.0])
    unit = np.stack((np.cos(angle), np.sin(angle)), axis=-1)
    for reach, expected_abs_theta2 in ((L_AB + L_BC, 0.0), (L_AB - L_BC, np.pi)):
        D = np.concatenate((reach * unit, [[60.0], [70.0]]), axis=-1)
        Dd = np.tile([5.0, -3.0, 1.0], (2, 1))
        for mode in (1, 2):
            s = assur_scara_inverse(D, Dd, np.zeros_like(D), L_OA, L_AB, L_BC, mode)
            assert s.case.tolist() == [RRRCase.ALIGNED] * 2
            np.testing.assert_allclose(s.theta1, angle, atol=1e-12)
            np.testing.assert_allclose(np.abs(s.theta2), expected_abs_theta2, atol=1e-7)
            D_back = assur_scara_forward(s.theta1, s.theta2, s.l3, L_OA, L_AB, L_BC)
            np.testing.assert_allclose(D_back, D, rtol=0, atol=1e-11)
            assert np.isnan(s.theta1d).all() and np.isnan(s.theta2dd).all()
            np.testing.assert_allclose(s.l3d, -1.0)  # the prismatic joint is unaffected


def test_scara_coincident_when_equal_arms_and_tool_on_shoulder_axis():
    D = np.array([[0.0, 0.0, 40.0], [10.0, 0.0, 40.0]])
    s = assur_scara_inverse(D, np.zeros_like(D), np.zeros_like(D), 150.0, 60.0, 60.0, 1)
    assert s.case.tolist() == [RRRCase.COINCIDENT, RRRCase.REGULAR]
    assert np.isnan(s.theta1[0]) and np.isnan(s.theta2[0]) and np.isnan(s.B[0]).all()
    np.testing.assert_allclose(s.l3, [110.0, 110.0])
    assert np.isfinite(s.qdd[1]).all()


def test_scara_unreachable():
    D = np.array([[131.0, 0.0, 0.0], [0.0, 29.0, 0.0], [100.0, 0.0, 0.0]])
    s = assur_scara_inverse(D, np.zeros_like(D), np.zeros_like(D), L_OA, L_AB, L_BC, 1)
    assert s.case.tolist() == [RRRCase.UNREACHABLE, RRRCase.UNREACHABLE, RRRCase.REGULAR]
    assert np.isnan(s.q[:2, :2]).all() and np.isfinite(s.q[2]).all()


# ---------------------------------------------------------------------------
# Errata of the paper (textbook.md §10, items 7-9): the printed formulas fail
# ---------------------------------------------------------------------------


def beta_dd_eq3(P, Pd, Pdd, Q, Qd, Qdd):
    """Eq. 3 of the paper as printed, in terms of P = 'A' and Q = 'B'."""
    u = P / Q
    ud = (Pd * Q - P * Qd) / Q**2
    udd = ((Pdd * Q - P * Qdd) * Q**2 - 2 * (Pd * Q - P * Qd) * Q * Qd) / Q**4
    return -1.0 / np.sqrt(1 - u**2) * (u * ud**2 / (1 - u**2) + udd)


def test_erratum_8_misprinted_p_double_dot_gives_the_wrong_theta1_acceleration():
    D, Dd, Ddd = spiral([1.0])
    zero = np.zeros((1, 2))
    g = rrr_group(zero, zero, zero, D[:, :2], Dd[:, :2], Ddd[:, :2], L_AB, L_BC, 1)
    l, ld, ldd, l_AC = g.l_AB, g.l_ABd, g.l_ABdd, L_AB
    P, Pd = l_AC**2 + l**2 - L_BC**2, 2 * l * ld
    Q, Qd, Qdd = 2 * l_AC * l, 2 * l_AC * ld, 2 * l_AC * ldd
    corrected = g.thetadd + beta_dd_eq3(P, Pd, 2 * (ld**2 + l * ldd), Q, Qd, Qdd)
    printed = g.thetadd + beta_dd_eq3(P, Pd, 2 * (l**2 + l * ldd), Q, Qd, Qdd)
    np.testing.assert_allclose(corrected, g.phidd, rtol=1e-12)  # the helper is eq. 3 itself
    np.testing.assert_allclose(corrected, 0.619384, rtol=TABLE_RTOL, atol=TABLE_ATOL)
    misprinted = DATA["errata"]["misprinted_P_dd_theta1dd_mode_1_t_1"]  # -4.33804
    np.testing.assert_allclose(printed, misprinted, rtol=TABLE_RTOL, atol=TABLE_ATOL)
    # Finite differences of theta1 side with the corrected formula.
    h = 1e-4
    theta1 = [solve_spiral([1.0 + k * h], 1).theta1[0] for k in (-1, 0, 1)]
    fd = (theta1[0] - 2 * theta1[1] + theta1[2]) / h**2
    assert abs(fd - corrected[0]) < 1e-6
    assert abs(fd - printed[0]) > 4.0


def test_erratum_7_printed_theta_dd_numerator_fails_for_uniform_rotation():
    # Unit vector turning at a constant 2 rad/s, seen at theta = 0.3: theta'' = 0.
    w, a = 2.0, 0.3
    x, y = np.cos(a), np.sin(a)
    xd, yd = -w * np.sin(a), w * np.cos(a)
    xdd, ydd = -w * w * np.cos(a), -w * w * np.sin(a)
    r = angle_function(x, y, xd, yd, xdd, ydd)
    np.testing.assert_allclose([r.theta, r.thetad, r.thetadd], [a, w, 0.0], atol=1e-14)
    r2 = x * x + y * y
    printed = ((yd * x - y * xd) * r2 - (yd * x - y * xd) * 2 * (x * xd + y * yd)) / r2**2
    np.testing.assert_allclose(printed, w, atol=1e-14)  # 2 rad/s² instead of 0


@pytest.mark.parametrize("y", [-2.0, 2.0])
def test_erratum_7_x_zero_branch(y):
    x, xd, yd, xdd, ydd = 0.0, 1.5, 0.5, 0.3, -0.7
    r = angle_function(x, y, xd, yd, xdd, ydd)
    # The corrected branch formulas, for both signs of y, equal the general formula.
    np.testing.assert_allclose(r.thetad, -xd / y, rtol=1e-15)
    np.testing.assert_allclose(r.thetadd, -xdd / y + 2 * xd * yd / y**2, rtol=1e-14)
    np.testing.assert_allclose(r.theta, np.sign(y) * np.pi / 2, rtol=0)
    # Finite differences along x(t) = x'·t + x''t²/2, y(t) = y + y't + y''t²/2.

    def theta(t):
        return np.arctan2(y + yd * t + ydd * t**2 / 2, x + xd * t + xdd * t**2 / 2)

    h = 1e-4
    fd1 = (theta(h) - theta(-h)) / (2 * h)
    fd2 = (theta(h) - 2 * theta(0.0) + theta(-h)) / h**2
    assert abs(r.thetad - fd1) < 1e-7 and abs(r.thetadd - fd2) < 1e-6
    # The printed branch formulas disagree with the finite differences.
    if y < 0:
        printed_d, printed_dd = xd / y, (xdd * y - xd * yd) / y**2
        assert abs(printed_d - fd1) > 1.0  # wrong sign: +-0.75
    else:
        printed_d, printed_dd = -xd / y, (xd * yd - xdd * y) / y**2
        assert abs(printed_d - fd1) < 1e-7  # the y > 0 velocity is right
    assert abs(printed_dd - fd2) > 0.1  # factor 2 missing (and sign, for y < 0)


def test_erratum_9_theta_bc_is_the_angle_of_b_to_c():
    D, Dd, Ddd = spiral(np.arange(9.0))
    s = assur_scara_inverse(D, Dd, Ddd, L_OA, L_AB, L_BC, 1)
    BC = D[:, :2] - s.B
    np.testing.assert_allclose(s.theta_BC, np.arctan2(BC[:, 1], BC[:, 0]), atol=1e-14)
    # Reading the text literally ("points A and B") would take the angle of
    # A->B, which is theta1 itself, and theta2 = theta1 - theta_BC would be 0.
    misread = angle_function(s.B[:, 0], s.B[:, 1], s.Bd[:, 0], s.Bd[:, 1], s.Bdd[:, 0], s.Bdd[:, 1])
    np.testing.assert_allclose(s.theta1 - misread.theta, 0.0, atol=1e-14)
    assert np.all(np.abs(s.theta2) > 0.8)


# ---------------------------------------------------------------------------
# Validation at the boundary, forward map, docstring examples
# ---------------------------------------------------------------------------


def test_forward_matches_the_textbook_test_vector():
    # textbook.md §8, assur001_scara_RRP, q = (0.5, -0.7, 100).
    for q, D in (((0.5, -0.7, 100.0), [88.3245, 84.956, 50.0]), ((-2.0, 1.2, 60.0), [-83.2065, -69.8251, 90.0])):
        np.testing.assert_allclose(assur_scara_forward(*q, L_OA, L_AB, L_BC), D, rtol=0, atol=1e-4)


_O = [0.0, 0.0]


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: rrr_group([0, 0, 0], _O, _O, [1, 0], _O, _O, 1, 1, 1), r"A must have shape \(\.\.\., 2\), got shape \(3,\)"),
        (lambda: rrr_group(_O, _O, _O, [np.nan, 0], _O, _O, 1, 1, 1), "B must contain only finite"),
        (lambda: rrr_group(_O, _O, _O, [1, 0], _O, _O, 0.0, 1, 1), "l_AC must be a positive"),
        (lambda: rrr_group(_O, _O, _O, [1, 0], _O, _O, 1, 1, 3), "assembly_mode must be 1"),
        (lambda: assur_scara_inverse([1, 0], [0, 0], [0, 0], 1, 1, 1, 1), r"D must have shape \(\.\.\., 3\)"),
        (lambda: assur_scara_inverse([1, 0, 0], [0, 0, 0], [0, 0, 0], 1, -1, 1, 2), "l_AB must be a positive"),
    ],
)
def test_invalid_input_raises_domain_error(call, match):
    with pytest.raises(InvalidInputError, match=match):
        call()


def test_invalid_input_error_names_the_field():
    with pytest.raises(InvalidInputError) as info:
        assur_scara_inverse([1, 0, 0], [0, 0], [0, 0, 0], 150, 80, 50, 1)
    assert info.value.location == ("Dd",)


def test_docstring_examples():
    result = doctest.TestResults(failed=0, attempted=0)
    for module in (_assur, _assur_functions):
        failed, attempted = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE)
        result = doctest.TestResults(result.failed + failed, result.attempted + attempted)
    assert result.attempted >= 10
    assert result.failed == 0
