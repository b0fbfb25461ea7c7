"""One pose in scalar arithmetic: the vector algebra and the subproblems' generic case, on floats.

A single-pose call through the array solvers costs hundreds of small numpy
operations, each with a fixed overhead far larger than its arithmetic. The hot
families (:class:`~._decoupled.DecoupledPlan` with an intersecting shoulder, the
PUMA and the Stanford types and the polar arms, an offset one, the OPW type,
a SCARA shoulder, a planar two-link arm, one revolute joint or no positioner,
followed by a spherical wrist, a roll or nothing, which covers position
targets too; and :class:`~._three_parallel.ThreeParallelPlan`, the UR5 type)
therefore also
solve one pose with ``math`` on floats (their ``solve_one``, which also labels
the slots from the quantities it has: :class:`OnePose`), from these pieces,
with the plan's fixed vectors reduced once when the plan is built
(:class:`Turn`, :class:`Height`, :class:`TwoTurns`).

Generic case only: every subproblem has two distinct, exact, non-degenerate
roots, or clearly none (then, as the array solver, the least-squares one and
an empty slot), each clearly (by :data:`MARGIN` times the tolerance) away from
the threshold where the array solver would decide otherwise. Anything else
raises :class:`NotGeneric` and the pose takes the array path, which is the
reference (``tests/kinematics/ik/test_one_pose.py`` and
``test_one_pose_families.py`` hold these paths to it). The subproblems' float
forms live beside their array code and share its constants and thresholds
(:func:`.subproblems._roots._harmonic_clear`,
:func:`.subproblems._paden_kahan._subproblem_2_chain_clear`,
:func:`~.subproblems._paden_kahan._distance_equation` and
:func:`.subproblems._vectors._rotate_onto_clear`), as the angle wraps do
(:func:`~service.kinematics._angles.wrap_float`); this module reduces a
plan's fixed vectors to the coordinates they take.
"""

from __future__ import annotations

import math

import numpy as np

from .._tolerances import DUPLICATE_TOLERANCE, GEOMETRY_TOLERANCE
from ._screws import axis_frame
from ._types import LabelCodes, SingularFlags
from .subproblems._paden_kahan import _distance_equation, _subproblem_2_chain_clear
from .subproblems._prismatic import _slide_to_distance_clear
from .subproblems._roots import _harmonic_clear, _quadratic_clear
from .subproblems._vectors import _rotate_onto_clear

#: How far (as a multiple of each tolerance) a quantity must be from the array solver's threshold for the
#: scalar path to decide the pose; closer than that, the array path decides.
MARGIN = 10.0

Vector = tuple[float, float, float]
Matrix = tuple[Vector, Vector, Vector]  # rows


class NotGeneric(Exception):
    """The pose is not clearly generic: leave it to the array path."""


class OnePose:
    """One pose's candidates from a family's scalar path, with their branch labels.

    ``rows`` holds the m slots' joint vectors (lists of floats, revolute joints
    wrapped to (−π, π]), None for an empty slot; ``codes`` one tuple per slot,
    a label code per name of ``names`` (values ``values``), each None where the
    label quantity is within :data:`MARGIN` times the tolerance of where the
    label flips or is left out (then the array labeller decides). ``joints``
    (1, m, n), ``valid`` (1, m) and ``singularities`` (none: the pose is
    generic) read it as :class:`Candidates`. ``slots_as_array``: every slot is
    the array solver's, an empty one where that leaves the slot undefined (NaN)
    and a least-squares one where that gives the same least-squares value; a
    family whose scalar path empties a slot the array solver fills with a
    least-squares value (the OPW type's elbow out of reach) leaves it False.
    """

    def __init__(self, rows: list[list[float] | None], codes: list[tuple[int | None, ...]],
                 names: tuple[str, ...], values: tuple[tuple[str, ...], ...], dof: int, *,
                 slots_as_array: bool = False) -> None:
        self.rows, self.codes, self.names, self.values, self.dof = rows, codes, names, values, dof
        self.slots_as_array = slots_as_array
        self.singularities = SingularFlags(1)
        self.complete = None
        self.promise_needs_every_slot = False

    @property
    def joints(self) -> np.ndarray:
        nan = [math.nan] * self.dof
        return np.array([nan if q is None else q for q in self.rows])[None]

    @property
    def valid(self) -> np.ndarray:
        return np.array([q is not None for q in self.rows])[None]

    def label_codes(self, kept: list[bool]) -> LabelCodes | None:
        """Label codes (m,) of the ``kept`` slots (the others −1), or None when one of them is not clear."""
        table = self.code_lists(kept)
        if table is None:
            return None
        return {name: (values, np.array(column, dtype=np.int8))
                for name, values, column in zip(self.names, self.values, table)}

    def code_lists(self, kept: list[bool]) -> list[list[int]] | None:
        """:meth:`label_codes` as lists, one per name."""
        table = [[-1] * len(kept) for _ in self.names]
        for slot, (keep, codes) in enumerate(zip(kept, self.codes)):
            if keep:
                for column, code in zip(table, codes):
                    if code is None:
                        return None
                    column[slot] = code
        return table


