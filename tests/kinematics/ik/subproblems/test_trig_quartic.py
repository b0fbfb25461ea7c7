"""The one root finder of subproblems 5 and 6 (and 5 with a slide): real roots of a trigonometric quartic.

Every equation here is built from its roots: ``(p0 - cos(t - m1)) (q0 - cos(t - m2))`` has the roots
``m1 ± acos(p0)`` and ``m2 ± acos(q0)``, and no real root from a factor with ``|p0| > 1`` (its roots lie
``acosh(p0)`` off the unit circle, radially, in ``z = exp(i t)``).
"""

import numpy as np
import pytest

from service.kinematics.ik.subproblems._roots import _ON_UNIT_CIRCLE, _trig_quartic_roots, _vanishes
from tests.ik_helpers import angle_gap

DOUBLE_ROOT = 1e-7  # a double root is found to about sqrt(eps)


def coefficients(p0, m1, q0, m2):
    """(alpha0, alpha1, beta1, alpha2, beta2) of (p0 - cos(t - m1)) (q0 - cos(t - m2)), arrays of one shape."""
    p0, m1, q0, m2 = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (p0, m1, q0, m2)))
    return (p0 * q0 + 0.5 * np.cos(m1 - m2), -p0 * np.cos(m2) - q0 * np.cos(m1), -p0 * np.sin(m2) - q0 * np.sin(m1),
            0.5 * np.cos(m1 + m2), 0.5 * np.sin(m1 + m2))


def value(alphas, t):
    a0, a1, b1, a2, b2 = (np.asarray(a)[..., None] for a in alphas)
    return a0 + a1 * np.cos(t) + b1 * np.sin(t) + a2 * np.cos(2 * t) + b2 * np.sin(2 * t)


def test_four_simple_roots_of_random_equations_are_all_found(rng):
    m1, m2 = rng.uniform(-np.pi, np.pi, (2, 500))
    p0, q0 = rng.uniform(-0.99, 0.99, (2, 500))
    theta, on_circle, double = _trig_quartic_roots(*coefficients(p0, m1, q0, m2))
    truth = np.stack([m1 + np.arccos(p0), m1 - np.arccos(p0), m2 + np.arccos(q0), m2 - np.arccos(q0)], -1)
    assert on_circle.all() and not double.any()
    nearest = angle_gap(theta[:, :, None], truth[:, None, :]).min(axis=1)  # each true root: its nearest slot
    assert (nearest < 1e-9).all()


def test_roots_at_zero_and_pi_are_ordinary():
    """z = 1 and z = -1: no tangent half-angle, so t = π is not a pole."""
    alphas = coefficients(0.0, np.pi / 2, np.cos(0.3), np.pi - 0.3)  # roots 0, π, π - 0.6 and π
    theta, on_circle, _ = _trig_quartic_roots(*alphas)
    found = theta[on_circle]
    for root in (0.0, np.pi, np.pi - 0.6):
        assert angle_gap(found, root).min() < DOUBLE_ROOT


@pytest.mark.parametrize("where", [0.0, np.pi, 1.234, -2.5])
def test_a_double_root_is_found_on_the_circle(where):
    """(1 - cos(t - m)) touches 0 at m: a double root that rounding splits by about sqrt(eps)."""
    theta, on_circle, _ = _trig_quartic_roots(*coefficients(1.0, where, 3.0, 0.7))
    assert on_circle.sum() >= 1
    assert (angle_gap(theta[on_circle], where) < DOUBLE_ROOT).all()
    assert np.abs(value(coefficients(1.0, where, 3.0, 0.7), theta[on_circle])).max() < 1e-12


def test_two_double_roots_and_a_quadruple_root():
    theta, on_circle, _ = _trig_quartic_roots(*coefficients(1.0, 0.4, 1.0, -2.0))
    assert {round(float(t), 5) for t in theta[on_circle]} == {0.4, -2.0}
    # (1 - cos(t - 0.4))²: a quadruple root splits by about eps ** (1/4) ~ 1e-4, beyond the acceptance radius,
    # so it is not taken for real; its four angles still point at it (subproblem 6 keeps the nearest candidate)
    theta, on_circle, _ = _trig_quartic_roots(*coefficients(1.0, 0.4, 1.0, 0.4))
    assert not on_circle.any() and (angle_gap(theta, 0.4) < 1e-3).all()


@pytest.mark.parametrize("beyond, real", [(1e-14, True), (1e-12, True), (1e-8, False), (1e-4, False)])
def test_the_circle_boundary_a_tangent_just_missed(beyond, real):
    """p0 = 1 + δ: no real root, the pair lies sqrt(2δ) off the circle. Within the acceptance radius it is
    the tangent root that rounding moved off the circle (the caller's residual test judges it); beyond, none."""
    alphas = coefficients(1.0 + beyond, 1.0, 3.0, 0.0)
    assert (np.sqrt(2 * beyond) <= _ON_UNIT_CIRCLE) == real
    theta, on_circle, _ = _trig_quartic_roots(*alphas)
    assert on_circle.any() == real
    assert angle_gap(theta, 1.0).min() < DOUBLE_ROOT  # the nearest angle is there either way, for the caller


@pytest.mark.parametrize("lead", [0.0, 1e-14, 1e-10, 1e-9, 1e-7, 1e-5])
def test_a_nearly_vanishing_degree_two_part(lead):
    """0.6 cos t + 0.8 sin t = 0.25 plus lead cos 2t: around the threshold where the harmonic equation is
    solved instead, the two real roots stay within about ``lead`` of the harmonic ones, and the other two
    (|z| about 1 / lead) are never taken for real."""
    alphas = (np.array(-0.25), np.array(0.6), np.array(0.8), np.array(lead), np.array(0.0))
    theta, on_circle, double = _trig_quartic_roots(*alphas)
    phi, half = np.arctan2(0.8, 0.6), np.arccos(0.25)
    assert on_circle.sum() == 2 and not double
    for root in (phi + half, phi - half):
        assert angle_gap(theta[on_circle], root).min() < 10 * lead + 1e-12
    assert (np.abs(value(alphas, theta[on_circle])) < 10 * lead + 1e-12).all()


def test_the_harmonic_tangent_is_one_double_root():
    """cos t = 1 with no degree-2 part: one root, flagged double."""
    theta, on_circle, double = _trig_quartic_roots(*(np.array(x) for x in (-1.0, 1.0, 0.0, 0.0, 0.0)))
    assert double and on_circle.sum() == 1 and angle_gap(theta[on_circle], 0.0).max() < DOUBLE_ROOT


def test_no_real_root_still_gives_the_nearest_angles():
    alphas = coefficients(1.5, 0.3, -2.0, 1.1)  # both factors keep away from 0
    theta, on_circle, _ = _trig_quartic_roots(*alphas)
    assert not on_circle.any()
    assert angle_gap(theta, 0.3).min() < 1e-9  # the pair off the circle lies at the angle where 1.5 − cos is least


def test_batches_of_any_shape_and_a_vanishing_equation(rng):
    m1, m2 = rng.uniform(-np.pi, np.pi, (2, 2, 3))
    alphas = coefficients(0.5, m1, 2.0, m2)
    theta, on_circle, double = _trig_quartic_roots(*alphas)
    assert theta.shape == on_circle.shape == (2, 3, 4) and double.shape == (2, 3)
    assert (on_circle.sum(axis=-1) == 2).all()
    zero = np.zeros(3)
    assert _vanishes(np.array([0.0, 1e-13, 1e-11]), zero, zero, zero, zero, np.ones(3)).tolist() == [True, True,
                                                                                                     False]
