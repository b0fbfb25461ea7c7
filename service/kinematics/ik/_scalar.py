"""One pose in scalar arithmetic: the vector algebra and the subproblems' generic case, on floats.

A single-pose call through the array solvers costs hundreds of small numpy
operations, each with a fixed overhead far larger than its arithmetic. The two
hot 6R families (:class:`~._decoupled.DecoupledPlan` with an intersecting
shoulder and a spherical wrist, the PUMA type, and
:class:`~._three_parallel.ThreeParallelPlan`, the UR5 type) therefore also
solve one pose with ``math`` on floats (their ``solve_one`` and
``label_codes_one``), from these pieces.

Generic case only: every subproblem has two distinct, exact, non-degenerate
roots, each clearly (by :data:`MARGIN` times the tolerance) away from the
threshold where the array solver would decide otherwise. Anything else raises
:class:`NotGeneric` and the pose takes the array path, which is the reference
(``tests/kinematics/ik/test_one_pose.py`` holds these paths to it). The
formulas are those of :mod:`._subproblems` (same slot order, same roots).
"""

from __future__ import annotations

import math

import numpy as np

from .._tolerances import DUPLICATE_TOLERANCE, GEOMETRY_TOLERANCE
from ._subproblems import axis_frame
from ._types import Candidates, LabelCodes, SingularFlags

#: How far (as a multiple of each tolerance) a quantity must be from the array solver's threshold for the
#: scalar path to decide the pose; closer than that, the array path decides.
MARGIN = 10.0

_PI, _TWO_PI = math.pi, 2.0 * math.pi
_MERGE_RESIDUAL = DUPLICATE_TOLERANCE ** 2
_MERGE_COS_GAP = 1.0 - math.cos(DUPLICATE_TOLERANCE / 2.0)

Vector = tuple[float, float, float]
Matrix = tuple[Vector, Vector, Vector]  # rows


class NotGeneric(Exception):
    """The pose is not clearly generic: leave it to the array path."""


def one_pose_candidates(solve, world_T_target: np.ndarray) -> Candidates | None:
    """Candidates (1, m, n) from ``solve(world_T_target)`` (the m joint vectors as lists), or None when the
    pose is not clearly generic."""
    try:
        joints = solve(world_T_target)
    except NotGeneric:
        return None
    joints = np.array(joints)[None]  # (1, m, n)
    return Candidates(joints, ~np.isnan(joints).any(axis=-1), SingularFlags(1))


def one_pose_label_codes(labeller, joints: np.ndarray, valid: np.ndarray) -> LabelCodes | None:
    """Label codes of one pose's slots (1, m, n) for the valid ones (the others get −1), from ``labeller``: its
    ``names``, their ``values`` and ``codes(q)`` (one code per name for a joint vector), or None when a slot's label quantity is within :data:`MARGIN` times the tolerance of
    the value where the label flips or is left out: the array labeller then decides."""
    names = labeller.names
    table = {name: [-1] * len(valid[0]) for name in names}
    try:
        for slot, (q, ok) in enumerate(zip(joints[0].tolist(), valid[0].tolist())):
            if ok:
                for name, code in zip(names, labeller.codes(q)):
                    table[name][slot] = code
    except NotGeneric:
        return None
    return {name: (labels, np.array(table[name], dtype=np.int8)) for name, labels in zip(names, labeller.values)}


def side_code(side: float, size: float) -> int:
    """:func:`._positioning.side_codes` for one value, clear of its thresholds."""
    if abs(side) <= MARGIN * DUPLICATE_TOLERANCE * size:
        raise NotGeneric
    return 0 if side > 0 else 1


def wrist_code(middle: float) -> int:
    """:func:`._wrist.wrist_codes` for one value, clear of its thresholds."""
    sine = math.sin(middle)
    if abs(sine) <= MARGIN * 10 * GEOMETRY_TOLERANCE:
        raise NotGeneric
    return 0 if sine > 0 else 1


def moved(directions: list[Vector], points: list[Vector], q: list[float], upto: int, x: Vector) -> Vector:
    """exp([S_1] q_1) ⋯ exp([S_upto] q_upto) x for revolute joints (as :func:`._screws.move_point`)."""
    for i in reversed(range(upto)):
        x = add(points[i], rotate(directions[i], q[i], sub(x, points[i])))
    return x


def reject(v: Vector, unit: Vector) -> Vector:
    along = dot(v, unit)
    return (v[0] - along * unit[0], v[1] - along * unit[1], v[2] - along * unit[2])


# --- vector algebra on tuples ---------------------------------------------------------------------------

def vector_of(a: np.ndarray) -> Vector:
    return tuple(float(x) for x in a)


