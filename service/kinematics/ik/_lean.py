"""Candidates for ONE pose in scalar arithmetic, for the two hot 6R families; the general path does the rest.

A single-pose call through the array solvers costs hundreds of small numpy
operations, each with a fixed overhead far larger than its arithmetic. For one
pose this module computes the same candidate slots as
:meth:`DecoupledPlan.solve` (intersecting shoulder + spherical wrist, the PUMA
type) and :meth:`ThreeParallelPlan.solve` (the UR5 type) with ``math`` on
floats, and hands them to the shared verification, merging, labelling and
ordering in :mod:`._arrays`.

It covers the generic case only: every subproblem has two distinct, exact,
non-degenerate roots, each clearly (by :data:`MARGIN` times the tolerance)
away from the threshold where the array solver would decide otherwise (the
one exception: the UR5 type's elbow may be clearly out of reach for some
shoulder and wrist roots, which gives a least-squares slot and an empty one,
as in the array solver). Then no singularity is met. Anything else (an unreachable
target, a singular or nearly singular pose, another family) returns None and
the pose takes the array path, which is the reference: a test holds these
candidates to it over many random poses.

The formulas are those of :mod:`._subproblems` (same slot order, same roots),
written for one set of floats.
"""

from __future__ import annotations

import math

import numpy as np

from .._cache import memo
from .._tolerances import DUPLICATE_TOLERANCE, GEOMETRY_TOLERANCE
from ._decoupled import DecoupledPlan
from ._positioning import IntersectingShoulder
from ._subproblems import _frame as _subproblems_frame
from ._three_parallel import ThreeParallelPlan
from ._types import Candidates, LabelCodes, SingularFlags
from ._wrist import SphericalWrist

#: How far (as a multiple of each tolerance) a quantity must be from the array solver's threshold for the
#: scalar path to decide the pose; closer than that, the array path decides.
MARGIN = 10.0

_PI, _TWO_PI = math.pi, 2.0 * math.pi
_MERGE_RESIDUAL = DUPLICATE_TOLERANCE ** 2
_MERGE_COS_GAP = 1.0 - math.cos(DUPLICATE_TOLERANCE / 2.0)

Vector = tuple[float, float, float]
Matrix = tuple[Vector, Vector, Vector]  # rows


class _NotGeneric(Exception):
    """The pose is not clearly generic: leave it to the array path."""


def lean_candidates(plan: object, world_T_target: np.ndarray, reference: np.ndarray | None) -> Candidates | None:
    """The candidate slots of ``plan.solve(world_T_target[None], reference)`` for one pose, or None.

    None when the plan is not one of the two families covered or the pose is not clearly generic.
    """
    solver = _solver_for(plan)
    if solver is None:
        return None
    try:
        joints = solver(world_T_target)
    except _NotGeneric:
        return None
    joints = np.array(joints)[None]  # (1, m, n)
    return Candidates(joints, ~np.isnan(joints).any(axis=-1), [], SingularFlags(1))


def lean_label_codes(plan: object, joints: np.ndarray, valid: np.ndarray) -> LabelCodes | None:
    """``plan.label_codes`` of one pose's slots (1, m, n), for the valid ones (the others get −1), or None.

    None when the plan is not covered or a slot's label quantity is within :data:`MARGIN` times the
    tolerance of the value where the label flips or is left out: the array labeller then decides.
    """
    labeller = _labeller_for(plan)
    if labeller is None:
        return None
    codes = {name: [-1] * len(valid[0]) for name in labeller.names}
    try:
        for slot, (q, ok) in enumerate(zip(joints[0].tolist(), valid[0].tolist())):
            if ok:
                for name, code in zip(labeller.names, labeller.codes(q)):
                    codes[name][slot] = code
    except _NotGeneric:
        return None
    return {name: (values, np.array(codes[name], dtype=np.int8))
            for name, values in zip(labeller.names, labeller.values)}


def _side_code(side: float, size: float) -> int:
    """:func:`._positioning.side_codes` for one value, clear of its thresholds."""
    if abs(side) <= MARGIN * DUPLICATE_TOLERANCE * size:
        raise _NotGeneric
    return 0 if side > 0 else 1


