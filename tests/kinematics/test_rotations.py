"""Tests for service.kinematics._rotations.

Random rotations come from a QR decomposition of Gaussian matrices, which does
not use the module under test, so round trips cannot hide a shared mistake.
"""

from __future__ import annotations

import contextlib
import doctest
import math

import numpy as np
import pytest

from service.kinematics import (
    InvalidInputError,
    _rotations,
    check_rotation,
    check_transform,
    check_transforms,
    check_unit_quaternion,
    frame_quaternion,
    frame_quaternions,
    matrix_from_euler_zyz,
    matrix_from_quaternion,
    matrix_from_rpy,
    quaternions_from_matrices,
    rpy_from_matrix,
)
from service.kinematics import _angles
from service.kinematics._angles import wrap_angle, wrap_any_float, wrap_float
from service.kinematics._rotations import euler_zyz_from_matrix, rot_x, rot_y, rot_z
from service.kinematics._tolerances import SINGULARITY_TOLERANCE
from tests.oracles.rotations import axis_angle, matrix_of_quaternion, random_rotations

N = 1000
PI = math.pi


def random_unit_vectors(rng: np.random.Generator, n: int) -> np.ndarray:
    v = rng.standard_normal((n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def quaternion_of(R: np.ndarray) -> np.ndarray:
    """The quaternion of one matrix, through the batch function."""
    return quaternions_from_matrices(R[None])[0]


def canonical(q: np.ndarray) -> np.ndarray:
    """Reference sign convention, written independently: w >= 0."""
    return q * (1.0 if q[0] >= 0 else -1.0)


def assert_is_rotation(R: np.ndarray, atol: float = 1e-12) -> None:
    np.testing.assert_allclose(np.swapaxes(R, -1, -2) @ R, np.broadcast_to(np.eye(3), R.shape), atol=atol)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=atol)


@contextlib.contextmanager
def raises_at(location: tuple, match: str):
    """Expect an InvalidInputError whose message matches ``match`` and whose location is ``location``."""
    with pytest.raises(InvalidInputError, match=match) as info:
        yield info
    assert info.value.location == location


# ---------------------------------------------------------------------------
# Docstring examples
# ---------------------------------------------------------------------------


def test_docstring_examples_hold():
    result = doctest.testmod(_rotations, optionflags=doctest.NORMALIZE_WHITESPACE)
    angles = doctest.testmod(_angles, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.failed == angles.failed == 0
    assert result.attempted + angles.attempted >= 27


def test_docstring_example_values():
    h = math.sqrt(0.5)
    np.testing.assert_allclose(quaternion_of(rot_z(PI / 2)), [h, 0.0, 0.0, h], atol=1e-15)
    angles, singular = euler_zyz_from_matrix(matrix_from_euler_zyz(0.1, 0.2, 0.3))
    np.testing.assert_allclose(angles, [0.1, 0.2, 0.3], atol=1e-14)
    assert singular is False
    angles, _ = euler_zyz_from_matrix(matrix_from_euler_zyz(0.1, 0.2, 0.3), branch=-1)
    np.testing.assert_allclose(angles, [0.1 - PI, -0.2, 0.3 - PI], atol=1e-14)
    np.testing.assert_allclose(
        matrix_from_euler_zyz(0.1, 0.2, 0.3)[:, 2],
        [math.cos(0.1) * math.sin(0.2), math.sin(0.1) * math.sin(0.2), math.cos(0.2)],
        atol=1e-15,
    )
    np.testing.assert_allclose(
        matrix_from_rpy(0.1, 0.2, 0.3)[2],
        [-math.sin(0.2), math.cos(0.2) * math.sin(0.1), math.cos(0.2) * math.cos(0.1)],
        atol=1e-15,
    )


# ---------------------------------------------------------------------------
# Elementary rotations
# ---------------------------------------------------------------------------


def test_elementary_rotations_match_their_closed_forms(rng):
    for a in rng.uniform(-PI, PI, 20):
        c, s = math.cos(a), math.sin(a)
        np.testing.assert_allclose(rot_x(a), [[1, 0, 0], [0, c, -s], [0, s, c]], atol=1e-15)
        np.testing.assert_allclose(rot_y(a), [[c, 0, s], [0, 1, 0], [-s, 0, c]], atol=1e-15)
        np.testing.assert_allclose(rot_z(a), [[c, -s, 0], [s, c, 0], [0, 0, 1]], atol=1e-15)


def test_elementary_rotations_accept_arrays(rng):
    angles = rng.uniform(-PI, PI, 7)
    for rot in (rot_x, rot_y, rot_z):
        stacked = rot(angles)
        assert stacked.shape == (7, 3, 3)
        np.testing.assert_array_equal(stacked, np.stack([rot(a) for a in angles]))
    assert rot_z(0.3).shape == (3, 3)


# ---------------------------------------------------------------------------
# Quaternions
# ---------------------------------------------------------------------------


def test_quaternion_round_trip_on_random_quaternions(rng):
    Q = rng.standard_normal((N, 4))
    Q /= np.linalg.norm(Q, axis=1, keepdims=True)
    for q in Q:
        R = matrix_from_quaternion(q)
        assert_is_rotation(R)
        np.testing.assert_allclose(quaternion_of(R), canonical(q), atol=1e-13)


def test_matrix_from_quaternion_agrees_with_rodrigues(rng):
    for axis, angle in zip(random_unit_vectors(rng, 200), rng.uniform(0, 2 * PI, 200)):
        q = np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * axis])
        np.testing.assert_allclose(matrix_from_quaternion(q), axis_angle(axis, angle), atol=1e-14)


