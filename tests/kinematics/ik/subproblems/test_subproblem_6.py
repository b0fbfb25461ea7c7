"""Subproblem 6 (two linear equations in two rotation angles) against random instances and an independent
multi-start Newton search."""

from __future__ import annotations

import numpy as np
import pytest

from service.kinematics.ik._screws import rotate_about
from service.kinematics.ik.subproblems import subproblem_6
from tests.ik_helpers import angle_gap


def _unit(x: np.ndarray) -> np.ndarray:
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def _sides(k1, k2, H, P, t1, t2):
    """Left-hand sides of both equations at angles t1, t2 of shape (N, ...)."""
    def term(h, k, t, p):
        return np.einsum("n...i,n...i->n...", np.broadcast_to(h, p.shape[:1] + np.shape(t)[1:] + (3,)),
                         rotate_about(k, t, np.broadcast_to(p, p.shape[:1] + np.shape(t)[1:] + (3,))))
    return (term(H[0], k1, t1, P[0]) + term(H[1], k2, t2, P[1]),
            term(H[2], k1, t1, P[2]) + term(H[3], k2, t2, P[3]))


def _instances(seed: int, count: int):
    rng = np.random.default_rng(seed)
    k1, k2 = _unit(rng.normal(size=3)), _unit(rng.normal(size=3))
    H = [rng.normal(size=(count, 1, 3)) for _ in range(4)]
    P = [rng.normal(size=(count, 1, 3)) for _ in range(4)]
    t1, t2 = rng.uniform(-np.pi, np.pi, (count, 1)), rng.uniform(-np.pi, np.pi, (count, 1))
    d1, d2 = _sides(k1, k2, H, P, t1, t2)
    return k1, k2, [h[:, 0] for h in H], [p[:, 0] for p in P], t1[:, 0], t2[:, 0], d1[:, 0], d2[:, 0]


def _solve(k1, k2, H, P, d1, d2):
    return subproblem_6(k1, k2, H[0], P[0], H[1], P[1], d1, H[2], P[2], H[3], P[3], d2)


def test_the_generating_angles_are_among_the_roots_and_every_root_solves_both_equations():
    k1, k2, H, P, t1, t2, d1, d2 = _instances(seed=0, count=5000)
    sol = _solve(k1, k2, H, P, d1, d2)
    hit = (sol.valid & (angle_gap(sol.theta1, t1[:, None]) < 1e-7) & (angle_gap(sol.theta2, t2[:, None]) < 1e-7))
    assert hit.any(axis=1).all()
    assert (sol.exact == sol.valid).all()  # every instance has its generating root, so no least-squares slot
    e1, e2 = _sides(k1, k2, [h[:, None] for h in H], [p[:, None] for p in P],
                    np.where(sol.valid, sol.theta1, 0.0), np.where(sol.valid, sol.theta2, 0.0))
    scale = sum(np.linalg.norm(h, axis=-1) * np.linalg.norm(p, axis=-1) for h, p in zip(H, P))[:, None]
    miss = np.maximum(np.abs(e1 - d1[:, None]), np.abs(e2 - d2[:, None])) / scale
    assert miss[sol.valid].max() <= 1e-9
    counts = sol.valid.sum(axis=1)
    assert set(np.unique(counts)) <= {1, 2, 3, 4} and (counts == 4).any() and (counts == 2).any()


def _newton_roots(k1, k2, H, P, d1, d2, seeds: int = 16) -> list[np.ndarray]:
    """Independent oracle: Newton from a seeds × seeds grid of angle pairs on the 2 × 2 system, distinct roots."""
    grid = np.linspace(-np.pi, np.pi, seeds, endpoint=False)
    a, b = np.meshgrid(grid, grid, indexing="ij")
    t = np.stack([a.ravel(), b.ravel()], -1)[None].repeat(len(d1), 0)  # (N, S, 2)
    Hs, Ps = [h[:, None] for h in H], [p[:, None] for p in P]
    for _ in range(40):
        f1, f2 = _sides(k1, k2, Hs, Ps, t[..., 0], t[..., 1])
        eps = 1e-7
        g1a, g2a = _sides(k1, k2, Hs, Ps, t[..., 0] + eps, t[..., 1])
        g1b, g2b = _sides(k1, k2, Hs, Ps, t[..., 0], t[..., 1] + eps)
        J = np.stack([np.stack([(g1a - f1) / eps, (g1b - f1) / eps], -1),
                      np.stack([(g2a - f2) / eps, (g2b - f2) / eps], -1)], -2)
        F = np.stack([f1 - d1[:, None], f2 - d2[:, None]], -1)
        det = J[..., 0, 0] * J[..., 1, 1] - J[..., 0, 1] * J[..., 1, 0]
        det = np.where(np.abs(det) > 1e-14, det, 1e-14)
        dx = np.stack([(J[..., 1, 1] * F[..., 0] - J[..., 0, 1] * F[..., 1]) / det,
                       (-J[..., 1, 0] * F[..., 0] + J[..., 0, 0] * F[..., 1]) / det], -1)
        t = t - np.clip(dx, -0.5, 0.5)
    f1, f2 = _sides(k1, k2, Hs, Ps, t[..., 0], t[..., 1])
    good = np.maximum(np.abs(f1 - d1[:, None]), np.abs(f2 - d2[:, None])) < 1e-10
    roots = []
    for row in range(len(d1)):
        distinct: list[np.ndarray] = []
        for pair in t[row][good[row]]:
            if all(angle_gap(pair, other).max() > 1e-5 for other in distinct):
                distinct.append(pair)
        roots.append(np.array(distinct).reshape(-1, 2))
    return roots