def _wrist_code(middle: float) -> int:
    """:func:`._wrist.wrist_codes` for one value, clear of its thresholds."""
    sine = math.sin(middle)
    if abs(sine) <= MARGIN * 10 * GEOMETRY_TOLERANCE:
        raise _NotGeneric
    return 0 if sine > 0 else 1


def _moved(directions: list[Vector], points: list[Vector], q: list[float], upto: int, x: Vector) -> Vector:
    """exp([S_1] q_1) ⋯ exp([S_upto] q_upto) x for revolute joints (as :func:`._screws.move_point`)."""
    for i in reversed(range(upto)):
        x = _add(points[i], _rotate(directions[i], q[i], _sub(x, points[i])))
    return x


def _reject(v: Vector, unit: Vector) -> Vector:
    along = _dot(v, unit)
    return (v[0] - along * unit[0], v[1] - along * unit[1], v[2] - along * unit[2])


def _labeller_for(plan: object):
    labeller = plan.__dict__.get("_lean_labels")
    if labeller is None:
        solver = _solver_for(plan)
        labeller = plan.__dict__["_lean_labels"] = solver.__self__ if solver is not None else False
    return labeller or None


def _solver_for(plan: object):
    constants = plan.__dict__.get("_lean")
    if constants is None:
        constants = plan.__dict__["_lean"] = _build(plan) or False
    return constants or None


def _build(plan: object):
    if isinstance(plan, ThreeParallelPlan):
        return _ThreeParallel(plan).solve
    if (isinstance(plan, DecoupledPlan) and isinstance(plan.positioner, IntersectingShoulder)
            and isinstance(plan.wrist, SphericalWrist) and not plan.fixed and not plan.positioner.free_joints
            and plan.positioner.joints == (0, 1, 2) and plan.wrist.joints == (3, 4, 5)
            and bool(plan.positioner.model.is_revolute[2])):
        return _ShoulderWrist(plan).solve
    return None


# --- small vector algebra on tuples ------------------------------------------------------------------------

def _v(a: np.ndarray) -> Vector:
    return tuple(float(x) for x in a)


def _m(a: np.ndarray) -> Matrix:
    return tuple(tuple(float(x) for x in row) for row in a)


def _dot(a: Vector, b: Vector) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _sub(a: Vector, b: Vector) -> Vector:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _add(a: Vector, b: Vector) -> Vector:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _cross(a: Vector, b: Vector) -> Vector:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _norm(a: Vector) -> float:
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def _mv(R: Matrix, v: Vector) -> Vector:
    return (_dot(R[0], v), _dot(R[1], v), _dot(R[2], v))


def _mtv(R: Matrix, v: Vector) -> Vector:
    """Rᵀ v."""
    return (R[0][0] * v[0] + R[1][0] * v[1] + R[2][0] * v[2], R[0][1] * v[0] + R[1][1] * v[1] + R[2][1] * v[2],
            R[0][2] * v[0] + R[1][2] * v[1] + R[2][2] * v[2])


def _mm(A: Matrix, B: Matrix) -> Matrix:
    (a00, a01, a02), (a10, a11, a12), (a20, a21, a22) = A
    (b00, b01, b02), (b10, b11, b12), (b20, b21, b22) = B
    return ((a00 * b00 + a01 * b10 + a02 * b20, a00 * b01 + a01 * b11 + a02 * b21, a00 * b02 + a01 * b12 + a02 * b22),
            (a10 * b00 + a11 * b10 + a12 * b20, a10 * b01 + a11 * b11 + a12 * b21, a10 * b02 + a11 * b12 + a12 * b22),
            (a20 * b00 + a21 * b10 + a22 * b20, a20 * b01 + a21 * b11 + a22 * b21, a20 * b02 + a21 * b12 + a22 * b22))


def _mtm(A: Matrix, B: Matrix) -> Matrix:
    """Aᵀ B."""
    (a00, a01, a02), (a10, a11, a12), (a20, a21, a22) = A
    return _mm(((a00, a10, a20), (a01, a11, a21), (a02, a12, a22)), B)


