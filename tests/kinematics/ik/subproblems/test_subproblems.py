"""Tests for the geometric IK subproblems.

Each subproblem is checked the same way:

* random exact instances built from known angles. The known angle is among the
  candidates, and every exact candidate satisfies the equation;
* batch results equal row-by-row results;
* infeasible instances give least-squares answers at least as good as a dense
  grid search;
* degenerate, tangent and boundary cases are flagged.
"""

from __future__ import annotations

import ast
import doctest
import importlib
import pathlib
import pkgutil

import numpy as np
import pytest

from service.kinematics import InvalidInputError
from service.kinematics._tolerances import DUPLICATE_TOLERANCE
from service.kinematics.ik import subproblems
from service.kinematics.ik.subproblems import _roots
from service.kinematics.ik.subproblems import (
    AnglePairSolutions,
    AngleSolutions,
    DisplacementSolutions,
    planar_two_link_elbow,
    prismatic_to_distance,
    prismatic_to_plane,
    subproblem_1,
    subproblem_2,
    subproblem_2_chain,
    subproblem_3,
    subproblem_4,
)
from tests.ik_helpers import angle_gap, wrapped

N_AXES = 10  # axes are constant per call: 10 random axes x 100 rows = 1,000 instances
N_ROWS = 100
GRID = np.linspace(-np.pi, np.pi, 10_000, endpoint=False)
RESIDUAL = 1e-12  # relative residual every exact candidate must meet
ANGLE = 1e-8  # radians: recovering the known angle


# ---------------------------------------------------------------------------
# Helpers: an independent Rodrigues rotation and comparisons
# ---------------------------------------------------------------------------


def rotate(k, theta, p):
    """``R(k, theta) p`` by Rodrigues' formula; broadcasts ``theta`` (...) against ``p`` (..., 3)."""
    k = np.asarray(k, dtype=float)
    p = np.asarray(p, dtype=float)
    theta = np.asarray(theta, dtype=float)[..., None]
    return p * np.cos(theta) + np.cross(k, p) * np.sin(theta) + k * (p @ k)[..., None] * (1.0 - np.cos(theta))


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def random_unit(rng, *shape):
    return unit(rng.normal(size=(*shape, 3)))


def gap_to_candidates(theta, valid, known):
    """Distance from ``known`` (...) to the nearest valid candidate in ``theta`` (..., m)."""
    return np.where(valid, angle_gap(theta, np.asarray(known)[..., None]), np.inf).min(axis=-1)


def assert_rows_match(batch, solve_row, rows):
    """Every field of ``batch`` at row i equals the single-row call ``solve_row(i)``."""
    for i in rows:
        single = solve_row(i)
        assert type(single) is type(batch)
        for name, b_value, s_value in zip(batch._fields, batch, single):
            b_row = b_value[i]
            assert np.shape(s_value) == np.shape(b_row), name
            if b_row.dtype == bool:
                np.testing.assert_array_equal(s_value, b_row, err_msg=name)
            else:
                np.testing.assert_allclose(s_value, b_row, rtol=0, atol=1e-12, err_msg=name)


def assert_record_shapes(sol, batch_shape, m):
    values = sol[:-4]  # theta / theta1, theta2 / s
    for value in values:
        assert value.shape == (*batch_shape, m)
    assert sol.valid.shape == sol.exact.shape == (*batch_shape, m)
    assert sol.degenerate.shape == sol.merged.shape == batch_shape
    assert sol.valid.dtype == sol.exact.dtype == sol.degenerate.dtype == sol.merged.dtype == bool
    # A missing candidate is NaN, never exact; the first slot always exists.
    assert sol.valid[..., 0].all()
    for value in values:
        assert np.array_equal(np.isnan(value), ~sol.valid)
    assert not (sol.exact & ~sol.valid).any()


def assert_generic_two_roots(sol, gap, distinct):
    """Exact two-root instances built from a known angle.

    ``gap`` (rows,) is the distance from the known angle to the nearest
    candidate, and ``distinct`` (rows,) the distance between the two candidates.
    A random instance only rarely lands so close to tangency that its roots
    merge. Such rows report one exact root near the known one. Every other row
    has two distinct exact roots, one of them the known angle.
    """
    assert sol.exact[:, 0].all() and not sol.degenerate.any()
    merged = sol.merged
    assert merged.mean() <= 0.01
    assert np.array_equal(sol.valid[:, 1], ~merged) and np.array_equal(sol.exact[:, 1], ~merged)
    assert (gap[~merged] < ANGLE).all() and (gap[merged] < 1e-4).all()
    assert (distinct[~merged] > DUPLICATE_TOLERANCE).all()


def assert_exact_two_root_instances(sol, known, reached, delta, scale, solve_row):
    """Exact instances of a two-root subproblem, N_ROWS of them built from the angles ``known``: the record's
    shapes, the generic two roots (:func:`assert_generic_two_roots`), every root's value ``reached`` (N_ROWS, 2)
    equal to ``delta`` within RESIDUAL of ``scale`` (N_ROWS, 1), and every seventh row solved alone
    (``solve_row``) as in the batch."""
    assert_record_shapes(sol, (N_ROWS,), 2)
    distinct = angle_gap(sol.theta[:, 0], sol.theta[:, 1])
    assert_generic_two_roots(sol, gap_to_candidates(sol.theta, sol.valid, known), distinct)
    assert not (np.abs(reached - delta[:, None]) > RESIDUAL * scale).any()  # NaN where no root
    assert_rows_match(sol, solve_row, range(0, N_ROWS, 7))


def test_rotation_convention_is_right_handed():
    np.testing.assert_allclose(rotate([0, 0, 1], np.pi / 2, [1, 0, 0]), [0, 1, 0], atol=1e-15)
    sol = subproblem_1([0, 0, 1], [1, 0, 0], [0, 1, 0])
    np.testing.assert_allclose(sol.theta, [np.pi / 2], rtol=0, atol=1e-15)


# ---------------------------------------------------------------------------
# Subproblem 1
# ---------------------------------------------------------------------------


def sp1_residual(k, theta, p, q):
    return np.linalg.norm(rotate(k, theta, p) - q, axis=-1)


