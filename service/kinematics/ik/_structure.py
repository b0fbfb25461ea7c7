"""Geometric facts about a robot's joint axes, read off its screw model.

Everything here works on the product-of-exponentials model (axes and points in
the world frame at q = 0), so the facts do not depend on the DH convention,
on the frame choices, or on base and tool transforms. Tests use tolerances
relative to the robot's size, never exact equality.

The screw model is first made canonical (:func:`canonical_model`): each
revolute axis is represented by a point near the arm (the foot of its common
normal with the previous axis, or the point nearest the previous one), never by
wherever a DH table happened to put its frame origin. A description whose DH
table carries huge compensating offsets (two nearly parallel axes whose common
normal lies kilometres away) therefore gives the same geometry, the same size
and the same plan as the compact description of the same arm.

:func:`idealised` snaps relations that hold within
:data:`~service.kinematics._tolerances.RECOGNITION_TOLERANCE` (rounded CAD
values) to exact ones, so that a closed form can be chosen for the idealised arm.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._cache import DerivedStore, memo
from .._forward import ScrewModel, cross, radius_about, screw_model
from .._tolerances import DUPLICATE_TOLERANCE, GEOMETRY_TOLERANCE, RECOGNITION_TOLERANCE, ROUNDING_TOLERANCE


@dataclass(frozen=True)
class Geometry:
    """A screw model plus the length scale used for relative tolerances.

    ``up`` (3,) is the robot's up direction in the world frame: the z axis of
    its base frame, so that a base transform (a tilted or ceiling mount) does
    not change which side of an arm is "up". ``link_x`` (n, 3), when known, holds
    the x axis of each link frame 1…n at q = 0, in the world frame: along the
    common normal of joint axes i and i+1 in every DH convention, with the
    sense the robot's designer chose. The textbook's "front" is defined by it
    (θ1 = atan2(yc, xc) puts the wrist centre along x1).
    """

    model: ScrewModel
    length_scale: float
    up: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    link_x: np.ndarray | None = None
    #: what is derived from this geometry alone, built once (:func:`exactly_idealised`)
    derived: DerivedStore = field(default_factory=DerivedStore, init=False, compare=False, repr=False)

    @property
    def dof(self) -> int:
        return len(self.model.is_revolute)

    def kinds(self, indices: range | tuple[int, ...] | None = None) -> str:
        """Joint kinds as a string such as ``"RRP"``."""
        indices = range(self.dof) if indices is None else indices
        return "".join("R" if self.model.is_revolute[i] else "P" for i in indices)

    def direction(self, i: int) -> np.ndarray:
        return self.model.directions[i]

    def point(self, i: int) -> np.ndarray:
        return self.model.points[i]

    def parallel(self, i: int, j: int) -> bool:
        """Whether the axes (or sliding directions) of joints i and j are parallel or anti-parallel."""
        return bool(radius_about(self.direction(i), self.direction(j)) <= GEOMETRY_TOLERANCE * 10)

    def nearly_parallel(self, i: int, j: int) -> bool:
        """Whether the axes (or sliding directions) of joints i and j are within ``RECOGNITION_TOLERANCE`` (rad)
        of parallel: a family that solves from the angle between them would divide by a rounding of the geometry
        there, and declines; the idealised arm's parallel families answer (see :func:`idealised`)."""
        return bool(radius_about(self.direction(i), self.direction(j)) <= RECOGNITION_TOLERANCE)

    def intersection(self, i: int, j: int) -> np.ndarray | None:
        """The point where two non-parallel revolute axes meet, or None if they are skew or parallel."""
        if self.parallel(i, j):
            return None
        return _closest_common_point([self.point(i), self.point(j)], [self.direction(i), self.direction(j)],
                                     self.length_scale)

    def common_point(self, indices: tuple[int, ...]) -> np.ndarray | None:
        """The point where all the given revolute axes meet, if they do (at least two non-parallel)."""
        if not all(self.model.is_revolute[i] for i in indices):
            return None
        directions = [self.direction(i) for i in indices]
        if all(self.parallel(indices[0], i) for i in indices[1:]):
            return None
        return _closest_common_point([self.point(i) for i in indices], directions, self.length_scale)

    def upward(self, direction: np.ndarray) -> np.ndarray:
        """``direction`` or its opposite, whichever has a non-negative component along :attr:`up`."""
        return -direction if float(direction @ self.up) < -1e-12 else direction

    def on_axis(self, i: int, point: np.ndarray) -> bool:
        """Whether ``point`` lies on the axis of revolute joint i."""
        return self.axis_distance(i, point) <= GEOMETRY_TOLERANCE * 10 * self.length_scale

    def axis_distance(self, i: int, point: np.ndarray) -> float:
        """The distance of ``point`` (3,) from the axis (line) of joint i."""
        return float(radius_about(self.direction(i), point - self.point(i)))

    def nearly_on_axis(self, i: int, point: np.ndarray) -> bool:
        """Whether ``point`` lies within ``RECOGNITION_TOLERANCE`` of the arm's size of the axis of joint i (on it
        included): a family that reads an angle off the point's radius about that axis would read it off a rounding
        of the geometry there, and declines, as :meth:`nearly_parallel`."""
        return self.axis_distance(i, point) <= RECOGNITION_TOLERANCE * self.length_scale

    def nearly_coincident(self, point: np.ndarray, other: np.ndarray) -> bool:
        """Whether two points (3,) lie within ``RECOGNITION_TOLERANCE`` of the arm's size of each other: angles read
        off the vector between them would be read off a rounding (see :meth:`nearly_on_axis`)."""
        return bool(np.linalg.norm(point - other) <= RECOGNITION_TOLERANCE * self.length_scale)