def _rotation(k: Vector, theta: float) -> Matrix:
    """R(k, θ) = I + sin θ [k]× + (1 − cos θ) [k]×² (as :func:`._screws.rotation_about`)."""
    s, c = math.sin(theta), 1.0 - math.cos(theta)
    x, y, z = k
    return ((1.0 + c * (x * x - 1.0), -s * z + c * x * y, s * y + c * x * z),
            (s * z + c * x * y, 1.0 + c * (y * y - 1.0), -s * x + c * y * z),
            (-s * y + c * x * z, s * x + c * y * z, 1.0 + c * (z * z - 1.0)))


def _rotate(k: Vector, theta: float, v: Vector) -> Vector:
    """R(k, θ) v by Rodrigues' formula."""
    s, c = math.sin(theta), math.cos(theta)
    (kx, ky, kz), (vx, vy, vz) = k, v
    along = (kx * vx + ky * vy + kz * vz) * (1.0 - c)
    return (vx * c + (ky * vz - kz * vy) * s + kx * along, vy * c + (kz * vx - kx * vz) * s + ky * along,
            vz * c + (kx * vy - ky * vx) * s + kz * along)


def _wrap(theta: float) -> float:
    """As :func:`._subproblems._wrap`: (−3π, 3π] to (−π, π]."""
    if theta > _PI:
        return theta - _TWO_PI
    if theta <= -_PI:
        return theta + _TWO_PI
    return theta


# --- the subproblems, generic case only ------------------------------------------------------------------

def _frame(k: Vector) -> tuple[Vector, Vector]:
    """e1, e2 of :func:`._subproblems._frame` (k completes the right-handed frame); built once per plan."""
    frame = _subproblems_frame(np.asarray(k, dtype=float))
    return tuple(frame[:, 0].tolist()), tuple(frame[:, 1].tolist())


def _harmonic(a: float, b: float, c: float, scale: float, out_of_reach: bool = False) -> tuple[float, float]:
    """The two roots of a cos θ + b sin θ = c, φ + half first; _NotGeneric unless clearly two.

    With ``out_of_reach``, a clearly unreachable c gives the least-squares root and NaN (one valid slot),
    as the array solver does.
    """
    tol = GEOMETRY_TOLERANCE * scale
    rho = math.sqrt(a * a + b * b)
    excess = abs(c) - rho
    phi = math.atan2(b, a)
    if out_of_reach and rho > MARGIN * tol and excess > MARGIN * tol:
        return _wrap(phi + math.atan2(0.0, c)), math.nan
    if not (rho > MARGIN * tol and -excess > MARGIN * (rho * _MERGE_COS_GAP + tol)):
        raise _NotGeneric
    half = math.atan2(math.sqrt(-excess * (rho + abs(c))), c)
    return _wrap(phi + half), _wrap(phi - half)


def _subproblem_1(k: Vector, frame: tuple[Vector, Vector], p: Vector, q: Vector) -> float:
    """θ with R(k, θ) p = q (least squares), non-degenerate only."""
    e1, e2 = frame
    px, py, pz = _dot(p, e1), _dot(p, e2), _dot(p, k)
    qx, qy, qz = _dot(q, e1), _dot(q, e2), _dot(q, k)
    radius_p, radius_q = math.sqrt(px * px + py * py), math.sqrt(qx * qx + qy * qy)
    tol = GEOMETRY_TOLERANCE * max(math.sqrt(radius_p ** 2 + pz * pz), math.sqrt(radius_q ** 2 + qz * qz))
    if not (radius_p > MARGIN * tol and radius_q > MARGIN * tol):
        raise _NotGeneric
    return _wrap(math.atan2(px * qy - py * qx, px * qx + py * qy))


def _subproblem_3(k: Vector, frame: tuple[Vector, Vector], p: Vector, q: Vector, delta: float,
                  out_of_reach: bool = False) -> tuple[float, float]:
    e1, e2 = frame
    px, py, pz = _dot(p, e1), _dot(p, e2), _dot(p, k)
    qx, qy, qz = _dot(q, e1), _dot(q, e2), _dot(q, k)
    rp2, rq2, delta2 = px * px + py * py, qx * qx + qy * qy, delta * delta
    c = 0.5 * (rp2 + rq2 + (pz - qz) ** 2 - delta2)
    return _harmonic(px * qx + py * qy, px * qy - py * qx, c, rp2 + rq2 + pz * pz + qz * qz + delta2, out_of_reach)