def test_sp1_exact_instances(rng):
    for _ in range(N_AXES):
        k = random_unit(rng)
        p = rng.normal(size=(N_ROWS, 3)) * rng.uniform(0.1, 10.0, size=(N_ROWS, 1))
        theta = rng.uniform(-np.pi, np.pi, N_ROWS)
        q = rotate(k, theta, p)
        sol = subproblem_1(k, p, q)
        assert_record_shapes(sol, (N_ROWS,), 1)
        assert sol.exact.all() and not sol.degenerate.any() and not sol.merged.any()
        assert gap_to_candidates(sol.theta, sol.valid, theta).max() < ANGLE
        residual = sp1_residual(k, sol.theta[:, 0], p, q)
        assert (residual <= RESIDUAL * np.linalg.norm(p, axis=-1)).all()
        assert ((sol.theta > -np.pi) & (sol.theta <= np.pi)).all()
        assert_rows_match(sol, lambda i: subproblem_1(k, p[i], q[i]), range(0, N_ROWS, 7))


def test_sp1_least_squares_beats_grid(rng):
    k = random_unit(rng)
    p = rng.normal(size=(200, 3))
    q = rotate(k, rng.uniform(-np.pi, np.pi, 200), p)
    q[:100] *= rng.uniform(0.5, 1.5, size=(100, 1))  # wrong distance from the axis
    q[100:] += rng.uniform(-0.2, 0.2, size=(100, 1)) * k  # wrong height along the axis
    sol = subproblem_1(k, p, q)
    assert not sol.exact.any() and sol.valid.all()
    best = sp1_residual(k, sol.theta[:, 0], p, q)
    grid = sp1_residual(k, GRID[None, :], p[:, None, :], q[:, None, :]).min(axis=1)
    assert (best <= grid + 1e-12).all()


def test_sp1_degenerate_and_tolerance_is_relative():
    k = np.array([0.0, 0.6, 0.8])
    for scale in (1e-6, 1.0, 1e6):
        on_axis = scale * 2.0 * k
        off_axis = scale * np.array([1.0, 0.0, 0.0])
        # p on the axis: every angle solves p -> p, none solves p -> off-axis point.
        sol = subproblem_1(k, [on_axis, on_axis, off_axis], [on_axis, off_axis, on_axis])
        assert sol.degenerate.tolist() == [True, True, True]
        assert sol.exact[:, 0].tolist() == [True, False, False]
        assert sol.theta[:, 0].tolist() == [0.0, 0.0, 0.0]
        # Relative tolerance: 1e-12 off the axis is degenerate, 1e-6 is not.
        near = on_axis + scale * np.array([1e-12, 0.0, 0.0])
        far = on_axis + scale * np.array([1e-6, 0.0, 0.0])
        sol = subproblem_1(k, [near, far], [near, rotate(k, 1.0, far)])
        assert sol.degenerate.tolist() == [True, False]
        assert abs(sol.theta[1, 0] - 1.0) < 1e-6


def test_sp1_validates_axes_and_shapes():
    with pytest.raises(InvalidInputError, match="unit vector") as error:
        subproblem_1([0, 0, 2], [1, 0, 0], [0, 1, 0])
    assert error.value.location == ("k",)
    with pytest.raises(InvalidInputError, match="shape"):
        subproblem_1([0, 0, 1], [1, 0], [0, 1, 0])
    with pytest.raises(ValueError, match="shape"):
        subproblem_1([[0, 0, 1]], [1, 0, 0], [0, 1, 0])


# ---------------------------------------------------------------------------
# Subproblem 2
# ---------------------------------------------------------------------------


def sp2_residual(k1, k2, theta1, theta2, p, q):
    return np.linalg.norm(rotate(k1, theta1, p) - rotate(k2, theta2, q), axis=-1)


def exact_pair_residuals(sol, k1, k2, p, q):
    """Residuals of every valid exact candidate (NaN elsewhere)."""
    res = sp2_residual(k1, k2, sol.theta1, sol.theta2, p[..., None, :], q[..., None, :])
    return np.where(sol.exact, res, np.nan)


def pair_gap(sol, theta1, theta2):
    gap = np.maximum(angle_gap(sol.theta1, theta1[:, None]), angle_gap(sol.theta2, theta2[:, None]))
    return np.where(sol.valid, gap, np.inf).min(axis=-1)


def pair_distinct(sol):
    """Joint-space distance between the two candidates (NaN when there is one)."""
    return np.maximum(angle_gap(sol.theta1[:, 0], sol.theta1[:, 1]), angle_gap(sol.theta2[:, 0], sol.theta2[:, 1]))


def random_axis_pair(rng):
    while True:
        k1, k2 = random_unit(rng, 2)
        if np.linalg.norm(np.cross(k1, k2)) > 0.05:
            return k1, k2


def test_sp2_exact_instances(rng):
    for _ in range(N_AXES):
        k1, k2 = random_axis_pair(rng)
        q = rng.normal(size=(N_ROWS, 3)) * rng.uniform(0.1, 10.0, size=(N_ROWS, 1))
        theta1 = rng.uniform(-np.pi, np.pi, N_ROWS)
        theta2 = rng.uniform(-np.pi, np.pi, N_ROWS)
        p = rotate(k1, -theta1, rotate(k2, theta2, q))
        sol = subproblem_2(k1, k2, p, q)
        assert_record_shapes(sol, (N_ROWS,), 2)
        distinct = pair_distinct(sol)
        assert_generic_two_roots(sol, pair_gap(sol, theta1, theta2), distinct)
        scale = np.linalg.norm(q, axis=-1)[:, None]
        residual = exact_pair_residuals(sol, k1, k2, p, q)
        assert not (residual > RESIDUAL * scale).any()
        assert_rows_match(sol, lambda i: subproblem_2(k1, k2, p[i], q[i]), range(0, N_ROWS, 7))


def test_sp2_chain_exact_instances(rng):
    for _ in range(N_AXES):
        k1, k2 = random_axis_pair(rng)
        p = rng.normal(size=(N_ROWS, 3))
        a = rng.uniform(-np.pi, np.pi, N_ROWS)
        b = rng.uniform(-np.pi, np.pi, N_ROWS)
        q = rotate(k1, a, rotate(k2, b, p))
        sol = subproblem_2_chain(k1, k2, p, q)
        assert_record_shapes(sol, (N_ROWS,), 2)
        distinct = pair_distinct(sol)
        assert_generic_two_roots(sol, pair_gap(sol, a, b), distinct)
        reached = rotate(k1, sol.theta1, rotate(k2, sol.theta2, p[:, None, :]))
        residual = np.where(sol.exact, np.linalg.norm(reached - q[:, None, :], axis=-1), np.nan)
        assert not (residual > RESIDUAL * np.linalg.norm(p, axis=-1)[:, None]).any()
        assert ((sol.theta1 > -np.pi) & (sol.theta1 <= np.pi)).all()
        assert_rows_match(sol, lambda i: subproblem_2_chain(k1, k2, p[i], q[i]), range(0, N_ROWS, 11))