def test_the_root_count_agrees_with_a_multistart_newton_search():
    k1, k2, H, P, t1, t2, d1, d2 = _instances(seed=3, count=80)
    sol = _solve(k1, k2, H, P, d1, d2)
    oracle = _newton_roots(k1, k2, H, P, d1, d2)
    for row, roots in enumerate(oracle):
        found = np.stack([sol.theta1[row], sol.theta2[row]], -1)[sol.valid[row]]
        assert len(found) == len(roots), row
        for pair in roots:
            assert (angle_gap(found, pair).max(axis=1) < 1e-6).any()


def test_decoupled_equations_give_every_combination():
    """Each equation in one angle only (both blocks singular): cos t1 = 0.5 and sin t2 = 0.5, 2 × 2 roots."""
    x, y, z = np.eye(3)
    sol = subproblem_6(z, z, x, x, x, np.zeros(3), 0.5, x, np.zeros(3), y, x, 0.5)
    found = sorted(zip(np.degrees(sol.theta1[sol.valid]).round(9), np.degrees(sol.theta2[sol.valid]).round(9)))
    assert found == [(-60.0, 30.0), (-60.0, 150.0), (60.0, 30.0), (60.0, 150.0)]
    assert not sol.degenerate and sol.exact[sol.valid].all()


def test_no_root_leaves_one_inexact_candidate_and_a_double_root_is_merged():
    x, y, z = np.eye(3)
    # cos t1 + cos t2 = 3 has no solution; the nearest pair is t1 = t2 = 0
    miss = subproblem_6(z, z, x, x, x, x, 3.0, y, x, y, -x, 0.0)
    assert miss.valid.tolist() == [True, False, False, False] and not miss.exact.any()
    assert np.allclose([miss.theta1[0], miss.theta2[0]], 0.0, atol=1e-6)
    # cos t1 + cos t2 = 2 (and sin t1 = sin t2): the single, double root t1 = t2 = 0
    touch = subproblem_6(z, z, x, x, x, x, 2.0, y, x, y, -x, 0.0)
    assert touch.valid.sum() == 1 and touch.merged
    assert np.allclose([touch.theta1[0], touch.theta2[0]], 0.0, atol=1e-6)


@pytest.mark.parametrize("shape", [(), (7,), (3, 5)])
def test_batch_shapes_lead_every_result(shape):
    rng = np.random.default_rng(5)
    k1, k2 = _unit(rng.normal(size=3)), _unit(rng.normal(size=3))
    vectors = [rng.normal(size=shape + (3,)) for _ in range(8)]
    sol = subproblem_6(k1, k2, *vectors[:4], np.zeros(shape), *vectors[4:], np.zeros(shape))
    assert sol.theta1.shape == sol.valid.shape == shape + (4,) and sol.merged.shape == shape


def test_an_angle_that_no_equation_fixes_is_free():
    """theta1 enters neither equation (p1, p3 on k1): cos t2 = 0.6, sin t2 = 0.8, theta1 free."""
    x, y, z = np.eye(3)
    sol = subproblem_6(z, z, x, z, x, x, 0.6, x, z, y, x, 0.8)
    assert sol.degenerate and sol.valid.tolist() == [True, False, False, False] and sol.exact[0]
    assert sol.theta1[0] == 0.0 and np.isclose(sol.theta2[0], np.arctan2(0.8, 0.6))