def test_matrix_round_trip_through_quaternion(rng):
    for R in random_rotations(rng, N):
        q = quaternion_of(R)
        assert q[0] >= 0.0
        assert np.linalg.norm(q) == pytest.approx(1.0, abs=1e-15)
        np.testing.assert_allclose(matrix_from_quaternion(q), R, atol=1e-14)


def test_quaternion_sign_is_canonical(rng):
    Q = rng.standard_normal((100, 4))
    Q /= np.linalg.norm(Q, axis=1, keepdims=True)
    for q in Q:
        expected = canonical(q)
        np.testing.assert_allclose(quaternion_of(matrix_from_quaternion(q)), expected, atol=1e-13)
        np.testing.assert_allclose(quaternion_of(matrix_from_quaternion(-q)), expected, atol=1e-13)


@pytest.mark.parametrize(
    ("half_turn", "expected"),
    [
        ([0.0, -0.6, 0.8, 0.0], [0.0, 0.6, -0.8, 0.0]),
        ([0.0, 0.0, -1.0, 0.0], [0.0, 0.0, 1.0, 0.0]),
        ([0.0, 0.0, 0.0, -1.0], [0.0, 0.0, 0.0, 1.0]),
        ([0.0, 0.0, 0.6, -0.8], [0.0, 0.0, 0.6, -0.8]),
    ],
)
def test_half_turn_sign_tie_break(half_turn, expected):
    q = quaternion_of(matrix_from_quaternion(half_turn))
    np.testing.assert_allclose(q, expected, atol=1e-15)
    assert not np.signbit(q[0])  # w is +0.0, not -0.0


@pytest.mark.parametrize("angle", [PI - 1e-6, PI - 1e-9, PI - 1e-12, PI])
def test_quaternion_of_near_half_turns_is_accurate(rng, angle):
    for axis in random_unit_vectors(rng, 100):
        R = axis_angle(axis, angle)
        assert np.trace(R) == pytest.approx(-1.0, abs=1e-11)
        expected = canonical(np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * axis]))
        q = quaternion_of(R)
        np.testing.assert_allclose(q, expected, atol=1e-13)
        np.testing.assert_allclose(matrix_from_quaternion(q), R, atol=1e-14)