def clearly_within(gap: float, band: float) -> bool:
    """Whether ``gap`` is inside ``band`` (True) or outside it (False) by :data:`MARGIN`; NotGeneric between, where
    the array path decides (a reference value it takes within a band, say)."""
    if gap * MARGIN <= band:
        return True
    if gap > MARGIN * band:
        return False
    raise NotGeneric


def side_code(side: float, size: float) -> int | None:
    """:func:`._positioning.side_codes` for one value, None unless clear of its thresholds."""
    if abs(side) <= MARGIN * DUPLICATE_TOLERANCE * size:
        return None
    return 0 if side > 0 else 1


def wrist_code(middle: float) -> int | None:
    """:func:`._wrist.wrist_codes` for one value, None unless clear of its thresholds."""
    sine = math.sin(middle)
    if abs(sine) <= MARGIN * 10 * GEOMETRY_TOLERANCE:
        return None
    return 0 if sine > 0 else 1


def reject(v: Vector, unit: Vector) -> Vector:
    (x, y, z), (a, b, c) = v, unit
    along = x * a + y * b + z * c
    return (x - along * a, y - along * b, z - along * c)


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
    (a, b, c), (d, e, f), (g, h, i) = R
    x, y, z = v
    return (a * x + b * y + c * z, d * x + e * y + f * z, g * x + h * y + i * z)


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


# --- the subproblems, generic case only ------------------------------------------------------------------

def plane_axes(k: Vector) -> tuple[Vector, Vector]:
    """e1, e2 of :func:`._screws.axis_frame` (k completes the right-handed frame); built once per plan."""
    frame = axis_frame(np.asarray(k, dtype=float))
    return tuple(frame[:, 0].tolist()), tuple(frame[:, 1].tolist())


class Turn:
    """Turns about one axis k (a unit vector), with the frame e1, e2, k of :func:`plane_axes`: subproblems 1 and 3,
    on vectors given by their :meth:`coordinates` (those of fixed vectors computed once per plan)."""

    def __init__(self, k: Vector) -> None:
        self.k = k
        self.e1, self.e2 = plane_axes(k)

    def coordinates(self, v: Vector) -> tuple[float, float, float, float, float]:
        """v's components along e1, e2 and k, its distance from the axis and its length."""
        (e0, e1, e2), (f0, f1, f2), (k0, k1, k2) = self.e1, self.e2, self.k
        x, y, z = v[0] * e0 + v[1] * e1 + v[2] * e2, v[0] * f0 + v[1] * f1 + v[2] * f2, v[0] * k0 + v[1] * k1 + v[2] * k2
        radius = math.sqrt(x * x + y * y)
        return x, y, z, radius, math.sqrt(radius * radius + z * z)

    @staticmethod
    def angle(p: tuple[float, ...], q: tuple[float, ...], free_below: float = GEOMETRY_TOLERANCE,
              scale: float | None = None) -> float:
        """Subproblem 1: θ with R(k, θ) p = q (least squares), p and q as :meth:`coordinates`; non-degenerate
        only (``free_below`` as :func:`.subproblems.subproblem_1`'s, relative to the vectors' length). With
        ``scale`` (:func:`.subproblems.subproblem_1`'s), relative to it, and clearly exact only."""
        theta = _rotate_onto_clear(p, q, MARGIN, free_below, scale)
        if theta is None:
            raise NotGeneric
        return theta

    @staticmethod
    def angles_at_distance(p: tuple[float, ...], q: tuple[float, ...], delta: float,
                           out_of_reach: bool = False) -> tuple[float, float]:
        """Subproblem 3: the two θ with |R(k, θ) p − q| = δ, p and q as :meth:`coordinates` (see
        :func:`.subproblems._roots._harmonic_clear` for ``out_of_reach``)."""
        px, py, pz, _, _ = p
        qx, qy, qz, _, _ = q
        a, b, c, scale = _distance_equation(px, py, pz, qx, qy, qz, delta)
        roots = _harmonic_clear(a, b, c, scale, MARGIN, out_of_reach)
        if roots is None:
            raise NotGeneric
        return roots