def _subproblem_4(h: Vector, k: Vector, p: Vector, delta: float) -> tuple[float, float]:
    hk = _dot(h, k)
    a = _dot((h[0] - hk * k[0], h[1] - hk * k[1], h[2] - hk * k[2]), p)
    b = _dot(_cross(h, k), p)
    return _harmonic(a, b, delta - hk * _dot(k, p), _norm(p) + abs(delta))


def _subproblem_2_chain(k1: Vector, k2: Vector, p: Vector, q: Vector) -> tuple[tuple[float, float], ...]:
    """The two (θ1, θ2) with R(k1, θ1) R(k2, θ2) p = q: :func:`._subproblems.subproblem_2` on (q, p), θ1 negated."""
    p, q = q, p  # subproblem_2(k1, k2, q, p): R(k1, t1) q = R(k2, t2) p
    normal = _cross(k1, k2)
    sin2 = _dot(normal, normal)
    cos, sin = _dot(k1, k2), math.sqrt(sin2)
    p1, p2, pn = _dot(p, k1), _dot(p, k2), _dot(p, normal)
    q1, q2, qn = _dot(q, k1), _dot(q, k2), _dot(q, normal)
    d1, e2 = p2 - cos * p1, q1 - cos * q2
    radius_p = math.sqrt(pn * pn + d1 * d1) / sin
    radius_q = math.sqrt(qn * qn + e2 * e2) / sin
    norm_p, norm_q = math.sqrt(p1 * p1 + radius_p * radius_p), math.sqrt(q2 * q2 + radius_q * radius_q)
    tol = GEOMETRY_TOLERANCE * max(norm_p, norm_q)
    if not (radius_p > MARGIN * tol and radius_q > MARGIN * tol and abs(norm_p - norm_q) * MARGIN <= tol):
        raise _NotGeneric
    h1, h2 = p1 / norm_p, q2 / norm_q
    rho1, rho2 = radius_p / norm_p, radius_q / norm_q
    alpha, beta = (h1 - cos * h2) / sin2, (h2 - cos * h1) / sin2
    # _subproblems._crossing_gap, in scalar form
    if rho1 <= rho2:
        g = (rho1 - abs(beta * sin)) * (rho1 + abs(beta * sin))
    else:
        g = (rho2 - abs(alpha * sin)) * (rho2 + abs(alpha * sin))
    if not g * (rho1 + rho2) > MARGIN * _MERGE_RESIDUAL * rho1 * rho2:
        raise _NotGeneric
    gamma = math.sqrt(g) / sin
    s1, c1, t1, u1 = -beta * pn, beta * d1, gamma * d1, gamma * pn
    s2, c2, t2, u2 = alpha * qn, alpha * e2, gamma * e2, gamma * qn
    return ((_wrap(-_wrap(math.atan2(s1 + t1, c1 + u1))), _wrap(math.atan2(s2 - t2, c2 + u2))),
            (_wrap(-_wrap(math.atan2(s1 - t1, c1 - u1))), _wrap(math.atan2(s2 + t2, c2 - u2))))


# --- the families ----------------------------------------------------------------------------------------