def _closest_common_point(points: list[np.ndarray], directions: list[np.ndarray], scale: float) -> np.ndarray | None:
    """Least-squares point nearest to every line; None unless it lies on all of them."""
    A = np.zeros((3, 3))
    b = np.zeros(3)
    for p, k in zip(points, directions):
        projector = np.eye(3) - np.outer(k, k)
        A += projector
        b += projector @ p
    if np.linalg.matrix_rank(A, tol=GEOMETRY_TOLERANCE) < 3:
        return None
    x = np.linalg.solve(A, b)
    for p, k in zip(points, directions):
        if radius_about(k, x - p) > GEOMETRY_TOLERANCE * 10 * scale:
            return None
    return x


def arm_size(robot) -> float:
    """The arm's size for relative tolerances in IK (residuals, duplicates, geometric tests): the size of its
    canonical screw model (:func:`canonical_model`), which depends on the lines of its axes and its tool, not on
    the numbers of its DH table (``Robot.characteristic_length`` sums those, and a table with offsets of 27 km on
    a 1 m arm makes it 54 km)."""
    return memo(robot, "ik_arm_size", lambda: canonical_model(screw_model(robot), robot.world_T_base[:3, 3])[1])


#: A previous axis at least this far from parallel (sine of the angle) puts the canonical point of the next axis at
#: their common normal's foot; closer to parallel the foot runs away (1/sine) and the nearest point is used instead.
_FOOT_SINE = 0.1


#: The polyline of an arm with a slide shorter than this (length units) is rounding dust, not a size: a P-R-P arm
#: with zero offsets written with 1e-9 rounding would otherwise measure 1e-9, and its residuals, relative to that
#: while its slides carry the tool 0.3 away, reject every solution; an R-R-P-R arm whose lines all meet in one point,
#: its angles rounded as CAD rounds them (1e-5), measures the distance between its nearly concurrent lines, 5e-5.
#: (An arm of revolute joints alone keeps a tiny size: its fixed lengths are its scale.)
_DUST_LENGTH = 1e-3