def grid_pair_min(k1, k2, p, q, n=100):
    """Smallest residual over an n x n grid of (theta1, theta2)."""
    angles = np.linspace(-np.pi, np.pi, n, endpoint=False)
    a = rotate(k1, angles[None, :], p[:, None, :])  # (rows, n, 3)
    b = rotate(k2, angles[None, :], q[:, None, :])
    return np.linalg.norm(a[:, :, None, :] - b[:, None, :, :], axis=-1).min(axis=(1, 2))


def test_sp2_least_squares_unequal_norms(rng):
    k1, k2 = random_axis_pair(rng)
    q = rng.normal(size=(60, 3))
    p = rotate(k1, -rng.uniform(-3, 3, 60), rotate(k2, rng.uniform(-3, 3, 60), q)) * 1.2
    sol = subproblem_2(k1, k2, p, q)
    assert not sol.exact.any()
    assert sol.valid.all()  # the cones still cross: two least-squares minimisers
    res = sp2_residual(k1, k2, sol.theta1, sol.theta2, p[:, None, :], q[:, None, :])
    assert (res <= grid_pair_min(k1, k2, p, q)[:, None] + 1e-12).all()
    # The minimum is the norm difference.
    np.testing.assert_allclose(res, np.repeat(0.2 * np.linalg.norm(q, axis=-1)[:, None], 2, axis=1), rtol=1e-9)


@pytest.mark.parametrize("layout", ["apart", "nested", "opposite"])
def test_sp2_least_squares_when_cones_miss(rng, layout):
    k1, k2 = random_axis_pair(rng)
    psi = np.arccos(k1 @ k2)
    phi1, phi2 = {
        "apart": (0.3 * psi, 0.3 * psi),  # phi1 + phi2 < psi
        "nested": (psi + 0.4 * (np.pi - psi), 0.2 * (np.pi - psi)),  # phi1 > phi2 + psi
        "opposite": (np.pi - 0.2 * psi, np.pi - 0.3 * psi),  # phi1 + phi2 > 2 pi - psi
    }[layout]
    rows = 40

    def on_cone(k, phi):
        perp = unit(np.cross(k, rng.normal(size=(rows, 3))))
        return np.cos(phi) * k + np.sin(phi) * perp

    radius = rng.uniform(0.5, 2.0, size=(rows, 1))
    p = radius * on_cone(k1, phi1)
    q = radius * on_cone(k2, phi2)
    sol = subproblem_2(k1, k2, p, q)
    assert not sol.exact.any() and not sol.merged.any() and not sol.degenerate.any()
    assert sol.valid.tolist() == [[True, False]] * rows
    res = sp2_residual(k1, k2, sol.theta1[:, 0], sol.theta2[:, 0], p, q)
    assert (res <= grid_pair_min(k1, k2, p, q) + 1e-12).all()
    assert (res > 1e-3).all()


def test_sp2_tangent_cones_merge(rng):
    for _ in range(N_AXES):
        k1, k2 = random_axis_pair(rng)
        normal = unit(np.cross(k1, k2))
        # Any direction in the plane of k1 and k2 is a point where the two cones touch.
        touch = rotate(normal, rng.uniform(-np.pi, np.pi, N_ROWS), k1)
        theta1 = rng.uniform(-np.pi, np.pi, N_ROWS)
        theta2 = rng.uniform(-np.pi, np.pi, N_ROWS)
        radius = rng.uniform(0.5, 2.0, size=(N_ROWS, 1))
        p = radius * rotate(k1, -theta1, touch)
        q = radius * rotate(k2, -theta2, touch)
        keep = (np.linalg.norm(np.cross(k1, p), axis=-1) > 1e-3) & (np.linalg.norm(np.cross(k2, q), axis=-1) > 1e-3)
        p, q, theta1, theta2 = p[keep], q[keep], theta1[keep], theta2[keep]
        sol = subproblem_2(k1, k2, p, q)
        assert sol.merged.all() and not sol.degenerate.any()
        assert sol.valid.tolist() == sol.exact.tolist() == [[True, False]] * len(p)
        assert pair_gap(sol, theta1, theta2).max() < 1e-6
        res = sp2_residual(k1, k2, sol.theta1[:, 0], sol.theta2[:, 0], p, q)
        assert (res <= RESIDUAL * radius[keep, 0]).all()


@pytest.mark.parametrize("split", [1e-12, 1e-9, 1e-7, 1e-6])
def test_sp2_tangency_split_by_rounding_returns_the_touching_root(rng, split):
    """Cones of half-angle 45° about z and x touch at (1, 0, 1)/√2; the cone of q made ``split`` narrower (a
    tangency an upstream error split, issue 22.6): the first slot is the touching pair, its residual within
    the split, reported merged, and never an empty answer. p and q start anywhere on their circles."""
    k1, k2 = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])
    p = rotate(k1, rng.uniform(-np.pi, np.pi, N_ROWS), np.array([1.0, 0.0, 1.0]) / np.sqrt(2))
    q = rotate(k2, rng.uniform(-np.pi, np.pi, N_ROWS), np.array([np.cos(np.pi / 4 - split),
                                                                 np.sin(np.pi / 4 - split), 0.0]))
    sol = subproblem_2(k1, k2, p, q)
    assert sol.merged.all() and not sol.degenerate.any()
    assert sol.valid[:, 0].all() and not sol.valid[:, 1].any()
    res = sp2_residual(k1, k2, sol.theta1[:, 0], sol.theta2[:, 0], p, q)
    assert (res <= 2 * split + RESIDUAL).all()
    # the touching direction: both turned onto (1, 0, 1)/√2 within the split
    turned = rotate(k1, sol.theta1[:, 0], p)
    assert np.abs(turned - np.array([1.0, 0.0, 1.0]) / np.sqrt(2)).max() <= 2 * split + 1e-12