def quadratic(A: float, B: float, C: float, scale: float) -> tuple[float, float]:
    """The real roots of A t² + B t + C = 0 (:func:`.subproblems.quadratic_roots`), the second NaN for a linear
    one."""
    roots = _quadratic_clear(A, B, C, scale, MARGIN)
    if roots is None:
        raise NotGeneric
    return roots


def slide_to_distance(p: Vector, v: Vector, q: Vector, delta: float) -> tuple[float, float]:
    """The two slides s with |p + s v − q| = δ (:func:`.subproblems.prismatic_to_distance`), in its slot order."""
    roots = _slide_to_distance_clear(p, v, q, delta, MARGIN)
    if roots is None:
        raise NotGeneric
    return roots


class Height:
    """Subproblem 4 for a fixed pair h, k: the two θ with h · R(k, θ) p = δ."""

    def __init__(self, h: Vector, k: Vector) -> None:
        hk = dot(h, k)
        self.hk, self.k = hk, k
        self.h_across = (h[0] - hk * k[0], h[1] - hk * k[1], h[2] - hk * k[2])
        self.h_cross_k = cross(h, k)

    def of(self, p: Vector) -> tuple[float, float, float, float]:
        """What the angles need of p (computed once when p is fixed)."""
        return dot(self.h_across, p), dot(self.h_cross_k, p), self.hk * dot(self.k, p), norm(p)

    @staticmethod
    def angles(p: tuple[float, float, float, float], delta: float) -> tuple[float, float]:
        """The two roots; where δ is clearly out of reach, the least-squares root and NaN (as the array solver)."""
        a, b, along, length = p
        roots = _harmonic_clear(a, b, delta - along, length + abs(delta), MARGIN, True)
        if roots is None:
            raise NotGeneric
        return roots


class TwoTurns:
    """Subproblem 2 as a chain for a fixed pair of axes k1, k2 (not parallel): the two (θ1, θ2) with
    R(k1, θ1) R(k2, θ2) start = goal, that is :func:`.subproblems.subproblem_2` on (goal, start) with θ1 negated.
    The vectors enter as :meth:`start` and :meth:`goal` (those of fixed vectors computed once per plan)."""

    def __init__(self, k1: Vector, k2: Vector, free_below: float = GEOMETRY_TOLERANCE) -> None:
        """``free_below``: the radius (relative to the vectors' size) at or below which the array solver holds a
        joint as free (a spherical wrist of an arm with rounding dust holds more than subproblem 2 does)."""
        self.k1, self.k2 = k1, k2
        self.free_below = free_below
        self.normal = cross(k1, k2)
        self.sin2 = dot(self.normal, self.normal)
        self.cos, self.sin = dot(k1, k2), math.sqrt(self.sin2)

    def goal(self, v: Vector) -> tuple[float, float, float, float, float]:
        along1, along2, across = self._projections(v)
        return self._cone(along1, along2, across)

    def start(self, v: Vector) -> tuple[float, float, float, float, float]:
        along1, along2, across = self._projections(v)
        return self._cone(along2, along1, across)

    def _projections(self, v: Vector) -> tuple[float, float, float]:
        """v along k1, along k2 and along their normal."""
        (k0, k1, k2), (l0, l1, l2), (n0, n1, n2) = self.k1, self.k2, self.normal
        v0, v1, v2 = v
        return v0 * k0 + v1 * k1 + v2 * k2, v0 * l0 + v1 * l1 + v2 * l2, v0 * n0 + v1 * n1 + v2 * n2

    def _cone(self, along: float, other: float, across: float) -> tuple[float, float, float, float, float]:
        """The cone about the axis v is turned around: v along it, across, the in-plane part, the radius about it
        and |v| (``along`` on this axis, ``other`` on the other one)."""
        in_plane = other - self.cos * along
        radius = math.sqrt(across * across + in_plane * in_plane) / self.sin
        return along, across, in_plane, radius, math.sqrt(along * along + radius * radius)

    def angles(self, start: tuple[float, ...], goal: tuple[float, ...], error: float = 0.0
               ) -> tuple[tuple[float, float] | None, ...]:
        """The two pairs, the +γ crossing first; where the cones clearly miss, the least-squares pair (as the
        array solver gives it, for the FK check to reject) and None for the empty slot
        (:func:`.subproblems._paden_kahan._subproblem_2_chain_clear`; ``error`` as there)."""
        pairs = _subproblem_2_chain_clear(goal, start, self.cos, self.sin, self.sin2, self.free_below, MARGIN, error)
        if pairs is None:
            raise NotGeneric
        return pairs