def matrix_of(a: np.ndarray) -> Matrix:
    return tuple(tuple(float(x) for x in row) for row in a)


def dot(a: Vector, b: Vector) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def sub(a: Vector, b: Vector) -> Vector:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def add(a: Vector, b: Vector) -> Vector:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def cross(a: Vector, b: Vector) -> Vector:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a: Vector) -> float:
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def mv(R: Matrix, v: Vector) -> Vector:
    return (dot(R[0], v), dot(R[1], v), dot(R[2], v))


def mtv(R: Matrix, v: Vector) -> Vector:
    """Rᵀ v."""
    return (R[0][0] * v[0] + R[1][0] * v[1] + R[2][0] * v[2], R[0][1] * v[0] + R[1][1] * v[1] + R[2][1] * v[2],
            R[0][2] * v[0] + R[1][2] * v[1] + R[2][2] * v[2])


def mm(A: Matrix, B: Matrix) -> Matrix:
    (a00, a01, a02), (a10, a11, a12), (a20, a21, a22) = A
    (b00, b01, b02), (b10, b11, b12), (b20, b21, b22) = B
    return ((a00 * b00 + a01 * b10 + a02 * b20, a00 * b01 + a01 * b11 + a02 * b21, a00 * b02 + a01 * b12 + a02 * b22),
            (a10 * b00 + a11 * b10 + a12 * b20, a10 * b01 + a11 * b11 + a12 * b21, a10 * b02 + a11 * b12 + a12 * b22),
            (a20 * b00 + a21 * b10 + a22 * b20, a20 * b01 + a21 * b11 + a22 * b21, a20 * b02 + a21 * b12 + a22 * b22))


def mtm(A: Matrix, B: Matrix) -> Matrix:
    """Aᵀ B."""
    (a00, a01, a02), (a10, a11, a12), (a20, a21, a22) = A
    return mm(((a00, a10, a20), (a01, a11, a21), (a02, a12, a22)), B)


def rotation(k: Vector, theta: float) -> Matrix:
    """R(k, θ) = I + sin θ [k]× + (1 − cos θ) [k]×² (as :func:`._screws.rotation_about`)."""
    s, c = math.sin(theta), 1.0 - math.cos(theta)
    x, y, z = k
    return ((1.0 + c * (x * x - 1.0), -s * z + c * x * y, s * y + c * x * z),
            (s * z + c * x * y, 1.0 + c * (y * y - 1.0), -s * x + c * y * z),
            (-s * y + c * x * z, s * x + c * y * z, 1.0 + c * (z * z - 1.0)))


def rotate(k: Vector, theta: float, v: Vector) -> Vector:
    """R(k, θ) v by Rodrigues' formula."""
    s, c = math.sin(theta), math.cos(theta)
    (kx, ky, kz), (vx, vy, vz) = k, v
    along = (kx * vx + ky * vy + kz * vz) * (1.0 - c)
    return (vx * c + (ky * vz - kz * vy) * s + kx * along, vy * c + (kz * vx - kx * vz) * s + ky * along,
            vz * c + (kx * vy - ky * vx) * s + kz * along)


def wrap(theta: float) -> float:
    """As :func:`._subproblems._wrap`: (−3π, 3π] to (−π, π]."""
    if theta > _PI:
        return theta - _TWO_PI
    if theta <= -_PI:
        return theta + _TWO_PI
    return theta


# --- the subproblems, generic case only ------------------------------------------------------------------

def plane_axes(k: Vector) -> tuple[Vector, Vector]:
    """e1, e2 of :func:`._subproblems.axis_frame` (k completes the right-handed frame); built once per plan."""
    frame = axis_frame(np.asarray(k, dtype=float))
    return tuple(frame[:, 0].tolist()), tuple(frame[:, 1].tolist())


def harmonic(a: float, b: float, c: float, scale: float, out_of_reach: bool = False) -> tuple[float, float]:
    """The two roots of a cos θ + b sin θ = c, φ + half first; NotGeneric unless clearly two.

    With ``out_of_reach``, a clearly unreachable c gives the least-squares root and NaN (one valid slot),
    as the array solver does.
    """
    tol = GEOMETRY_TOLERANCE * scale
    rho = math.sqrt(a * a + b * b)
    excess = abs(c) - rho
    phi = math.atan2(b, a)
    if out_of_reach and rho > MARGIN * tol and excess > MARGIN * tol:
        return wrap(phi + math.atan2(0.0, c)), math.nan
    if not (rho > MARGIN * tol and -excess > MARGIN * (rho * _MERGE_COS_GAP + tol)):
        raise NotGeneric
    half = math.atan2(math.sqrt(-excess * (rho + abs(c))), c)
    return wrap(phi + half), wrap(phi - half)