@pytest.mark.parametrize("split", [1e-12, 1e-10, 1e-8])
def test_sp2_crossing_an_input_error_can_make_of_a_tangency_is_one_root(rng, split):
    """The same tangency with q's cone made ``split`` wider: the cones cross, at two roots about √split apart
    (5e-5 rad at 1e-9: each half misses the tangency the caller means by that much). Given inputs that carry an
    error of ``split`` (an arm's deviation from the family that computed them), such crossings are one root,
    merged, within the split of the touching direction; an error a thousand times smaller leaves them two."""
    k1, k2 = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])
    p = rotate(k1, rng.uniform(-np.pi, np.pi, N_ROWS), np.array([1.0, 0.0, 1.0]) / np.sqrt(2))
    q = rotate(k2, rng.uniform(-np.pi, np.pi, N_ROWS), np.array([np.cos(np.pi / 4 + split),
                                                                 np.sin(np.pi / 4 + split), 0.0]))
    apart = subproblem_2(k1, k2, p, q, error=split / 1000)
    assert not apart.merged.any() and apart.valid.all()
    assert (pair_gap_of_slots(apart) > 0.1 * np.sqrt(split)).all()
    sol = subproblem_2(k1, k2, p, q, error=split)
    assert sol.merged.all() and not sol.degenerate.any()
    assert sol.valid[:, 0].all() and not sol.valid[:, 1].any()
    turned = rotate(k1, sol.theta1[:, 0], p)
    assert np.abs(turned - np.array([1.0, 0.0, 1.0]) / np.sqrt(2)).max() <= 2 * split + 1e-12
    chain = subproblem_2_chain(k1, k2, q, p, error=split)  # the chain form passes it on
    assert chain.merged.all()


def pair_gap_of_slots(sol) -> np.ndarray:
    """How far apart (rad, the larger of the two joints) each row's two roots are."""
    return np.maximum(angle_gap(sol.theta1[:, 0], sol.theta1[:, 1]), angle_gap(sol.theta2[:, 0], sol.theta2[:, 1]))


def test_sp2_clear_miss_is_not_a_tangency(rng):
    """Cones apart by 1e-3 (far beyond sqrt(GEOMETRY_TOLERANCE)) are a miss: least squares, not merged."""
    k1, k2 = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])
    # both cones of half-angle 45° touch at (1, 0, 1)/√2; tilt q's cone 1e-3 narrower
    p = np.array([1.0, 0.0, 1.0]) / np.sqrt(2)
    q = np.array([np.cos(np.pi / 4 - 1e-3), np.sin(np.pi / 4 - 1e-3), 0.0])
    sol = subproblem_2(k1, k2, p, q)
    assert not sol.merged and not sol.exact.any() and sol.valid.tolist() == [True, False]


def test_sp2_free_joint_is_degenerate(rng):
    k1, k2 = random_axis_pair(rng)
    theta2 = rng.uniform(-np.pi, np.pi, 20)
    # p on k1: theta1 is free, theta2 turns q onto p.
    p = np.broadcast_to(1.5 * k1, (20, 3))
    q = rotate(k2, -theta2, p)
    sol = subproblem_2(k1, k2, p, q)
    assert sol.degenerate.all() and not sol.merged.any()
    assert sol.valid.tolist() == sol.exact.tolist() == [[True, False]] * 20
    assert (sol.theta1[:, 0] == 0.0).all()
    assert angle_gap(sol.theta2[:, 0], theta2).max() < ANGLE
    # q on k2: theta2 is free (mirror image), and an unreachable p is least squares.
    q = np.broadcast_to(-2.0 * k2, (20, 3))
    p = rotate(k1, -theta2, q)
    sol = subproblem_2(k1, k2, np.concatenate([p, 1.1 * p]), np.concatenate([q, q]))
    assert sol.degenerate.all()
    assert sol.exact[:, 0].tolist() == [True] * 20 + [False] * 20
    assert (sol.theta2[:, 0] == 0.0).all()
    assert angle_gap(sol.theta1[:20, 0], theta2).max() < ANGLE
    # Zero vectors: both joints free, exact.
    sol = subproblem_2(k1, k2, np.zeros(3), np.zeros(3))
    assert sol.degenerate.item() and sol.exact.tolist() == [True, False]
    assert sol.theta1.tolist()[0] == sol.theta2.tolist()[0] == 0.0


def test_sp2_chain_free_joints_follow_paden_kahan_form(rng):
    k1, k2 = random_axis_pair(rng)
    # p on k2: theta2 is free in R(k1, theta1) R(k2, theta2) p = q.
    a = 0.7
    q = rotate(k1, a, k2)
    sol = subproblem_2_chain(k1, k2, k2, q)
    assert sol.degenerate.item() and sol.exact[0]
    assert sol.theta2[0] == 0.0 and abs(sol.theta1[0] - a) < ANGLE


def test_sp2_parallel_axes_raise():
    with pytest.raises(ValueError, match="parallel"):
        subproblem_2([0, 0, 1], [0, 0, -1], [1, 0, 0], [0, 1, 0])
    with pytest.raises(InvalidInputError, match="parallel"):
        subproblem_2_chain([0, 0, 1], [0, 0, 1], [1, 0, 0], [0, 1, 0])


# ---------------------------------------------------------------------------
# Subproblem 3
# ---------------------------------------------------------------------------


def sp3_distance(k, theta, p, q):
    return np.linalg.norm(rotate(k, theta, p) - q, axis=-1)


def sp3_range(k, p, q):
    """Smallest and largest distance ||R(k, theta) p - q|| over theta."""
    rp = np.linalg.norm(np.cross(k, p), axis=-1)
    rq = np.linalg.norm(np.cross(k, q), axis=-1)
    dh = (p - q) @ k
    return np.hypot(rp - rq, dh), np.hypot(rp + rq, dh)


def test_sp3_exact_instances(rng):
    for _ in range(N_AXES):
        k = random_unit(rng)
        p = rng.normal(size=(N_ROWS, 3))
        q = rng.normal(size=(N_ROWS, 3)) * rng.uniform(0.2, 5.0, size=(N_ROWS, 1))
        theta = rng.uniform(-np.pi, np.pi, N_ROWS)
        delta = sp3_distance(k, theta, p, q)
        sol = subproblem_3(k, p, q, delta)
        scale = (np.linalg.norm(p, axis=-1) + np.linalg.norm(q, axis=-1) + delta)[:, None]
        assert_exact_two_root_instances(sol, theta, sp3_distance(k, sol.theta, p[:, None, :], q[:, None, :]), delta,
                                        scale, lambda i: subproblem_3(k, p[i], q[i], delta[i]))