def test_batch_quaternions_mix_every_case_of_shepperds_method(rng):
    # w, x, y or z largest, in one batch
    R = np.concatenate([np.stack([np.eye(3), rot_x(3.0), rot_y(3.0), rot_z(3.0)]), random_rotations(rng, N)])
    quaternions = quaternions_from_matrices(R)
    assert quaternions.shape == (N + 4, 4)
    assert np.all(quaternions[:, 0] >= 0.0)
    np.testing.assert_allclose(np.stack([matrix_from_quaternion(q) for q in quaternions]), R, atol=1e-14)
    np.testing.assert_allclose(quaternions[:4, 0], [1.0, math.cos(1.5), math.cos(1.5), math.cos(1.5)], atol=1e-15)
    np.testing.assert_allclose(np.abs(quaternions[1:4, 1:]), math.sin(1.5) * np.eye(3), atol=1e-15)


def test_batch_functions_accept_empty_batches():
    assert check_transforms(np.zeros((0, 4, 4))).shape == (0, 4, 4)
    assert quaternions_from_matrices(np.zeros((0, 3, 3))).shape == (0, 4)


# ---------------------------------------------------------------------------
# ZYZ Euler angles
# ---------------------------------------------------------------------------


def test_zyz_matrix_matches_the_textbook_closed_form(rng):
    for phi, theta, psi in rng.uniform(-PI, PI, (50, 3)):
        cf, sf, ct, st, cp, sp = (math.cos(phi), math.sin(phi), math.cos(theta), math.sin(theta),
                                  math.cos(psi), math.sin(psi))
        expected = [
            [cf * ct * cp - sf * sp, -cf * ct * sp - sf * cp, cf * st],
            [sf * ct * cp + cf * sp, -sf * ct * sp + cf * cp, sf * st],
            [-st * cp, st * sp, ct],
        ]
        np.testing.assert_allclose(matrix_from_euler_zyz(phi, theta, psi), expected, atol=1e-15)


@pytest.mark.parametrize("branch", [1, -1])
def test_zyz_round_trip_on_random_rotations(rng, branch):
    for R in random_rotations(rng, N):
        angles, singular = euler_zyz_from_matrix(R, branch=branch)
        assert singular is False
        assert angles.shape == (3,)
        assert np.all((angles > -PI) & (angles <= PI))
        assert branch * math.sin(angles[1]) > 0.0
        np.testing.assert_allclose(matrix_from_euler_zyz(*angles), R, atol=1e-13)


def test_zyz_branches_are_related_by_the_textbook_map(rng):
    for R in random_rotations(rng, N):
        phi, theta, psi = euler_zyz_from_matrix(R, branch=1)[0]
        other = euler_zyz_from_matrix(R, branch=-1)[0]
        np.testing.assert_allclose(wrap_angle(other - [phi + PI, -theta, psi + PI]), 0.0, atol=1e-12)


def test_zyz_angles_round_trip(rng):
    phi = rng.uniform(-PI, PI, N)
    theta = rng.uniform(0.01, PI - 0.01, N)
    psi = rng.uniform(-PI, PI, N)
    R = matrix_from_euler_zyz(phi, theta, psi)
    assert R.shape == (N, 3, 3)
    for i in range(N):
        angles, singular = euler_zyz_from_matrix(R[i])
        assert singular is False
        np.testing.assert_allclose(angles, [phi[i], theta[i], psi[i]], atol=1e-11)


@pytest.mark.parametrize("free_angle", [0.0, 1.0, -2.5])
@pytest.mark.parametrize("branch", [1, -1])
@pytest.mark.parametrize(("phi", "psi"), [(0.3, 0.5), (-3.0, 1.0), (2.9, 2.8)])
def test_zyz_singular_theta_zero(free_angle, branch, phi, psi):
    R = matrix_from_euler_zyz(phi, 0.0, psi)
    angles, singular = euler_zyz_from_matrix(R, branch=branch, free_angle=free_angle)
    assert singular is True
    assert angles[0] == pytest.approx(free_angle, abs=1e-15)
    assert angles[1] == 0.0
    assert wrap_angle(angles[0] + angles[2] - (phi + psi)) == pytest.approx(0.0, abs=1e-14)
    np.testing.assert_allclose(matrix_from_euler_zyz(*angles), R, atol=1e-14)


