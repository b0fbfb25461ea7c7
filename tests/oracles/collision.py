"""Independent references for signed distances between capsules, spheres and boxes.

This module is a test oracle: nothing here calls or copies the service's collision code.

* :class:`Bullet`: pybullet's ``getClosestPoints`` between collision shapes made with ``createCollisionShape``
  in a DIRECT client. Bullet's capsule lies along its local z axis with ``height`` the segment's length, and its
  boxes carry a collision margin (0.001 by default) that rounds their edges and corners: the oracle sets it to 0
  (``changeDynamics(collisionMargin=0)``) unless asked for the default, to show the difference.
* :func:`core_distance`: the distance between two cores (a point, a segment, a box) as a bound-constrained
  least-squares problem over their parameters, solved by enumerating every active set (each parameter at its
  lower bound, at its upper bound, or free) with ``numpy.linalg.lstsq``: a different formulation from the
  service's closed forms, exact up to rounding.
* :func:`penetration_depth`: the minimum translation distance of two overlapping convex polytopes (a segment or
  a box against a box), from the facets of their Minkowski difference computed by Qhull (``scipy.spatial``).
* :func:`signed_distances`: the two combined, radii subtracted: a second reference for every kind and regime.
* :func:`segment_distance_exact`: two segments in exact rational arithmetic, for nearly parallel segments.

Shapes are read for their fields only (:func:`kind_of`): the service's records
(:class:`~service.kinematics.collision.Capsule`, ``Sphere``, ``Box``) or light records with the same fields.
"""

from __future__ import annotations

import itertools

import numpy as np


# --- pybullet -------------------------------------------------------------------------------------------------


def kind_of(shape) -> str:
    """"box", "capsule" or "sphere", read from the fields a shape has (the service's records, or any record with
    the same field names: ``center``, ``rotation``, ``half_size``; ``start``, ``end``, ``radius``; ``center``,
    ``radius``)."""
    if hasattr(shape, "half_size"):
        return "box"
    return "capsule" if hasattr(shape, "start") else "sphere"


class Bullet:
    """A pybullet DIRECT client that measures the signed distance of two shapes with ``getClosestPoints``.

    Shapes are queried as collision shapes with a pose, without bodies (a body costs about a millisecond to
    make); each distinct shape is made once. ``box_margin`` None keeps Bullet's default collision margin on boxes;
    a number sets it, through one body made for each box shape (the margin belongs to the shape).
    """

    #: getClosestPoints reports pairs closer than this; farther pairs are not measured here.
    REACH = 1.0e3

    def __init__(self, box_margin: float | None = 0.0) -> None:
        import pybullet

        self._p = pybullet
        self._client = pybullet.connect(pybullet.DIRECT)
        self._box_margin = box_margin
        self._shapes: dict[tuple, int] = {}

    def close(self) -> None:
        self._p.disconnect(self._client)

    def distance(self, shape_a, shape_b) -> float:
        """The smallest contact distance getClosestPoints reports for the two shapes (negative in overlap)."""
        if len(self._shapes) > 20_000:  # shapes are never freed one by one: start afresh now and then
            self._p.resetSimulation(physicsClientId=self._client)
            self._shapes.clear()
        index_a, position_a, orientation_a = self._posed(shape_a)
        index_b, position_b, orientation_b = self._posed(shape_b)
        points = self._p.getClosestPoints(
            -1, -1, self.REACH, collisionShapeA=index_a, collisionShapeB=index_b,
            collisionShapePositionA=position_a, collisionShapePositionB=position_b,
            collisionShapeOrientationA=orientation_a, collisionShapeOrientationB=orientation_b,
            physicsClientId=self._client)
        return min(point[8] for point in points) if points else float("nan")

    def _posed(self, shape) -> tuple[int, list[float], list[float]]:
        kind = kind_of(shape)
        if kind == "sphere":
            return self._shape(("sphere", float(shape.radius))), list(shape.center), [0.0, 0.0, 0.0, 1.0]
        if kind == "capsule":
            axis = np.asarray(shape.end) - np.asarray(shape.start)
            length = float(np.linalg.norm(axis))
            orientation = _quaternion_turning_z_to(axis / length if length > 0.0 else np.array([0.0, 0.0, 1.0]))
            middle = 0.5 * (np.asarray(shape.start) + np.asarray(shape.end))
            return self._shape(("capsule", float(shape.radius), length)), list(middle), orientation
        return (self._shape(("box", *map(float, shape.half_size))), list(shape.center),
                _quaternion_xyzw(np.asarray(shape.rotation)))

    def _shape(self, key: tuple) -> int:
        index = self._shapes.get(key)
        if index is not None:
            return index
        p, client = self._p, self._client
        if key[0] == "sphere":
            index = p.createCollisionShape(p.GEOM_SPHERE, radius=key[1], physicsClientId=client)
        elif key[0] == "capsule":
            index = p.createCollisionShape(p.GEOM_CAPSULE, radius=key[1], height=key[2], physicsClientId=client)
        else:
            index = p.createCollisionShape(p.GEOM_BOX, halfExtents=list(key[1:]), physicsClientId=client)
            if self._box_margin is not None:
                body = p.createMultiBody(baseMass=0.0, baseCollisionShapeIndex=index, physicsClientId=client)
                p.changeDynamics(body, -1, collisionMargin=self._box_margin, physicsClientId=client)
        self._shapes[key] = index
        return index