def test_sp3_least_squares_beats_grid(rng):
    k = random_unit(rng)
    p = rng.normal(size=(200, 3))
    q = rng.normal(size=(200, 3))
    low, high = sp3_range(k, p, q)
    delta = np.concatenate([high[:100] + 0.3, 0.5 * low[100:]])
    sol = subproblem_3(k, p, q, delta)
    assert not sol.exact.any() and not sol.merged.any() and not sol.degenerate.any()
    assert sol.valid.tolist() == [[True, False]] * 200
    best = np.abs(sp3_distance(k, sol.theta[:, 0], p, q) - delta)
    grid = np.abs(sp3_distance(k, GRID[None, :], p[:, None, :], q[:, None, :]) - delta[:, None]).min(axis=1)
    assert (best <= grid + 1e-12).all()


def test_sp3_boundary_roots_merge(rng):
    k = random_unit(rng)
    p = rng.normal(size=(200, 3))
    q = rng.normal(size=(200, 3))
    low, high = sp3_range(k, p, q)
    delta = np.concatenate([high[:100], low[100:]])
    sol = subproblem_3(k, p, q, delta)
    assert sol.merged.all() and not sol.degenerate.any()
    assert sol.valid.tolist() == sol.exact.tolist() == [[True, False]] * 200
    scale = np.linalg.norm(p, axis=-1) + np.linalg.norm(q, axis=-1) + delta
    assert (np.abs(sp3_distance(k, sol.theta[:, 0], p, q) - delta) <= RESIDUAL * scale).all()
    # Just inside the range the two roots separate again.
    inside = subproblem_3(k, p, q, np.concatenate([high[:100] * (1 - 1e-6), low[100:] * (1 + 1e-6)]))
    assert not inside.merged.any() and inside.valid.all() and inside.exact.all()


def test_sp3_degenerate_when_distance_is_constant():
    k = np.array([0.0, 0.0, 1.0])
    p_on_axis = np.array([0.0, 0.0, 2.0])
    q = np.array([1.0, 1.0, 0.0])
    constant = np.linalg.norm(p_on_axis - q)
    sol = subproblem_3(k, p_on_axis, q, [constant, constant + 0.1])
    assert sol.degenerate.tolist() == [True, True]
    assert sol.exact.tolist() == [[True, False], [False, False]]
    assert sol.theta[:, 0].tolist() == [0.0, 0.0]
    sol = subproblem_3(k, q, p_on_axis, constant)  # q on the axis
    assert sol.degenerate.item() and sol.exact[0]
    with pytest.raises(InvalidInputError, match="negative"):
        subproblem_3(k, q, p_on_axis, -1.0)




# ---------------------------------------------------------------------------
# Subproblem 4
# ---------------------------------------------------------------------------


def sp4_height(h, k, theta, p):
    return rotate(k, theta, p) @ h


def sp4_range(h, k, p):
    hk = h @ k
    spread = np.linalg.norm(h - hk * k) * np.linalg.norm(np.cross(k, p), axis=-1)
    centre = hk * (p @ k)
    return centre - spread, centre + spread


def test_sp4_exact_instances(rng):
    for _ in range(N_AXES):
        h, k = random_unit(rng, 2)
        p = rng.normal(size=(N_ROWS, 3)) * rng.uniform(0.1, 10.0, size=(N_ROWS, 1))
        theta = rng.uniform(-np.pi, np.pi, N_ROWS)
        delta = sp4_height(h, k, theta, p)
        sol = subproblem_4(h, k, p, delta)
        scale = (np.linalg.norm(p, axis=-1) + np.abs(delta))[:, None]
        assert_exact_two_root_instances(sol, theta, sp4_height(h, k, sol.theta, p[:, None, :]), delta, scale,
                                        lambda i: subproblem_4(h, k, p[i], delta[i]))


def test_sp4_least_squares_beats_grid(rng):
    h, k = random_unit(rng, 2)
    p = rng.normal(size=(200, 3))
    low, high = sp4_range(h, k, p)
    delta = np.concatenate([high[:100] + 0.2, low[100:] - 0.2])
    sol = subproblem_4(h, k, p, delta)
    assert not sol.exact.any() and not sol.merged.any()
    assert sol.valid.tolist() == [[True, False]] * 200
    best = np.abs(sp4_height(h, k, sol.theta[:, 0], p) - delta)
    grid = np.abs(sp4_height(h, k, GRID[None, :], p[:, None, :]) - delta[:, None]).min(axis=1)
    assert (best <= grid + 1e-12).all()
    np.testing.assert_allclose(best, 0.2, rtol=1e-9)


def test_sp4_boundary_roots_merge(rng):
    h, k = random_unit(rng, 2)
    p = rng.normal(size=(200, 3))
    low, high = sp4_range(h, k, p)
    delta = np.concatenate([high[:100], low[100:]])
    sol = subproblem_4(h, k, p, delta)
    assert sol.merged.all()
    assert sol.valid.tolist() == sol.exact.tolist() == [[True, False]] * 200
    scale = np.linalg.norm(p, axis=-1) + np.abs(delta)
    assert (np.abs(sp4_height(h, k, sol.theta[:, 0], p) - delta) <= RESIDUAL * scale).all()


def test_sp4_degenerate_when_height_is_constant():
    k = np.array([0.0, 0.0, 1.0])
    p = np.array([1.0, 2.0, 3.0])
    sol = subproblem_4(k, k, p, [3.0, 3.5])  # h parallel to k
    assert sol.degenerate.tolist() == [True, True]
    assert sol.exact[:, 0].tolist() == [True, False]
    assert sol.valid.tolist() == [[True, False], [True, False]]
    sol = subproblem_4([1.0, 0.0, 0.0], k, [0.0, 0.0, 3.0], 0.0)  # p on the axis
    assert sol.degenerate.item() and sol.exact[0] and sol.theta[0] == 0.0


# ---------------------------------------------------------------------------
# Planar two-link elbow
# ---------------------------------------------------------------------------


def two_link_reach(l1, l2, elbow):
    return np.hypot(l1 + l2 * np.cos(elbow), l2 * np.sin(elbow))