@pytest.mark.parametrize("free_angle", [0.0, 1.0, -2.5])
@pytest.mark.parametrize("branch", [1, -1])
@pytest.mark.parametrize(("phi", "psi"), [(0.3, 0.5), (-3.0, 1.0), (2.9, -2.8)])
def test_zyz_singular_theta_pi(free_angle, branch, phi, psi):
    R = matrix_from_euler_zyz(phi, PI, psi)
    angles, singular = euler_zyz_from_matrix(R, branch=branch, free_angle=free_angle)
    assert singular is True
    assert angles[0] == pytest.approx(free_angle, abs=1e-15)
    assert angles[1] == PI
    assert wrap_angle(angles[0] - angles[2] - (phi - psi)) == pytest.approx(0.0, abs=1e-14)
    np.testing.assert_allclose(matrix_from_euler_zyz(*angles), R, atol=1e-14)


def test_zyz_singular_values_from_the_textbook():
    angles, singular = euler_zyz_from_matrix(matrix_from_euler_zyz(0.3, 0.0, 0.5))
    np.testing.assert_allclose(angles, [0.0, 0.0, 0.8], atol=1e-15)
    angles, singular = euler_zyz_from_matrix(matrix_from_euler_zyz(0.3, PI, 0.5))
    np.testing.assert_allclose(angles, [0.0, PI, 0.2], atol=1e-15)
    angles, _ = euler_zyz_from_matrix(matrix_from_euler_zyz(0.3, PI, 0.5), free_angle=1.0)
    np.testing.assert_allclose(angles, [1.0, PI, 1.2], atol=1e-15)


def test_zyz_singularity_uses_the_tolerance_not_exact_equality():
    near = matrix_from_euler_zyz(0.3, 0.5 * SINGULARITY_TOLERANCE, 0.5)
    angles, singular = euler_zyz_from_matrix(near)
    assert singular is True
    np.testing.assert_allclose(matrix_from_euler_zyz(*angles), near, atol=SINGULARITY_TOLERANCE)
    near_pi = matrix_from_euler_zyz(0.3, PI - 0.5 * SINGULARITY_TOLERANCE, 0.5)
    angles, singular = euler_zyz_from_matrix(near_pi)
    assert singular is True
    assert angles[1] == PI

    outside = matrix_from_euler_zyz(0.3, 2.0 * SINGULARITY_TOLERANCE, 0.5)
    angles, singular = euler_zyz_from_matrix(outside)
    assert singular is False
    np.testing.assert_allclose(matrix_from_euler_zyz(*angles), outside, atol=1e-12)


# ---------------------------------------------------------------------------
# Roll, pitch, yaw
# ---------------------------------------------------------------------------


