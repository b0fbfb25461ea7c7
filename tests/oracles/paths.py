"""Tool paths with exact derivatives, and a Jacobian by differences of FK: references for the trajectory tests.

Nothing here uses the code under test except forward kinematics (tested against the textbook on its own).
"""

from __future__ import annotations

import numpy as np

from service.kinematics import forward_kinematics
from tests.oracles.rotations import axis_angle


def spiral(t):
    """The paper's path (eq. 16, textbook.md §4.4) and its exact derivatives, each of shape (N, 3) [mm, s]."""
    t = np.asarray(t, dtype=float)
    w = np.pi / 2.0
    s, c, one = np.sin(w * t), np.cos(w * t), np.ones_like(t)
    D = np.stack((100.0 + 20.0 * s, -20.0 * c, 50.0 + 10.0 * t), axis=-1)
    Dd = np.stack((10.0 * np.pi * c, 10.0 * np.pi * s, 10.0 * one), axis=-1)
    Ddd = np.stack((-5.0 * np.pi**2 * s, 5.0 * np.pi**2 * c, 0.0 * one), axis=-1)
    return D, Dd, Ddd


def wobble(t, world_T_start: np.ndarray, radius: float, k1, k2):
    """A smooth pose path from ``world_T_start`` with its exact twist and acceleration (world frame).

    Position: ``p0 + ρ (sin t, 1 − cos t, ½ sin 2t)``. Orientation:
    ``R(k1, α(t)) R(k2, β(t)) R0`` with α = 0.2 sin t and β = 0.15 sin(1.3t + 0.4) (β = 0 when k2 is None), so
    ``ω = k1 α' + R(k1, α) k2 β'`` and ``ω' = k1 α'' + R(k1, α) k2 β'' + (k1 α') × (R(k1, α) k2 β')``.

    Returns (N, 4, 4) poses, (N, 6) twists [ṗ; ω] and (N, 6) accelerations [p̈; ω'].
    """
    t = np.asarray(t, dtype=float)
    p = world_T_start[:3, 3] + radius * np.stack([np.sin(t), 1 - np.cos(t), 0.5 * np.sin(2 * t)], axis=-1)
    pd = radius * np.stack([np.cos(t), np.sin(t), np.cos(2 * t)], axis=-1)
    pdd = radius * np.stack([-np.sin(t), np.cos(t), -2 * np.sin(2 * t)], axis=-1)
    a, ad, add = 0.2 * np.sin(t), 0.2 * np.cos(t), -0.2 * np.sin(t)
    phase = 1.3 * t + 0.4
    b, bd, bdd = 0.15 * np.sin(phase), 0.195 * np.cos(phase), -0.2535 * np.sin(phase)
    k1 = np.asarray(k1, dtype=float)
    k2 = np.zeros(3) if k2 is None else np.asarray(k2, dtype=float)
    poses = np.tile(np.eye(4), (len(t), 1, 1))
    omega, omegad = np.zeros((len(t), 3)), np.zeros((len(t), 3))
    for i in range(len(t)):
        Ra = axis_angle(k1, a[i])
        Rb = axis_angle(k2, b[i]) if k2.any() else np.eye(3)
        poses[i, :3, :3] = Ra @ Rb @ world_T_start[:3, :3]
        poses[i, :3, 3] = p[i]
        second = Ra @ k2 * bd[i]
        omega[i] = k1 * ad[i] + second
        omegad[i] = k1 * add[i] + Ra @ k2 * bdd[i] + np.cross(k1 * ad[i], second)
    return poses, np.concatenate([pd, omega], axis=1), np.concatenate([pdd, omegad], axis=1)


def difference_jacobian(robot, q: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """The geometric Jacobian (6, n) by central differences of forward kinematics.

    Column i: the tool origin's velocity and the angular velocity (from ``Ṙ Rᵀ``) for q̇ = e_i.
    """
    q = np.asarray(q, dtype=float)
    J = np.zeros((6, len(q)))
    R = forward_kinematics(robot, q)[:3, :3]
    for i in range(len(q)):
        step = np.zeros(len(q))
        step[i] = h
        plus, minus = forward_kinematics(robot, q + step), forward_kinematics(robot, q - step)
        J[:3, i] = (plus[:3, 3] - minus[:3, 3]) / (2 * h)
        W = (plus[:3, :3] - minus[:3, :3]) / (2 * h) @ R.T
        J[3:, i] = 0.5 * np.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0], W[1, 0] - W[0, 1]])
    return J