def canonical_model(model: ScrewModel, base_origin: np.ndarray) -> tuple[ScrewModel, float]:
    """The screw model with every revolute axis represented by a point near the arm, and the arm's size.

    The point on revolute axis i is the foot of the common normal with the previous revolute axis when the two are
    clearly not parallel (sine of their angle at least 0.1, and the foot no farther from the previous point than
    the arm's size), else the point of axis i nearest to the previous axis' point; the first axis takes the point
    nearest ``base_origin`` (3,), the origin of the robot's base frame in the world frame. Both choices depend on
    the lines only, not on where a description puts its frames.

    The size is the length of the polyline base origin → canonical points → tool origin at q = 0 (1 when that is
    zero): the sum of the arm's offsets and link lengths, measured on the lines themselves. An arm with a slide
    whose polyline is rounding dust (:data:`_DUST_LENGTH`) measures 1 too: its scale is its slides' travel, which
    no fixed length states.
    """
    directions, points = model.directions, model.points.copy()
    revolute = [i for i in range(len(directions)) if model.is_revolute[i]]
    previous = np.asarray(base_origin, dtype=float)
    nearest = {}
    for i in revolute:  # first pass: nearest points, always well conditioned
        k = directions[i]
        nearest[i] = points[i] + k * float(k @ (previous - points[i]))
        previous = nearest[i]
    size = _polyline([base_origin, *(nearest[i] for i in revolute), model.home[:3, 3]])
    for before, i in zip(revolute, revolute[1:]):
        foot = _common_normal_foot(points[i], directions[i], nearest[before], directions[before])
        if foot is not None and np.linalg.norm(foot - nearest[i]) <= size:
            nearest[i] = foot
    for i in revolute:
        points[i] = nearest[i]
    size = _polyline([base_origin, *(points[i] for i in revolute), model.home[:3, 3]])
    if size <= _DUST_LENGTH and not model.is_revolute.all():
        size = 1.0
    return ScrewModel(directions.copy(), points, model.is_revolute.copy(), model.home.copy()), size


def _polyline(points: list[np.ndarray]) -> float:
    total = float(sum(np.linalg.norm(b - a) for a, b in zip(points, points[1:])))
    return total if total > 0.0 else 1.0


def _common_normal_foot(p: np.ndarray, k: np.ndarray, p_other: np.ndarray, k_other: np.ndarray,
                        least_sine: float = _FOOT_SINE) -> np.ndarray | None:
    """The point of line (p, k) nearest to line (p_other, k_other); None when the sine of their angle is below
    ``least_sine`` (the foot runs away as 1/sine)."""
    normal = cross(k, k_other)
    sine = float(np.linalg.norm(normal))
    if sine <= least_sine:
        return None
    # p + t k − (p_other + s k_other) ⟂ k and k_other: t = ((p_other − p) × k_other)·n / |n|², n = k × k_other
    t = float(cross(p_other - p, k_other) @ normal) / sine ** 2
    return p + t * k


@dataclass(frozen=True)
class Idealisation:
    """An arm with its nearly special relations made exact, and how far that moved its axes.

    ``deviation`` is the largest change of any joint axis: its angle (radians) plus the displacement of its line at
    its canonical point, as a fraction of the arm's size. 0 means nothing was snapped.
    """

    geometry: Geometry
    deviation: float