def test_rpy_matrix_matches_the_fixed_axis_closed_form(rng):
    for roll, pitch, yaw in rng.uniform(-PI, PI, (50, 3)):
        cr, sr, cp, sp, cy, sy = (math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch),
                                  math.cos(yaw), math.sin(yaw))
        expected = [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
        np.testing.assert_allclose(matrix_from_rpy(roll, pitch, yaw), expected, atol=1e-15)
    np.testing.assert_allclose(matrix_from_rpy(0.4, 0.0, 0.0), rot_x(0.4), atol=1e-16)
    np.testing.assert_allclose(matrix_from_rpy(0.0, 0.4, 0.0), rot_y(0.4), atol=1e-16)
    np.testing.assert_allclose(matrix_from_rpy(0.0, 0.0, 0.4), rot_z(0.4), atol=1e-16)


def test_rpy_round_trip_on_random_rotations(rng):
    for R in random_rotations(rng, N):
        angles, singular = rpy_from_matrix(R)
        assert singular is False
        assert np.all((angles > -PI) & (angles <= PI))
        assert -PI / 2 <= angles[1] <= PI / 2
        np.testing.assert_allclose(matrix_from_rpy(*angles), R, atol=1e-13)


def test_rpy_angles_round_trip(rng):
    roll = rng.uniform(-PI, PI, N)
    pitch = rng.uniform(-PI / 2 + 0.01, PI / 2 - 0.01, N)
    yaw = rng.uniform(-PI, PI, N)
    R = matrix_from_rpy(roll, pitch, yaw)
    for i in range(N):
        angles, singular = rpy_from_matrix(R[i])
        assert singular is False
        np.testing.assert_allclose(angles, [roll[i], pitch[i], yaw[i]], atol=1e-11)


@pytest.mark.parametrize("free_angle", [0.0, 0.4, -3.0])
@pytest.mark.parametrize(("roll", "yaw"), [(0.3, 0.5), (-3.0, 2.0), (2.5, -2.9)])
def test_rpy_gimbal_lock_pitch_up(free_angle, roll, yaw):
    R = matrix_from_rpy(roll, PI / 2, yaw)
    angles, singular = rpy_from_matrix(R, free_angle=free_angle)
    assert singular is True
    assert angles[0] == pytest.approx(free_angle, abs=1e-15)
    assert angles[1] == PI / 2
    assert wrap_angle(angles[0] - angles[2] - (roll - yaw)) == pytest.approx(0.0, abs=1e-14)
    np.testing.assert_allclose(matrix_from_rpy(*angles), R, atol=1e-14)


@pytest.mark.parametrize("free_angle", [0.0, 0.4, -3.0])
@pytest.mark.parametrize(("roll", "yaw"), [(0.3, 0.5), (-3.0, 2.0), (2.5, 2.9)])
def test_rpy_gimbal_lock_pitch_down(free_angle, roll, yaw):
    R = matrix_from_rpy(roll, -PI / 2, yaw)
    angles, singular = rpy_from_matrix(R, free_angle=free_angle)
    assert singular is True
    assert angles[0] == pytest.approx(free_angle, abs=1e-15)
    assert angles[1] == -PI / 2
    assert wrap_angle(angles[0] + angles[2] - (roll + yaw)) == pytest.approx(0.0, abs=1e-14)
    np.testing.assert_allclose(matrix_from_rpy(*angles), R, atol=1e-14)


def test_rpy_gimbal_lock_values():
    np.testing.assert_allclose(rpy_from_matrix(matrix_from_rpy(0.3, PI / 2, 0.5))[0], [0.0, PI / 2, 0.2], atol=1e-15)
    np.testing.assert_allclose(rpy_from_matrix(matrix_from_rpy(0.3, -PI / 2, 0.5))[0], [0.0, -PI / 2, 0.8], atol=1e-15)
    near = matrix_from_rpy(0.3, PI / 2 - 0.5 * SINGULARITY_TOLERANCE, 0.5)
    assert rpy_from_matrix(near)[1] is True
    assert rpy_from_matrix(matrix_from_rpy(0.3, PI / 2 - 2.0 * SINGULARITY_TOLERANCE, 0.5))[1] is False


# ---------------------------------------------------------------------------
# Angle wrap
# ---------------------------------------------------------------------------


def test_wrap_angle_values():
    assert wrap_angle(3 * PI / 2) == pytest.approx(-PI / 2, abs=1e-15)
    assert wrap_angle(-PI) == PI
    assert wrap_angle(PI) == PI
    assert wrap_angle(-3 * PI) == PI
    # one ulp above pi: one turn down is exact, just above -pi (pi's float is below the true pi)
    assert wrap_angle(np.nextafter(PI, 4.0)) == np.nextafter(PI, 4.0) - 2 * PI > -PI
    # far angles go through the modulo, which must not round up to a full turn
    assert wrap_angle(np.nextafter(5 * PI, 0.0)) == pytest.approx(PI, abs=1e-14)
    assert wrap_angle(-5 * PI) == PI
    assert wrap_angle(np.nextafter(5 * PI, 6 * PI)) == pytest.approx(-PI, abs=1e-14)
    assert np.isnan(wrap_angle([np.inf, -np.inf, np.nan])).all()
    assert wrap_angle(0.1) == 0.1
    assert wrap_angle(100.0) == pytest.approx(100.0 - 32 * PI, abs=1e-13)
    assert isinstance(wrap_angle(1.0), float)


def test_wrap_angle_is_vectorized_and_in_range(rng):
    x = np.concatenate([rng.uniform(-50, 50, (10, 100)), rng.uniform(-3 * PI, 3 * PI, (10, 100))])
    wrapped = wrap_angle(x)
    assert wrapped.shape == x.shape
    assert np.all((wrapped > -PI) & (wrapped <= PI))
    turns = (x - wrapped) / (2 * PI)
    np.testing.assert_allclose(turns, np.round(turns), atol=1e-12)
    inside = rng.uniform(-PI, PI, 100)
    np.testing.assert_array_equal(wrap_angle(inside), inside)


def test_float_wraps_are_wrap_angle_bit_for_bit(rng):
    """The one-pose paths' float wraps give wrap_angle's value, sign of zero included (wrap_float within
    three half-turns, wrap_any_float anywhere)."""
    near = [PI, -PI, np.nextafter(PI, 4.0), np.nextafter(-PI, -4.0), 3 * PI, np.nextafter(-3 * PI, 0.0), 0.0, -0.0]
    far = [-3 * PI, np.nextafter(5 * PI, 0.0), -5 * PI, 100.0, -1e9]
    within = near + rng.uniform(-3 * PI, 3 * PI, 2000).tolist()
    for x in within:
        assert wrap_float(x) == wrap_angle(x), x
        assert math.copysign(1.0, wrap_float(x)) == math.copysign(1.0, wrap_angle(x)), x
    for x in within + far + rng.uniform(-50, 50, 2000).tolist():
        assert wrap_any_float(x) == wrap_angle(x), x
        assert math.copysign(1.0, wrap_any_float(x)) == math.copysign(1.0, wrap_angle(x)), x


# ---------------------------------------------------------------------------
# Validation
# ---------------------------------------------------------------------------


def test_check_rotation_returns_a_float64_copy():
    R = np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1]])
    checked = check_rotation(R)
    assert checked.dtype == np.float64
    np.testing.assert_array_equal(checked, R)
    checked[0, 0] = 5.0
    assert R[0, 0] == 0