def test_two_link_exact_instances_and_mapping_to_sp3(rng):
    for _ in range(N_AXES):
        l1, l2 = rng.uniform(0.2, 2.0, 2)
        elbow = rng.uniform(-np.pi, np.pi, N_ROWS)
        r = two_link_reach(l1, l2, elbow)
        sol = planar_two_link_elbow(l1, l2, r)
        assert_record_shapes(sol, (N_ROWS,), 2)
        assert sol.exact.all() and not sol.merged.any() and not sol.degenerate.any()
        assert gap_to_candidates(sol.theta, sol.valid, elbow).max() < ANGLE
        # Branches +acos(D), -acos(D).
        np.testing.assert_allclose(sol.theta[:, 0], np.abs(elbow), atol=ANGLE)
        np.testing.assert_allclose(sol.theta[:, 1], -sol.theta[:, 0], rtol=0, atol=0)
        reached = two_link_reach(l1, l2, sol.theta)
        assert (np.abs(reached - r[:, None]) <= RESIDUAL * (l1 + l2)).all()
        # The documented mapping: subproblem 3 with k = z, p = (l2, 0, 0), q = (-l1, 0, 0).
        via_sp3 = subproblem_3([0, 0, 1], [l2, 0, 0], [-l1, 0, 0], r)
        assert via_sp3.exact.all()
        np.testing.assert_allclose(np.sort(via_sp3.theta, axis=1), np.sort(sol.theta, axis=1), atol=1e-12)
        assert_rows_match(sol, lambda i: planar_two_link_elbow(l1, l2, r[i]), range(0, N_ROWS, 9))


def test_two_link_boundary_and_unreachable():
    l1, l2 = 1.0, 0.6
    r = np.array([1.6, 0.4, 1.7, 0.3, 0.0])
    sol = planar_two_link_elbow(l1, l2, r)
    assert sol.merged.tolist() == [True, True, False, False, False]
    assert sol.exact[:, 0].tolist() == [True, True, False, False, False]
    assert sol.valid[:, 1].tolist() == [False] * 5
    np.testing.assert_allclose(np.abs(sol.theta[:, 0]), [0.0, np.pi, 0.0, np.pi, np.pi], atol=1e-7)
    grid = np.abs(two_link_reach(l1, l2, GRID[None, :]) - r[:, None]).min(axis=1)
    assert (np.abs(two_link_reach(l1, l2, sol.theta[:, 0]) - r) <= grid + 1e-12).all()
    # Equal links folded onto the base: D = -1, a merged exact root at pi.
    folded = planar_two_link_elbow(0.5, 0.5, 0.0)
    assert folded.merged.item() and folded.exact[0] and abs(abs(folded.theta[0]) - np.pi) < 1e-7


def test_two_link_degenerate_and_validation():
    sol = planar_two_link_elbow(1.0, 0.0, [1.0, 2.0])
    assert sol.degenerate.tolist() == [True, True]
    assert sol.exact[:, 0].tolist() == [True, False]
    # A second link below tolerance (5e-10 of a scale of about 2) is degenerate too.
    # ``exact`` then speaks for the representative q2 = 0 (reach 1 + 5e-10).
    # It is true at r = 1 + 5e-10 and false at r = 1 - 2.2e-9, even though
    # some q2 (pi) would come within tolerance there.
    l2 = 5e-10
    sol = planar_two_link_elbow(1.0, l2, np.sqrt([(1 + l2) ** 2, 1 - 4.4e-9 + l2**2]))
    assert sol.degenerate.tolist() == [True, True]
    assert sol.exact[:, 0].tolist() == [True, False]
    with pytest.raises(InvalidInputError, match="l2"):
        planar_two_link_elbow(1.0, -1.0, 1.0)
    with pytest.raises(InvalidInputError, match="negative"):
        planar_two_link_elbow(1.0, 1.0, [-1.0])


# ---------------------------------------------------------------------------
# Prismatic helpers
# ---------------------------------------------------------------------------


def slide_distance(p, v, s, q):
    return np.linalg.norm(p + s[..., None] * v - q, axis=-1)


def test_prismatic_to_distance_exact_instances(rng):
    for _ in range(N_AXES):
        v = random_unit(rng)
        p = rng.normal(size=(N_ROWS, 3))
        q = rng.normal(size=(N_ROWS, 3)) * 3.0
        s = rng.uniform(-5.0, 5.0, N_ROWS)
        delta = slide_distance(p, v, s, q)
        sol = prismatic_to_distance(p, v, q, delta)
        assert_record_shapes(sol, (N_ROWS,), 2)
        assert sol.exact.all() and not sol.merged.any() and not sol.degenerate.any()
        scale = np.linalg.norm(p - q, axis=-1) + delta
        assert (np.abs(sol.s - s[:, None]).min(axis=1) <= 1e-9 * scale).all()
        assert (sol.s[:, 0] > sol.s[:, 1]).all()
        reached = slide_distance(p[:, None, :], v, sol.s, q[:, None, :])
        assert (np.abs(reached - delta[:, None]) <= RESIDUAL * scale[:, None]).all()
        assert_rows_match(sol, lambda i: prismatic_to_distance(p[i], v, q[i], delta[i]), range(0, N_ROWS, 7))


def test_prismatic_to_distance_least_squares_and_tangent(rng):
    v = random_unit(rng)
    p = rng.normal(size=(100, 3))
    q = rng.normal(size=(100, 3))
    w = p - q
    gap = np.linalg.norm(w - (w @ v)[:, None] * v, axis=-1)  # distance from q to the line
    sol = prismatic_to_distance(p, v, q, 0.5 * gap)
    assert not sol.exact.any() and not sol.merged.any()
    assert sol.valid.tolist() == [[True, False]] * 100
    grid_s = np.linspace(-10.0, 10.0, 10_000)
    grid = np.abs(slide_distance(p[:, None, :], v, grid_s[None, :], q[:, None, :]) - 0.5 * gap[:, None]).min(axis=1)
    best = np.abs(slide_distance(p, v, sol.s[:, 0], q) - 0.5 * gap)
    assert (best <= grid + 1e-12).all()
    tangent = prismatic_to_distance(p, v, q, gap)
    assert tangent.merged.all()
    assert tangent.valid.tolist() == tangent.exact.tolist() == [[True, False]] * 100
    np.testing.assert_allclose(tangent.s[:, 0], -(w @ v), rtol=0, atol=1e-12)