class _ShoulderWrist:
    """:class:`DecoupledPlan` with an :class:`IntersectingShoulder` (revolute joint 3) and a spherical wrist."""

    def __init__(self, plan: DecoupledPlan) -> None:
        positioner, wrist, model = plan.positioner, plan.wrist, plan.positioner.model
        self.directions = [_v(d) for d in model.directions]
        self.points = [_v(p) for p in model.points]
        self.frame_3 = _frame(self.directions[2])
        self.centre, self.point = _v(positioner.centre), _v(plan.point)
        self.home_inverse = _m(plan.home_inverse[:3, :3]), _v(plan.home_inverse[:3, 3])
        self.axes = [_v(a) for a in wrist.axes]
        self.normal = _v(wrist.normal)
        self.frame_c = _frame(self.axes[2])
        forward, in_plane, up = positioner._label_constants
        self.forward, self.in_plane, self.up = _v(forward), in_plane, _v(up)
        self.on_axis = GEOMETRY_TOLERANCE * 10 * positioner.geometry.length_scale

    names = ("shoulder", "elbow", "wrist")
    values = (("left", "right"), ("up", "down"), ("no_flip", "flip"))

    def codes(self, q: list[float]) -> tuple[int, int, int]:
        """:meth:`IntersectingShoulder.label_codes` and :func:`wrist_codes` for one joint vector."""
        d, p, c = self.directions, self.points, self.centre
        forward = _rotate(d[0], q[0], self.forward)
        reach = _sub(_moved(d, p, q, 3, self.point), c)
        if _norm(_reject(reach, d[0])) <= MARGIN * self.on_axis:  # the point near axis 1
            raise _NotGeneric
        shoulder = _side_code(_dot(reach, forward), _norm(reach))
        elbow = _sub(_moved(d, p, q, 2, p[2]), c)
        if self.in_plane:  # in the arm's plane, normal to axis 2
            normal = _rotate(d[0], q[0], d[1])
            elbow, reach = _reject(elbow, normal), _reject(reach, normal)
        length = _norm(reach)
        line = (reach[0] / length, reach[1] / length, reach[2] / length)
        side = _dot(_reject(elbow, line), self.up)
        return shoulder, _side_code(side, _norm(elbow)), _wrist_code(q[4])

    def solve(self, T: np.ndarray) -> list[list[float]]:
        (R_T0, R_T1, R_T2, t_T) = T[:3].T.tolist()  # the target's columns
        R_T = tuple(zip(R_T0, R_T1, R_T2))  # rows
        H, h = self.home_inverse
        R_target = _mm(R_T, H)
        # the wrist point: (T · home⁻¹) · point
        translation = _add(_mv(R_T, h), tuple(t_T))
        point_world = _add(_mv(R_target, self.point), translation)
        d, p, c, w = self.directions, self.points, self.centre, self.point
        target = _sub(point_world, c)
        third = _subproblem_3(d[2], self.frame_3, _sub(w, p[2]), _sub(c, p[2]), _norm(target))
        joints = []
        for q3 in third:
            w3 = _add(p[2], _rotate(d[2], q3, _sub(w, p[2])))
            for q1, q2 in _subproblem_2_chain(d[0], d[1], _sub(w3, c), target):
                R_G = _mm(_mm(_rotation(d[0], q1), _rotation(d[1], q2)), _rotation(d[2], q3))
                R_H = _mtm(R_G, R_target)
                for qa, qb, qc in self._wrist(R_H):
                    joints.append([q1, q2, q3, qa, qb, qc])
        return joints

    def _wrist(self, R_w: Matrix) -> list[tuple[float, float, float]]:
        a, b, c = self.axes
        target_axis = _mv(R_w, c)
        wanted = _mv(R_w, self.normal)
        roots = []
        for qa, qb in _subproblem_2_chain(a, b, c, target_axis):
            unwound = _rotate(b, -qb, _rotate(a, -qa, wanted))
            roots.append((qa, qb, _subproblem_1(c, self.frame_c, self.normal, unwound)))
        return roots