def test_check_rotation_accepts_errors_within_tolerance():
    R = rot_z(0.3)
    R[0, 0] += 1e-7
    np.testing.assert_array_equal(check_rotation(R), R)  # returned as given, not re-orthonormalised
    R[0, 0] += 1e-5
    check_rotation(R, tolerance=1e-4)


def test_non_orthonormal_by_1e_5_is_rejected_with_the_amount():
    R = np.eye(3)
    R[0, 0] += 1e-5
    with raises_at((), r"not orthonormal: max \|R\^T R - I\| is 2e-05, more than the tolerance 1e-06 "
                       r"\(column 0 has length 1\.00001\)"):
        check_rotation(R)
    R = rot_z(0.3)
    R[1, 2] = 1e-5
    with raises_at((), r"not orthonormal.*columns 1 and 2 have dot product"):
        check_rotation(R)


@pytest.mark.parametrize("R", [np.diag([1.0, 1.0, -1.0]), -rot_z(0.3), rot_x(1.0) @ np.diag([1.0, -1.0, 1.0])])
def test_reflection_is_named(R):
    with raises_at((), r"determinant -1: it is a reflection, not a rotation"):
        check_rotation(R)


@pytest.mark.parametrize(("bad", "index", "text"), [(np.nan, (1, 2), "nan"), (np.inf, (2, 0), "inf"),
                                                     (-np.inf, (0, 0), "-inf")])
def test_non_finite_rotation_entries_are_located(bad, index, text):
    R = np.eye(3)
    R[index] = bad
    with raises_at(index, rf"rotation matrix entry \({index[0]}, {index[1]}\) is {text}; every entry must be"):
        check_rotation(R)


@pytest.mark.parametrize("shape", [(3, 4), (9,), (2, 3, 3), ()])
def test_rotation_of_wrong_shape_is_rejected(shape):
    with raises_at((), rf"rotation matrix must have shape \(3, 3\), got shape {re_shape(shape)}"):
        check_rotation(np.zeros(shape))


def re_shape(shape: tuple) -> str:
    return str(shape).replace("(", r"\(").replace(")", r"\)")


def test_rotation_that_is_not_numbers_is_rejected():
    with raises_at((), "must contain real numbers"):
        check_rotation([["a", "b", "c"]] * 3)
    with raises_at((), "must be an array of numbers"):
        check_rotation([[1, 0, 0], [0, 1], [0, 0, 1]])
    with raises_at((), "must contain real numbers"):
        check_rotation(np.eye(3, dtype=complex))