def idealised(geometry: Geometry, tolerance: float = RECOGNITION_TOLERANCE) -> Idealisation:
    """Snap the relations that hold within ``tolerance`` (rad, or fraction of the arm's size) to exact ones.

    1. Directions within ``tolerance`` of parallel (or anti-parallel) take one common direction, the first joint's
       of the group; directions within ``tolerance`` of perpendicular are made exactly perpendicular (each group's
       direction loses its components along the earlier groups' it is nearly perpendicular to).
    2. Revolute axes that (after step 1) pass within ``tolerance`` × size of a common point are moved to pass
       through it (their least-squares point), for the groups the families look for, in this order: the last
       three axes (a wrist), the first three (a wrist at the base), then consecutive pairs (a shoulder, the
       UR type's axes 4–5 and 5–6). A pair whose first axis already meets another keeps that axis and
       translates the second onto it: through the point where the kept axis meets the others when the second
       passes within ``tolerance`` × size of it (four axes through one point), else through the foot of their
       common normal. An axis is moved once at most.
    3. A revolute axis left out of step 2 that passes within ``tolerance`` × size of the tool point (the flange
       origin at q = 0) is moved through it.

    Lines turn about their canonical points, which lie on the arm, so a turn by ε moves no part of the arm by much
    more than ε × size.
    """
    model, scale = geometry.model, geometry.length_scale
    n = geometry.dof
    directions = model.directions.copy()
    # 1. parallel groups, then perpendicular snapping between group directions
    group_of = list(range(n))
    for j in range(n):
        for i in range(j):
            if group_of[i] == i and radius_about(directions[i], directions[j]) <= tolerance:
                group_of[j] = i
                break
    leaders = [i for i in range(n) if group_of[i] == i]
    for position, j in enumerate(leaders):
        earlier = _spanning([directions[i] for i in leaders[:position]
                             if abs(float(directions[i] @ directions[j])) <= tolerance])
        if 0 < len(earlier) < 3:  # remove the components along the span of those directions
            projected = _across(directions[j], earlier)
            directions[j] = projected / np.linalg.norm(projected)
    for j in range(n):
        leader = directions[group_of[j]]
        directions[j] = leader if float(leader @ model.directions[j]) >= 0 else -leader
    points = model.points.copy()
    # 2. nearly concurrent revolute axes, in the groups the families use: a wrist at the end or at the base, then
    # consecutive pairs (a shoulder, the UR type's last two axes)
    revolute = set(i for i in range(n) if model.is_revolute[i])
    candidates = [tuple(range(n - 3, n)), (0, 1, 2)] + [(i, i + 1) for i in range(n - 1)] if n >= 3 else \
        [(i, i + 1) for i in range(n - 1)]
    assigned: set[int] = set()
    for group in candidates:
        members = list(group)
        fixed = [g for g in members if g in assigned]
        if not set(members) <= revolute or len(fixed) == len(members) or (fixed and len(members) > 2):
            continue
        if all(radius_about(directions[members[0]], directions[g]) <= _CONCURRENT_SINE
               for g in members[1:]):
            continue  # all parallel, or so nearly that rounding sets their common point: none to snap to
        centre = _least_squares_point(points[members], directions[members])
        if max(radius_about(directions[g], centre - points[g]) for g in members) > tolerance * scale:
            continue
        if fixed:  # a pair whose first axis already meets another: translate the free one onto it
            (kept,), (moved,) = fixed, [g for g in members if g not in fixed]
            if radius_about(directions[moved], points[kept] - points[moved]) <= tolerance * scale:
                points[moved] = points[kept]  # through the point where the kept axis meets the others (a 4th axis)
            else:  # on both lines now: the moved line passes through the kept one's foot
                points[moved] = _common_normal_foot(points[kept], directions[kept], points[moved],
                                                    directions[moved], 0.0)
        else:
            for g in members:
                points[g] = centre
        assigned.update(members)
    # 3. the tool point near a revolute axis that meets no other (a flange on the last axis, as most arms have it):
    # step 1 turned that axis about its canonical point, off the flange by up to the turn × the arm's length, and
    # the families would see a tool point off the axis that joint does not move on the true arm
    flange = model.home[:3, 3]
    for j in sorted(revolute - assigned):
        if radius_about(directions[j], flange - points[j]) <= tolerance * scale:
            points[j] = flange
    # how far each line moved: its angle, and its displacement at the canonical point
    angle = radius_about(model.directions, directions)
    shift = np.array([radius_about(directions[i], model.points[i] - points[i]) for i in range(n)]) / scale
    shift[~model.is_revolute] = 0.0
    deviation = float((angle + shift).max()) if n else 0.0
    ideal = Geometry(ScrewModel(directions, points, model.is_revolute.copy(), model.home.copy()), scale,
                     up=geometry.up, link_x=geometry.link_x)
    return Idealisation(ideal, deviation)


def exactly_idealised(geometry: Geometry) -> Idealisation:
    """The arm with the relations exact recognition accepts (those within ``10 GEOMETRY_TOLERANCE``, as
    :meth:`Geometry.parallel`) made exact, and how far that moved it: a closed form that assumes those relations
    sees its vectors off by about that deviation (0 for an arm whose relations hold to the last digit). Built once
    per geometry: the plan choice, the spherical wrist and the polar shoulder all read it."""
    return memo(geometry, "exactly_idealised", lambda: idealised(geometry, 10 * GEOMETRY_TOLERANCE))