def test_prismatic_to_plane(rng):
    for _ in range(N_AXES):
        h, v = random_unit(rng, 2)
        p = rng.normal(size=(N_ROWS, 3))
        s = rng.uniform(-5.0, 5.0, N_ROWS)
        delta = (p + s[:, None] * v) @ h
        sol = prismatic_to_plane(h, p, v, delta)
        assert_record_shapes(sol, (N_ROWS,), 1)
        assert sol.exact.all() and not sol.degenerate.any() and not sol.merged.any()
        np.testing.assert_allclose(sol.s[:, 0], s, rtol=1e-9, atol=1e-9)
        reached = (p + sol.s[:, :1] * v) @ h
        assert (np.abs(reached - delta) <= RESIDUAL * (np.linalg.norm(p, axis=-1) + np.abs(delta)) * 10).all()
        assert_rows_match(sol, lambda i: prismatic_to_plane(h, p[i], v, delta[i]), range(0, N_ROWS, 7))
    # Sliding parallel to the plane (within tolerance): degenerate, exact only
    # when p is already in it.
    for v in ([1.0, 0.0, 0.0], unit([1.0, 0.0, 1e-12])):
        sol = prismatic_to_plane([0, 0, 1], [[1.0, 2.0, 3.0], [1.0, 2.0, 3.5]], v, 3.0)
        assert sol.degenerate.tolist() == [True, True]
        assert sol.exact[:, 0].tolist() == [True, False]
        assert sol.s[:, 0].tolist() == [0.0, 0.0]
    sol = prismatic_to_plane([0, 0, 1], [1.0, 2.0, 3.5], unit([1.0, 0.0, 1e-6]), 3.0)
    assert not sol.degenerate and sol.exact[0]
    np.testing.assert_allclose(sol.s, [-0.5e6], rtol=1e-9)


# ---------------------------------------------------------------------------
# Module hygiene
# ---------------------------------------------------------------------------


BROADCAST_CASES = {
    # name: (function, m, builder of (constants, p of shape (3,), data of shape (4, 5, 3), scalars of shape (5,)))
    "subproblem_1": (subproblem_1, 1, lambda k, h, p, q, d: ((k,), (p, q), ())),
    "subproblem_2": (subproblem_2, 2, lambda k, h, p, q, d: ((k, h), (p, q), ())),
    "subproblem_2_chain": (subproblem_2_chain, 2, lambda k, h, p, q, d: ((k, h), (q, p), ())),
    "subproblem_3": (subproblem_3, 2, lambda k, h, p, q, d: ((k,), (p, q), (d,))),
    "subproblem_4": (subproblem_4, 2, lambda k, h, p, q, d: ((h, k), (q,), (d,))),
}


@pytest.mark.parametrize("name", BROADCAST_CASES)
def test_data_broadcast_to_one_batch_shape(rng, name):
    solve, m, build = BROADCAST_CASES[name]
    k, h = random_unit(rng, 2)
    p = rng.normal(size=3)
    q = rng.normal(size=(4, 5, 3))
    d = rng.uniform(0.5, 2.0, size=5)
    constants, points, scalars = build(k, h, p, q, d)
    sol = solve(*constants, *points, *scalars)
    assert_record_shapes(sol, (4, 5), m)
    for i, j in [(0, 0), (2, 3), (3, 4)]:
        row_points = [x if x.shape == (3,) else x[i, j] for x in points]
        single = solve(*constants, *row_points, *[x[j] for x in scalars])
        assert_record_shapes(single, (), m)
        for name_, b_value, s_value in zip(sol._fields, sol, single):
            np.testing.assert_allclose(s_value, b_value[i, j], rtol=0, atol=1e-12, err_msg=name_)


def test_prismatic_data_broadcast(rng):
    v, h = random_unit(rng, 2)
    p = rng.normal(size=3)
    q = rng.normal(size=(4, 5, 3))
    d = rng.uniform(0.5, 2.0, size=5)
    sol = prismatic_to_distance(p, v, q, d)
    assert_record_shapes(sol, (4, 5), 2)
    np.testing.assert_allclose(prismatic_to_distance(p, v, q[2, 3], d[3]).s, sol.s[2, 3], rtol=0, atol=1e-12)
    sol = prismatic_to_plane(h, q, v, d)
    assert_record_shapes(sol, (4, 5), 1)
    np.testing.assert_allclose(prismatic_to_plane(h, q[2, 3], v, d[3]).s, sol.s[2, 3], rtol=0, atol=1e-12)


def test_single_rows_return_arrays():
    for sol, m in [
        (subproblem_1([0, 0, 1], [1, 0, 0], [0, 1, 0]), 1),
        (subproblem_2([0, 0, 1], [1, 0, 0], [1, 0, 0], [0, 1, 0]), 2),
        (subproblem_3([0, 0, 1], [1, 0, 0], [0, 1, 0], 1.0), 2),
        (subproblem_4([0, 1, 0], [0, 0, 1], [1, 0, 0], 0.5), 2),
        (planar_two_link_elbow(1.0, 1.0, 1.0), 2),
        (prismatic_to_distance([0, 0, 0], [1, 0, 0], [0, 1, 0], 2.0), 2),
        (prismatic_to_plane([0, 0, 1], [0, 0, 0], [0, 0, 1], 1.0), 1),
    ]:
        assert isinstance(sol, (AngleSolutions, AnglePairSolutions, DisplacementSolutions))
        assert all(isinstance(value, np.ndarray) for value in sol)
        assert_record_shapes(sol, (), m)


def package_modules():
    """Every module of the subproblems package, the package itself first."""
    return [subproblems] + [importlib.import_module(f"{subproblems.__name__}.{info.name}")
                            for info in pkgutil.iter_modules(subproblems.__path__)]


def test_docstring_examples():
    result = doctest.TestResults(failed=0, attempted=0)
    for module in package_modules():
        failed, attempted = doctest.testmod(module, extraglobs={"np": np})
        result = doctest.TestResults(result.failed + failed, result.attempted + attempted)
    assert result.attempted >= 10
    assert result.failed == 0