def _quaternion_turning_z_to(direction: np.ndarray) -> list[float]:
    """(x, y, z, w) of the shortest rotation taking e_z to the unit ``direction``."""
    half = np.array([0.0, 0.0, 1.0]) + direction
    if np.linalg.norm(half) < 1e-12:  # direction = -e_z: half a turn about x
        return [1.0, 0.0, 0.0, 0.0]
    half /= np.linalg.norm(half)
    axis = np.cross([0.0, 0.0, 1.0], half)
    return [*axis, float(half[2])]


def _quaternion_xyzw(R: np.ndarray) -> list[float]:
    """(x, y, z, w) of a rotation matrix (Shepperd's method)."""
    trace = np.trace(R)
    if trace > 0.0:
        s = 2.0 * np.sqrt(1.0 + trace)
        return [(R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s, 0.25 * s]
    i = int(np.argmax(np.diag(R)))
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2.0 * np.sqrt(1.0 + R[i, i] - R[j, j] - R[k, k])
    q = np.empty(4)
    q[i] = 0.25 * s
    q[j] = (R[j, i] + R[i, j]) / s
    q[k] = (R[k, i] + R[i, k]) / s
    q[3] = (R[k, j] - R[j, k]) / s
    return q.tolist()


# --- enumeration of active sets -------------------------------------------------------------------------------


def _core(shape):
    """A shape's core as origin + G λ with lower ≤ λ ≤ upper, and its radius."""
    kind = kind_of(shape)
    if kind == "sphere":
        return np.asarray(shape.center), np.zeros((3, 0)), np.zeros(0), np.zeros(0), shape.radius
    if kind == "capsule":
        start, end = np.asarray(shape.start), np.asarray(shape.end)
        return start, (end - start)[:, None], np.zeros(1), np.ones(1), shape.radius
    half = np.asarray(shape.half_size)
    return np.asarray(shape.center), np.asarray(shape.rotation), -half, half, 0.0


def core_distances(shapes_a, shapes_b) -> np.ndarray:
    """min |x_a(λ) - x_b(μ)| over the cores' parameters, for pairs of shapes of one kind each, by enumerating
    active sets.

    Each parameter is at its lower bound, its upper bound, or free; the free ones solve the least-squares
    problem (normal equations, or the minimum-norm solution by ``numpy.linalg.pinv`` when they are singular) and
    the candidate counts only when they are within their bounds. The minimisers of a convex problem within the
    parameter box form a polytope; each of its vertices is the unique stationary point of the face it is
    interior to, where the free columns are independent (so at most 3 are free). Every candidate is a genuine
    pair of points, so none undershoots.
    """
    cores_a = [_core(shape) for shape in shapes_a]
    cores_b = [_core(shape) for shape in shapes_b]
    G = np.array([np.hstack([a[1], -b[1]]) for a, b in zip(cores_a, cores_b)])  # (N, 3, k)
    low = np.array([np.concatenate([a[2], b[2]]) for a, b in zip(cores_a, cores_b)]).reshape(len(G), -1)
    high = np.array([np.concatenate([a[3], b[3]]) for a, b in zip(cores_a, cores_b)]).reshape(len(G), -1)
    offset = np.array([a[0] - b[0] for a, b in zip(cores_a, cores_b)])
    count = G.shape[2]
    best = np.full(len(G), np.inf)
    for states in itertools.product((0, 1, 2), repeat=count):
        states = np.array(states, dtype=int)
        free = np.flatnonzero(states == 2)
        if free.size > 3:
            continue
        x = np.where(states == 0, low, high)
        feasible = np.ones(len(G), dtype=bool)
        if free.size:
            fixed = np.flatnonzero(states != 2)
            columns = G[:, :, free]
            target = -(offset + np.einsum("nik,nk->ni", G[:, :, fixed], x[:, fixed]))
            normal = np.einsum("nik,nil->nkl", columns, columns)
            try:
                solution = np.linalg.solve(normal, np.einsum("nik,ni->nk", columns, target)[..., None])[..., 0]
            except np.linalg.LinAlgError:
                solution = np.einsum("nki,ni->nk", np.linalg.pinv(columns), target)
            span = high[:, free] - low[:, free]
            feasible = np.all((solution >= low[:, free] - 1e-12 * span) & (solution <= high[:, free] + 1e-12 * span),
                              axis=1)
            x[:, free] = solution
        distance = np.linalg.norm(offset + np.einsum("nik,nk->ni", G, x), axis=1)
        best = np.where(feasible, np.minimum(best, distance), best)
    return best


def core_distance(shape_a, shape_b) -> float:
    """:func:`core_distances` of one pair."""
    return float(core_distances([shape_a], [shape_b])[0])


# --- Minkowski difference by Qhull ----------------------------------------------------------------------------


def _corners(shape) -> np.ndarray:
    kind = kind_of(shape)
    if kind == "capsule":
        return np.array([shape.start, shape.end], dtype=float)
    if kind == "sphere":
        return np.asarray(shape.center, dtype=float)[None]
    signs = np.array(list(itertools.product((-1.0, 1.0), repeat=3)))
    return np.asarray(shape.center) + (signs * np.asarray(shape.half_size)) @ np.asarray(shape.rotation).T


def penetration_depth(shape_a, shape_b) -> float:
    """The minimum translation distance of the cores of two overlapping shapes, one of them a box: the distance
    from the origin to the nearest facet of the convex hull of the corner differences (their Minkowski
    difference), Qhull's facet planes n · x + c ≤ 0 giving the distance -c."""
    from scipy.spatial import ConvexHull

    differences = (_corners(shape_b)[:, None, :] - _corners(shape_a)[None, :, :]).reshape(-1, 3)
    return float(-ConvexHull(differences).equations[:, 3].max())


def signed_distances(shapes_a, shapes_b) -> np.ndarray:
    """Signed distances from :func:`core_distances` (cores apart or touching) or :func:`penetration_depth`
    (overlapping cores, one of them a box), less the radii, for pairs of shapes of one kind each. Two round
    cores never penetrate (their Minkowski difference is flat)."""
    apart = core_distances(shapes_a, shapes_b)
    result = np.empty(len(apart))
    for k, (shape_a, shape_b) in enumerate(zip(shapes_a, shapes_b)):
        radius = _core(shape_a)[4] + _core(shape_b)[4]
        scale = max(np.abs(_corners(shape_a)).max(), np.abs(_corners(shape_b)).max(), 1e-300)
        if apart[k] > 1e-12 * scale or "box" not in (kind_of(shape_a), kind_of(shape_b)):
            result[k] = apart[k] - radius
        else:
            # cores that meet, or nearly (within the enumeration's rounding): the facet planes give the depth,
            # or for cores apart by less than that, minus the largest facet distance, their distance there
            result[k] = -penetration_depth(shape_a, shape_b) - radius
    return result


def signed_distance(shape_a, shape_b) -> float:
    """:func:`signed_distances` of one pair."""
    return float(signed_distances([shape_a], [shape_b])[0])


# --- exact rational arithmetic for segments -------------------------------------------------------------------


def segment_distance_exact(p0, p1, q0, q1) -> float:
    """The distance between two segments, computed in exact rational arithmetic from the floats given (the
    candidates of every face of the parameter square), rounded once at the end."""
    from fractions import Fraction

    p0, p1, q0, q1 = ([Fraction(float(x)) for x in point] for point in (p0, p1, q0, q1))
    d1 = [b - a for a, b in zip(p0, p1)]
    d2 = [b - a for a, b in zip(q0, q1)]
    r = [a - b for a, b in zip(p0, q0)]

    def dot(u, v):
        return sum(x * y for x, y in zip(u, v))

    def squared(s, t):
        gap = [ri + s * x - t * y for ri, x, y in zip(r, d1, d2)]
        return dot(gap, gap)

    def clamp(value):
        return min(max(value, Fraction(0)), Fraction(1))

    a, b, c, e, f = dot(d1, d1), dot(d1, d2), dot(d1, r), dot(d2, d2), dot(d2, r)
    candidates = []
    for s in (Fraction(0), Fraction(1)):
        candidates.append(squared(s, clamp((b * s + f) / e) if e else Fraction(0)))
    for t in (Fraction(0), Fraction(1)):
        candidates.append(squared(clamp((t * b - c) / a) if a else Fraction(0), t))
    determinant = a * e - b * b
    if determinant:
        s, t = (b * f - c * e) / determinant, (a * f - b * c) / determinant
        if 0 <= s <= 1 and 0 <= t <= 1:
            candidates.append(squared(s, t))
    return float(min(candidates)) ** 0.5