def scaled_sigma_min(robot, J: np.ndarray, rows: list[int]) -> float:
    """Smallest singular value of J's given rows, linear rows divided by the robot's size, slides multiplied."""
    L = robot.characteristic_length
    Js = J[rows] * np.array([1 / L if r < 3 else 1.0 for r in rows])[:, None]
    Js = Js * np.where(robot.is_revolute, 1.0, L)
    return float(np.linalg.svd(Js, compute_uv=False)[-1])


def _det(robot, q: np.ndarray) -> float:
    return float(np.linalg.det(difference_jacobian(robot, q)))


def _det_gradient(robot, q: np.ndarray, h: float = 1e-6) -> np.ndarray:
    step = np.eye(len(q)) * h
    return np.array([(_det(robot, q + e) - _det(robot, q - e)) / (2 * h) for e in step])


def near_singular_path(robot, q0, v, delta: float, t):
    """A joint path (6-joint arm) that passes near a singularity at t = 0.5 without crossing it, with its exact
    rates: q(t) = q* + s v + (δ + c s²) n, s = t − 0.5.

    q* is a singular configuration (det J = 0, J by FK differences) found by Newton steps from ``q0``; v is ``v``
    made tangent to the singular set there, n = ∇det / |∇det|² (so det J ≈ δ + … at the middle), and c is chosen
    so that det J keeps its sign along the whole path (checked here). Returns q, q̇, q̈, each of shape (N, 6).
    """
    q = np.array(q0, dtype=float)
    for _ in range(50):
        f, g = _det(robot, q), _det_gradient(robot, q)
        q = q - f * g / (g @ g)
        if abs(f) < 1e-14:
            break
    g = _det_gradient(robot, q)
    n = g / (g @ g)
    v = np.asarray(v, dtype=float)
    v = v - (v @ g) / (g @ g) * g
    s = np.asarray(t, dtype=float) - 0.5
    away = np.abs(s) > 1e-3
    curvature = np.array([_det(robot, q + si * v) for si in s[away]]) / s[away] ** 2
    c = 1.5 * max(0.0, float(np.max(-curvature))) + 0.5
    path = q + s[:, None] * v + (delta + c * s[:, None] ** 2) * n
    dets = np.array([_det(robot, row) for row in path])
    assert (dets > 0).all(), "the path crosses the singularity"
    return path, v + 2 * c * s[:, None] * n, np.tile(2 * c * n, (len(s), 1))


def sigma_ratio(robot, q: np.ndarray) -> float:
    """σ_min / σ_max of the FK-difference Jacobian at q."""
    values = np.linalg.svd(difference_jacobian(robot, q), compute_uv=False)
    return float(values[-1] / values[0])


#: Sample times of the near-singular paths: 199 samples on [0, 1], sample 99 at the path's middle (t = 0.5).
NEAR_SINGULAR_TIMES = np.linspace(0.0, 1.0, 199)

#: A UR5e path (``near_singular_path``'s q0, v, δ) whose middle passes 3e-5 (σmin/σmax) from its shoulder
#: singularity (the wrist point at radius d4 from axis 1, where the two q1 solutions meet). Before issue 22.11 the
#: trajectory left it at sample 100 for the other q1 solution, with the same labels and branch_changed false, and
#: ended 2.3 rad off.
UR5E_PATH = ([-1.07, 1.812, -1.237, -0.292, -2.299, -0.609], [-0.593, -0.475, 0.501, -0.439, -0.03, 0.961], 1e-5)


def twists_of(robot, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """[ṗ; ω] (N, 6) of the tool, world frame, by the FK-difference Jacobian; joints q and rates qd (N, n)."""
    return np.einsum("kij,kj->ki", np.array([difference_jacobian(robot, row) for row in q]), qd)