def _outcome(check, value):
    """What a check says of a value: "ok", or its error's message and location."""
    try:
        check(value)
    except InvalidInputError as error:
        return str(error), error.location
    return "ok"


@pytest.mark.parametrize("size", [0.0, 1e-8, 3e-7, 1e-6, 3e-6, 1e-4])
def test_one_matrix_is_judged_as_the_array_checks_judge_it(rng, size, monkeypatch):
    """check_rotation and check_transform of one matrix first screen it on floats (half the tolerance to spare)
    and leave anything doubtful to the array checks: the same verdict and the same words as the array checks
    alone, for perturbations from well within the tolerance (1e-6) to well beyond it, NaN and infinite entries
    and reflections included."""
    cases = []
    for R in random_rotations(rng, 300):
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = R, rng.normal(size=3)
        T += size * rng.normal(size=(4, 4)) * (rng.random((4, 4)) < 0.5)
        choice = rng.random()
        if choice < 0.05:
            T[rng.integers(4), rng.integers(4)] = rng.choice([np.nan, np.inf, -np.inf])
        elif choice < 0.1:
            T[:3, :3] = T[:3, :3] @ np.diag([1.0, 1.0, -1.0])
        cases.append(T)
    screened = [(_outcome(check_transform, T), _outcome(check_rotation, T[:3, :3])) for T in cases]
    monkeypatch.setattr(_rotations, "_clearly_rigid", lambda rows, tolerance: False)
    assert screened == [(_outcome(check_transform, T), _outcome(check_rotation, T[:3, :3])) for T in cases]
    accepted = sum(single == "ok" for single, _ in screened)
    if size <= 1e-8:
        assert accepted >= 250
    if size >= 1e-4:
        assert accepted <= 50


def test_check_transform_errors_are_located_in_the_4x4():
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = rot_z(0.3), [1.0, 2.0, 3.0]
    np.testing.assert_array_equal(check_transform(T), T)

    bad = T.copy()
    bad[3, 2] = 0.5
    with raises_at((3, 2), r"bottom row .* must be \[0, 0, 0, 1\], but entry \(3, 2\) is 0\.5"):
        check_transform(bad)
    bad = T.copy()
    bad[3, 3] = 1.0 + 1e-5
    with raises_at((3, 3), r"entry \(3, 3\) is 1\.00001"):
        check_transform(bad)
    bad = T.copy()
    bad[3, 0] = 1e-7  # within tolerance
    check_transform(bad)

    bad = T.copy()
    bad[2, 1] = np.nan
    with raises_at((2, 1), r"transform entry \(2, 1\) is nan"):
        check_transform(bad)
    bad = T.copy()
    bad[0, 3] = np.inf
    with raises_at((0, 3), r"transform entry \(0, 3\) is inf"):
        check_transform(bad)
    bad = T.copy()
    bad[:3, :3] = np.diag([1.0, -1.0, 1.0])
    with raises_at((), "rotation block of the transform has determinant -1: it is a reflection"):
        check_transform(bad)
    bad = T.copy()
    bad[1, 1] += 1e-5
    with raises_at((), "rotation block of the transform is not orthonormal"):
        check_transform(bad)
    with raises_at((), r"transform must have shape \(4, 4\), got shape \(3, 4\)"):
        check_transform(T[:3])


def test_check_unit_quaternion():
    q = check_unit_quaternion([0.5, 0.5, 0.5, 0.5])
    assert q.dtype == np.float64
    check_unit_quaternion([1.0 + 1e-7, 0.0, 0.0, 0.0])
    with raises_at((), r"norm 1, but its norm is 1\.00001 \(off by 1e-05, tolerance 1e-06\)"):
        check_unit_quaternion([1.0 + 1e-5, 0.0, 0.0, 0.0])
    with raises_at((), r"norm is 0 "):
        matrix_from_quaternion([0.0, 0.0, 0.0, 0.0])
    with raises_at((2,), r"quaternion entry 2 is nan"):
        check_unit_quaternion([1.0, 0.0, np.nan, 0.0])
    with raises_at((0,), r"quaternion entry 0 is inf"):
        check_unit_quaternion([np.inf, 0.0, 0.0, 0.0])
    with raises_at((), r"quaternion must have shape \(4,\), got shape \(3,\)"):
        check_unit_quaternion([1.0, 0.0, 0.0])