def subproblem_1(k: Vector, frame: tuple[Vector, Vector], p: Vector, q: Vector) -> float:
    """θ with R(k, θ) p = q (least squares), non-degenerate only."""
    e1, e2 = frame
    px, py, pz = dot(p, e1), dot(p, e2), dot(p, k)
    qx, qy, qz = dot(q, e1), dot(q, e2), dot(q, k)
    radius_p, radius_q = math.sqrt(px * px + py * py), math.sqrt(qx * qx + qy * qy)
    tol = GEOMETRY_TOLERANCE * max(math.sqrt(radius_p ** 2 + pz * pz), math.sqrt(radius_q ** 2 + qz * qz))
    if not (radius_p > MARGIN * tol and radius_q > MARGIN * tol):
        raise NotGeneric
    return wrap(math.atan2(px * qy - py * qx, px * qx + py * qy))


def subproblem_3(k: Vector, frame: tuple[Vector, Vector], p: Vector, q: Vector, delta: float,
                  out_of_reach: bool = False) -> tuple[float, float]:
    e1, e2 = frame
    px, py, pz = dot(p, e1), dot(p, e2), dot(p, k)
    qx, qy, qz = dot(q, e1), dot(q, e2), dot(q, k)
    rp2, rq2, delta2 = px * px + py * py, qx * qx + qy * qy, delta * delta
    c = 0.5 * (rp2 + rq2 + (pz - qz) ** 2 - delta2)
    return harmonic(px * qx + py * qy, px * qy - py * qx, c, rp2 + rq2 + pz * pz + qz * qz + delta2, out_of_reach)


def subproblem_4(h: Vector, k: Vector, p: Vector, delta: float) -> tuple[float, float]:
    hk = dot(h, k)
    a = dot((h[0] - hk * k[0], h[1] - hk * k[1], h[2] - hk * k[2]), p)
    b = dot(cross(h, k), p)
    return harmonic(a, b, delta - hk * dot(k, p), norm(p) + abs(delta))


def subproblem_2_chain(k1: Vector, k2: Vector, p: Vector, q: Vector) -> tuple[tuple[float, float], ...]:
    """The two (θ1, θ2) with R(k1, θ1) R(k2, θ2) p = q: :func:`._subproblems.subproblem_2` on (q, p), θ1 negated."""
    p, q = q, p  # subproblem_2(k1, k2, q, p): R(k1, t1) q = R(k2, t2) p
    normal = cross(k1, k2)
    sin2 = dot(normal, normal)
    cos, sin = dot(k1, k2), math.sqrt(sin2)
    p1, p2, pn = dot(p, k1), dot(p, k2), dot(p, normal)
    q1, q2, qn = dot(q, k1), dot(q, k2), dot(q, normal)
    d1, e2 = p2 - cos * p1, q1 - cos * q2
    radius_p = math.sqrt(pn * pn + d1 * d1) / sin
    radius_q = math.sqrt(qn * qn + e2 * e2) / sin
    norm_p, norm_q = math.sqrt(p1 * p1 + radius_p * radius_p), math.sqrt(q2 * q2 + radius_q * radius_q)
    tol = GEOMETRY_TOLERANCE * max(norm_p, norm_q)
    if not (radius_p > MARGIN * tol and radius_q > MARGIN * tol and abs(norm_p - norm_q) * MARGIN <= tol):
        raise NotGeneric
    h1, h2 = p1 / norm_p, q2 / norm_q
    rho1, rho2 = radius_p / norm_p, radius_q / norm_q
    alpha, beta = (h1 - cos * h2) / sin2, (h2 - cos * h1) / sin2
    # _subproblems._crossing_gap, in scalar form
    if rho1 <= rho2:
        g = (rho1 - abs(beta * sin)) * (rho1 + abs(beta * sin))
    else:
        g = (rho2 - abs(alpha * sin)) * (rho2 + abs(alpha * sin))
    if not g * (rho1 + rho2) > MARGIN * _MERGE_RESIDUAL * rho1 * rho2:
        raise NotGeneric
    gamma = math.sqrt(g) / sin
    s1, c1, t1, u1 = -beta * pn, beta * d1, gamma * d1, gamma * pn
    s2, c2, t2, u2 = alpha * qn, alpha * e2, gamma * e2, gamma * qn
    return ((wrap(-wrap(math.atan2(s1 + t1, c1 + u1))), wrap(math.atan2(s2 - t2, c2 + u2))),
            (wrap(-wrap(math.atan2(s1 - t1, c1 - u1))), wrap(math.atan2(s2 + t2, c2 - u2))))