class _ThreeParallel:
    """:class:`ThreeParallelPlan` (the UR5 type), step for step."""

    def __init__(self, plan: ThreeParallelPlan) -> None:
        model = plan.model
        self.directions = [_v(d) for d in model.directions]
        self.points = [_v(p) for p in model.points]
        self.frames = [_frame(direction) for direction in self.directions]
        self.centre = _v(plan.centre)
        self.home_inverse = _m(plan.home_inverse[:3, :3]), _v(plan.home_inverse[:3, 3])
        self.omega_p, self.normal_p = _v(plan.omega_p), _v(plan.normal_p)
        self.frame_p = _frame(self.omega_p)
        self.signs = [float(s) for s in plan.signs]
        self.height = _dot(self.omega_p, _sub(self.centre, self.points[0]))
        self.forward = _v(plan.forward)
        self.up = _v(plan.geometry.upward(plan.geometry.direction(0)))

    names = ("shoulder", "elbow", "wrist")
    values = (("left", "right"), ("up", "down"), ("no_flip", "flip"))

    def codes(self, q: list[float]) -> tuple[int, int, int]:
        """:meth:`ThreeParallelPlan.label_codes` for one joint vector."""
        d, p = self.directions, self.points
        forward = _rotate(d[0], q[0], self.forward)
        wrist_point = _moved(d, p, q, 3, p[3])
        to_wrist = _sub(wrist_point, p[0])
        shoulder = _side_code(_dot(to_wrist, forward), _norm(to_wrist))
        shoulder_point = _moved(d, p, q, 1, p[1])
        normal = _rotate(d[0], q[0], self.omega_p)  # the parallel axes, after joint 1
        elbow = _reject(_sub(_moved(d, p, q, 2, p[2]), shoulder_point), normal)
        reach = _reject(_sub(wrist_point, shoulder_point), normal)
        length = _norm(reach)
        if length <= 1e-300:
            raise _NotGeneric
        line = (reach[0] / length, reach[1] / length, reach[2] / length)
        side = _dot(_reject(elbow, line), self.up)
        return shoulder, _side_code(side, _norm(elbow)), _wrist_code(q[4])

    def solve(self, T: np.ndarray) -> list[list[float]]:
        (R_T0, R_T1, R_T2, t_T) = T[:3].T.tolist()
        R_T = tuple(zip(R_T0, R_T1, R_T2))
        H, h = self.home_inverse
        R_A = _mm(R_T, H)
        t_A = _add(_mv(R_T, h), tuple(t_T))
        d, p, w_p = self.directions, self.points, self.omega_p
        c_world = _add(_mv(R_A, self.centre), t_A)
        s2, s3, s4 = self.signs
        joints: list[list[float]] = []
        for theta1 in _subproblem_4(w_p, d[0], _sub(c_world, p[0]), self.height):
            q1 = -theta1
            R1 = _rotation(d[0], q1)
            R_rest = _mtm(R1, R_A)
            wrist = _subproblem_4(w_p, d[4], d[5], _dot(w_p, _mv(R_rest, d[5])))
            wanted_p = _mtv(R_rest, w_p)
            for q5 in wrist:
                q6 = -_subproblem_1(d[5], self.frames[5], _rotate(d[4], -q5, w_p), wanted_p)
                R5, R6 = _rotation(d[4], q5), _rotation(d[5], q6)
                # R234 = R_rest R6ᵀ R5ᵀ, applied to the normal of ω_p
                R234_normal = _mv(R_rest, _mtv(R6, _mtv(R5, self.normal_p)))
                angle_sum = _subproblem_1(w_p, self.frame_p, self.normal_p, R234_normal)
                # the point on axis 4: G_5⁻¹ then G_6⁻¹ (turns about axes through p5, p6), then A, then G_1⁻¹
                y = _add(p[4], _mtv(R5, _sub(p[3], p[4])))
                y = _add(p[5], _mtv(R6, _sub(y, p[5])))
                p4_world = _add(_mv(R_A, y), t_A)
                z = _add(p[0], _mtv(R1, _sub(p4_world, p[0])))
                z1 = _sub(z, p[1])
                # this shoulder and wrist may leave the point out of the elbow's reach: a least-squares root
                # (then rejected by the FK check) and an empty slot, as in the array solver
                elbow = _subproblem_3(d[2], self.frames[2], _sub(p[3], p[2]), _sub(p[1], p[2]), _norm(z1),
                                      out_of_reach=True)
                for q3 in elbow:
                    if math.isnan(q3):
                        joints.append([q1, math.nan, math.nan, math.nan, q5, q6])
                        continue
                    moved = _add(p[2], _rotate(d[2], q3, _sub(p[3], p[2])))
                    q2 = _subproblem_1(d[1], self.frames[1], _sub(moved, p[1]), z1)
                    q4 = s4 * (angle_sum - s2 * q2 - s3 * q3)
                    joints.append([q1, q2, q3, q4, q5, q6])
        return joints