def test_batch_errors_name_the_row():
    R = np.tile(np.eye(3), (4, 1, 1))
    R[2] = np.diag([-1.0, 1.0, 1.0])
    with raises_at((2,), "reflection, not a rotation"):
        quaternions_from_matrices(R)
    R[2] = np.eye(3)
    R[1, 0, 1] = 1e-5
    with raises_at((1,), "not orthonormal"):
        quaternions_from_matrices(R)
    with raises_at((), r"must have shape \(N, 3, 3\), got shape \(3, 3\)"):
        quaternions_from_matrices(np.eye(3))

    T = np.tile(np.eye(4), (3, 1, 1))
    T[1, 3, 0] = 0.2
    with raises_at((1, 3, 0), "bottom row"):
        check_transforms(T)
    T[1, 3, 0] = 0.0
    T[2, 1, 2] = np.nan
    with raises_at((2, 1, 2), r"transform entry \(2, 1, 2\) is nan"):
        check_transforms(T)


def test_errors_of_multi_argument_functions_start_with_the_argument_name():
    with raises_at(("roll", 1), "entry 1 is nan"):
        matrix_from_rpy([0.0, np.nan], 0.0, 0.0)
    with raises_at(("theta",), "theta is nan"):
        matrix_from_euler_zyz(0.0, np.nan, 0.0)
    with raises_at((), "same length"):
        matrix_from_rpy([0.0, 1.0], [0.0, 1.0, 2.0], 0.0)


def test_angle_arguments_are_validated():
    with raises_at((), "angle is nan; every entry must be a finite number"):
        rot_x(np.nan)
    with raises_at((1,), "angle entry 1 is inf"):
        rot_y([0.0, np.inf])
    with raises_at((), r"angle must be a scalar or shape \(N,\), got shape \(2, 2\)"):
        rot_z(np.zeros((2, 2)))
    with raises_at(("branch",), "branch must be 1 or -1, got 0"):
        euler_zyz_from_matrix(np.eye(3), branch=0)
    with raises_at(("free_angle",), "is nan"):
        euler_zyz_from_matrix(np.eye(3), free_angle=np.nan)
    with raises_at(("free_angle",), "must be a scalar"):
        rpy_from_matrix(np.eye(3), free_angle=[0.0, 1.0])
    with raises_at((), "reflection"):
        euler_zyz_from_matrix(-np.eye(3))
    with raises_at((0, 0), "is nan"):
        rpy_from_matrix(np.full((3, 3), np.nan))


@pytest.mark.parametrize("angle", [0.0, 0.5, PI - 1e-9, PI])
def test_frame_quaternions_of_one_rotation_on_floats_agree_with_the_batch(rng, angle):
    """The FK encoder's conversion (frame_quaternions, frame_quaternion) takes one rotation on floats: the same
    quaternion as the batch method, canonical sign included, for every case of Shepperd's method and half turns."""
    rotations = [axis_angle(axis, angle) for axis in random_unit_vectors(rng, 50)]
    rotations += [np.eye(3), rot_x(3.0), rot_y(3.0), rot_z(3.0), np.diag([-1.0, 1.0, -1.0]), np.diag([-1.0, -1.0, 1.0])]
    batch = quaternions_from_matrices(np.stack(rotations))
    for R, expected in zip(rotations, batch):
        one = frame_quaternions(R[None])
        assert one.shape == (1, 4)
        assert frame_quaternion(R.reshape(9).tolist()) == one[0].tolist()  # the float path it takes
        np.testing.assert_allclose(one[0], expected, rtol=0, atol=4e-16)
        assert one[0, 0] >= 0.0 and not np.signbit(one[0, 0])
        np.testing.assert_allclose(matrix_of_quaternion(*one[0]), R, atol=1e-14)  # the test's own formula
    np.testing.assert_array_equal(frame_quaternions(np.stack(rotations)), batch)  # a batch takes the array method