def test_core_imports_numpy_and_standard_library_only():
    imported = set()
    for module in package_modules():
        source = pathlib.Path(module.__file__).read_text()
        for node in ast.walk(ast.parse(source)):
            if isinstance(node, ast.Import):
                imported.update(alias.name.split(".")[0] for alias in node.names)
            elif isinstance(node, ast.ImportFrom) and node.level == 0:
                imported.add(node.module.split(".")[0])
    assert imported <= {"__future__", "math", "typing", "numpy"}


# ---------------------------------------------------------------------------
# Subproblem 5: p0 + R(k1, t1) p1 = R(k2, t2) (p2 + R(k3, t3) p3)
# ---------------------------------------------------------------------------


def sp5_instances(rng, known):
    """Random axes and points with p1 chosen so that the known angles (rows, 3) solve the equation."""
    k1, k2, k3 = random_unit(rng, 3)
    rows = len(known)
    p0, p2, p3 = rng.normal(size=(3, rows, 3))
    p1 = rotate(k1, -known[:, 0], rotate(k2, known[:, 1], p2 + rotate(k3, known[:, 2], p3)) - p0)
    return (k1, k2, k3), (p0, p1, p2, p3)


def sp5_residual(axes, points, sol):
    k1, k2, k3 = axes
    p0, p1, p2, p3 = (p[..., None, :] for p in points)
    left = p0 + rotate(k1, sol.theta1, p1)
    right = rotate(k2, sol.theta2, p2 + rotate(k3, sol.theta3, p3))
    scale = sum(np.linalg.norm(p, axis=-1) for p in (p0, p1, p2, p3))
    return np.linalg.norm(left - right, axis=-1) / scale


def test_sp5_exact_instances(rng):
    for _ in range(N_AXES):
        known = rng.uniform(-np.pi, np.pi, (N_ROWS, 3))
        axes, points = sp5_instances(rng, known)
        sol = subproblems.subproblem_5(*axes, *points)
        assert_record_shapes_sp5(sol, (N_ROWS,))
        gap = np.where(sol.valid[..., None], angle_gap(np.stack([sol.theta1, sol.theta2, sol.theta3], -1),
                                                        known[:, None, :]), np.inf).max(axis=-1).min(axis=-1)
        assert (gap < ANGLE).all()
        assert (sp5_residual(axes, points, sol)[sol.valid] < RESIDUAL).all()
        assert sol.exact[sol.valid].all()
        # a real trigonometric quartic has its real roots in pairs: 2 or 4 here (one is known)
        assert set(sol.valid.sum(axis=1).tolist()) <= {2, 4}
        assert_rows_match(sol, lambda i: subproblems.subproblem_5(*axes, *(p[i] for p in points)),
                          range(0, N_ROWS, 9))


def assert_record_shapes_sp5(sol, batch_shape):
    for value in (sol.theta1, sol.theta2, sol.theta3):
        assert value.shape == (*batch_shape, 4)
        assert np.array_equal(np.isnan(value), ~sol.valid)
    assert sol.degenerate.shape == sol.merged.shape == batch_shape
    assert not (sol.exact & ~sol.valid).any()


def test_sp5_roots_at_pi_are_ordinary(rng):
    """z = exp(i t) has no pole at t = π (a tangent half-angle would)."""
    known = np.array([[np.pi, 0.3, np.pi], [np.pi, np.pi, -0.7], [0.2, -1.0, np.pi]])
    axes, points = sp5_instances(rng, known)
    sol = subproblems.subproblem_5(*axes, *points)
    found = np.stack([sol.theta1, sol.theta2, sol.theta3], -1)
    gap = np.where(sol.valid[..., None], angle_gap(found, known[:, None, :]), np.inf).max(axis=-1).min(axis=-1)
    assert (gap < ANGLE).all()


def test_sp5_infeasible_degenerate_and_inseparable(rng):
    k1, k2, k3 = random_unit(rng, 3)
    p0, p2, p3 = rng.normal(size=(3, 3))
    # far out of reach: no root on the unit circle, no slot (no least-squares candidate for this one)
    far = subproblems.subproblem_5(k1, k2, k3, p0, 100 * rng.normal(size=3) + 1000 * k1[[1, 2, 0]], p2, p3)
    assert not far.valid.any()
    # p1 on k1: the left side does not depend on t1, which is free when the target is reachable
    t2, t3 = 0.4, -1.2
    right = rotate(k2, t2, p2 + rotate(k3, t3, p3))
    p1_free = 0.7 * k1
    p0_free = right - p1_free  # L = p0 + R(k1, t1) p1 = right for every t1
    sol = subproblems.subproblem_5(k1, k2, k3, p0_free, p1_free, p2, p3)
    assert sol.degenerate and sol.valid[0] and sol.theta1[0] == 0.0
    assert (sp5_residual((k1, k2, k3), (p0_free, p1_free, p2, p3), sol)[sol.valid] < 1e-9).all()
    # k2 ∥ k3: the height row does not involve t3 and neither block inverts: no slot (use subproblems 3, 4)
    assert not subproblems.subproblem_5(k1, k2, k2, p0, rng.normal(size=3), p2, p3).valid.any()


def test_sp5_quartic_that_drops_to_a_quadratic():
    """||f + G u||² = 1 with G a scaled rotation has no 2θ terms: the leading coefficient vanishes and the
    harmonic equation 2 g·u + c0 = 0 is what is left (here 0.6 cos θ + 0.8 sin θ = 0.25)."""
    theta, valid, double = _roots._trig_quartic_roots(
        np.array([-0.25]), np.array([0.6]), np.array([0.8]), np.array([0.0]), np.array([0.0]))
    phi, half = np.arctan2(0.8, 0.6), np.arccos(0.25)
    assert valid.sum() == 2 and not double[0]
    assert np.allclose(np.sort(theta[valid]), np.sort(wrapped([phi + half, phi - half])))
    # and the constant left when g vanishes too: identically zero (free) or never
    zeros = np.zeros(2)
    theta, valid, _ = _roots._trig_quartic_roots(np.array([0.0, 0.5]), zeros, zeros, zeros, zeros)
    free = _roots._vanishes(np.array([0.0, 0.5]), zeros, zeros, zeros, zeros, np.ones(2))
    assert free.tolist() == [True, False] and not valid[1].any()
    # every angle solves 0 = 0: the root finder gives one representative, angle 0 (the caller marks it free)
    assert valid[0].tolist() == [True, False, False, False] and theta[0, 0] == 0.0