def read_off_below(geometry: Geometry) -> float:
    """The radius (relative to the size of the unit vectors it is read off) at or below which a family holds an
    angle as free rather than read it off a vector about its axis: where the arm's deviation from the relations
    exact recognition accepted (:func:`exactly_idealised`), over that radius, would move the angle by more than
    ``DUPLICATE_TOLERANCE`` (a vendor's URDF, 1e-11 off, reads it within 1e-5 of the axis' singularity). An exact
    arm keeps the subproblems' own test, ``GEOMETRY_TOLERANCE``."""
    return max(GEOMETRY_TOLERANCE, exactly_idealised(geometry).deviation / DUPLICATE_TOLERANCE)


def read_off_error(geometry: Geometry) -> float:
    """The error (relative to their size) of the unit vectors a family reads an angle off about an axis: the
    target's rounding, or the arm's deviation from the relations exact recognition accepted
    (:func:`exactly_idealised`), whichever is larger. Over the vectors' radius about the axis, it is the angle's
    error (the reading :func:`read_off_below` holds free where that would pass ``DUPLICATE_TOLERANCE``)."""
    return max(ROUNDING_TOLERANCE, exactly_idealised(geometry).deviation)


def target_error(geometry: Geometry, distance: float | np.ndarray, rounding: float = ROUNDING_TOLERANCE
                 ) -> float | np.ndarray:
    """The error, in length units, with which a family of an exactly recognised arm sees a target ``distance``
    from the base (a float, or an array of them): the target's ``rounding`` and the arm's own deviation from the
    family's relations (:func:`exactly_idealised`: 1e-16 for a DH table, 1e-11 for a vendor's URDF), each relative
    to the lever they act on, the arm's size plus that distance. Every band a family draws around a quantity it
    reads off the target (a point on an axis, two roots meeting) is at least this wide. A subproblem that counts
    its inputs' rounding itself takes ``rounding=0``."""
    return (rounding + exactly_idealised(geometry).deviation) * (geometry.length_scale + distance)


#: Lines whose directions are all within this sine of the first's have no common point :func:`idealised` snaps
#: to: their least-squares point is set by rounding (its matrix's smallest eigenvalue is about sine² / 2, and at
#: 1e-8 that is singular to machine precision: a LinAlgError, a 500 over HTTP).
_CONCURRENT_SINE = 1e-6
#: A direction adds to the span :func:`_spanning` keeps only where it leaves the span of those before it by at
#: least this (the sine of its angle to it).
_SPANNING_SINE = 0.5


def _spanning(directions: list[np.ndarray]) -> list[np.ndarray]:
    """The directions (unit, each (3,)) that span their plane or space well: each kept only where it leaves the span
    of those kept before it by at least :data:`_SPANNING_SINE`.

    Two directions a little more than the tolerance apart (a pair the parallel test left in two groups, as
    rounding to the tolerance's order leaves them) span a plane set by their tiny difference: removing a third
    direction's components along it turned that direction by up to the tolerance over their angle (0.6 rad on an
    arm rounded to 1e-8, which then solved as another arm). Dropping the second moves the third by about the
    tolerance, and leaves it perpendicular to both within about the tolerance."""
    kept: list[np.ndarray] = []
    for k in directions:
        if not kept or np.linalg.norm(_across(k, kept)) >= _SPANNING_SINE:
            kept.append(k)
    return kept


def _across(k: np.ndarray, span: list[np.ndarray]) -> np.ndarray:
    """``k`` (3,) less its components along the span of ``span`` (1 to 3 independent (3,) directions)."""
    E = np.array(span).T  # (3, m)
    return k - E @ np.linalg.solve(E.T @ E, E.T @ k)


def _least_squares_point(points: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """The point nearest (least squares) to the lines (points[i], directions[i]), which are not all parallel."""
    projectors = np.eye(3) - directions[:, :, None] * directions[:, None, :]
    return np.linalg.solve(projectors.sum(axis=0), np.einsum("kij,kj->i", projectors, points))

