"""The general solver's chain model in normalised lengths (lengths divided by the robot's size):
G_1(q_1) ⋯ G_6(q_6) with its spatial joint twists, the error twist against a target A, Newton's steps on
G_1 ⋯ G_6 = A that polish the elimination's roots (:mod:`._general_6r_elimination`), and the Jacobian's null motion
at a singular root, from which :mod:`._general_6r` tells a family of solutions from a fold.

Joint vectors q are (K, 6): radians for turns, normalised lengths for slides; ``directions`` and ``points`` (6, 3)
are the joints' unit axes and points on them, ``revolute`` (6,) tells turns from slides.
"""

from __future__ import annotations

import numpy as np

from .._forward import cross
from .._linear import solve_each
from .._tolerances import DUPLICATE_TOLERANCE
from ._screws import rotation_about

#: Newton steps on the FK at most, for every root whose error twist (normalised lengths, radians) is above
#: NEWTON_TOLERANCE; the shared verification then accepts at 1e-9.
NEWTON_STEPS = 5
NEWTON_TOLERANCE = 1e-13

#: A root where the Jacobian's null motion (two joints turned by ±t, or any joint motion) moves the tool by less
#: than this ratio of its largest singular value is singular: the elimination's roots satisfy the loop to about
#: ELIMINATION_RESIDUAL before Newton's steps, which pins them along that motion only to
#: ELIMINATION_RESIDUAL / FAMILY_CONDITION = DUPLICATE_TOLERANCE; below it they land anywhere on a family (on a
#: raw xArm 7 at q2 = 0, four roots 0.004-0.02 rad apart, each verified at ACCEPT_RESIDUAL), or anywhere in the
#: band where two roots meet (on a Jaco 2 at det J = 0, 1e-6…9e-6 from the generating configuration).
ELIMINATION_RESIDUAL = 1e-12
FAMILY_CONDITION = ELIMINATION_RESIDUAL / DUPLICATE_TOLERANCE


def newton(directions: np.ndarray, points: np.ndarray, revolute: np.ndarray, A_targets: np.ndarray,
           q: np.ndarray, steps: int = NEWTON_STEPS, held: np.ndarray | None = None,
           tolerance: float = NEWTON_TOLERANCE, rcond: float | None = None) -> np.ndarray:
    """Newton's method on G_1 ⋯ G_6 = A for candidates q (K, 6) and targets A (K, 4, 4), normalised lengths
    (``revolute`` (6,) tells turns from slides); ``held`` (K,), a joint per candidate that keeps its value
    (Gauss–Newton on the other five).

    Steps the candidates whose error twist is above ``tolerance`` (roots come from the eigenproblem
    to about 1e-12, so one step, or none, usually suffices); singular candidates get a tiny damping instead of a
    failure.

    Not :func:`._gauss_newton.gauss_newton`: that loop runs on a Robot's FK and a goal's pose error, holds one
    joint set for the whole batch and only damps, where this one runs on the normalised chain against A, holds a
    joint per candidate, and needs the pseudo-inverse (``rcond``) to split a double root (damped steps leave its
    halves ~3e-6 apart: three general-6R tests fail).
    """
    q = q.copy()
    R_A, p_A = A_targets[:, :3, :3], A_targets[:, :3, 3]
    stepped = np.arange(len(q))  # the candidates whose error may have changed: the others keep theirs
    for _ in range(steps + 1):
        R, p, twists = chain_twists(directions, points, revolute, q[stepped])
        error = error_twist(R, p, R_A[stepped], p_A[stepped])
        active = np.abs(error).max(axis=1) > tolerance
        if _ == steps or not active.any():
            break
        stepped = stepped[active]
        J = twists[active]
        fixed = np.zeros(J.shape[:2])
        if held is not None:
            J[np.arange(len(J)), held[stepped]] = 0.0
            fixed[np.arange(len(J)), held[stepped]] = 1.0
        if rcond is not None:  # the pseudo-inverse: every singular value above rcond · σ_max counts in full
            q[stepped] += np.einsum("kij,kj->ki", np.linalg.pinv(np.swapaxes(J, -1, -2), rcond=rcond), error[active])
            continue
        JJt = J @ np.swapaxes(J, -1, -2) + 1e-14 * np.eye(6) + fixed[..., None] * np.eye(6)
        q[stepped] += solve_each(JJt, J @ error[active][..., None])[..., 0]
    return q


def error_twist(R: np.ndarray, p: np.ndarray, R_A: np.ndarray, p_A: np.ndarray) -> np.ndarray:
    """The spatial error twist (ω, v) (K, 6) with A ≈ exp([ξ]) T, of T = (R, p) against A = (R_A, p_A)."""
    R_err = R_A @ np.swapaxes(R, -1, -2)
    omega = 0.5 * np.stack([R_err[:, 2, 1] - R_err[:, 1, 2], R_err[:, 0, 2] - R_err[:, 2, 0],
                            R_err[:, 1, 0] - R_err[:, 0, 1]], axis=-1)
    return np.concatenate([omega, p_A - p - cross(omega, p)], axis=-1)


def chain_twists(directions: np.ndarray, points: np.ndarray, revolute: np.ndarray, q: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """G_1 ⋯ G_6 at q (K, 6) as its rotation (K, 3, 3) and translation (K, 3), and the spatial joint twists
    (K, 6, 6) at q, (ω, v): (ω, p × ω) of a turn through p, (0, k) of a slide along k; normalised lengths."""
    R = np.broadcast_to(np.eye(3), q.shape[:-1] + (3, 3))
    p = np.zeros(q.shape[:-1] + (3,))
    twists = np.zeros(q.shape + (6,))
    for j in range(6):
        axis = R @ directions[j]
        if not revolute[j]:
            twists[:, j, 3:] = axis
            p = p + axis * q[:, j, None]
            continue
        twists[:, j, :3] = axis
        twists[:, j, 3:] = cross(R @ points[j] + p, axis)
        turn = rotation_about(directions[j], q[:, j])
        p = p + (R @ (points[j] - turn @ points[j])[..., None])[..., 0]
        R = R @ turn
    return R, p, twists


def singular_motion(directions: np.ndarray, points: np.ndarray, revolute: np.ndarray, q: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Roots q (K, 6) where the twist Jacobian is singular to within :data:`FAMILY_CONDITION` (its smallest
    singular value that small a ratio of its largest): the target fixes them along the null motion only to about
    DUPLICATE_TOLERANCE. There two roots meet (a fold), or a family of solutions passes (two coaxial joints, as
    the xArm's joints 1 and 3 at q2 = 0, or a self-motion over more joints, as a raw xArm 7's shoulder and joint
    5 at its elbow angle q4 = -0.44 with q7 held).

    Returns ``found`` (K,) bool, the unit null motion (K, 6) (largest entry positive) and ``coaxial`` (K,) bool:
    the motion turns two joints only, one by t and the other by ∓t (±1/√2 on the pair)."""
    _, _, J = chain_twists(directions, points, revolute, q)  # (K, joints, twist)
    u, sigma, _ = np.linalg.svd(J)
    null = u[..., -1]  # (K, 6): the joint motion of the smallest singular value
    largest = np.take_along_axis(null, np.argmax(np.abs(null), axis=-1)[:, None], axis=-1)
    null = null * np.sign(largest)
    top = -np.sort(-np.abs(null), axis=-1)[:, :2]
    coaxial = np.abs(top - np.sqrt(0.5)).max(axis=-1) <= 1e-3
    found = sigma[:, -1] <= FAMILY_CONDITION * sigma[:, 0]
    return found, null, coaxial

