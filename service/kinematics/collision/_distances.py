"""Signed distances between capsules, spheres and boxes, vectorised over a batch.

Sign convention
---------------
The signed distance of two closed convex shapes A and B is

    sd(A, B) = min |p - q| over p in A, q in B            when A and B are apart (> 0),
    sd(A, B) = -min |v| over v with (A + v) ∩ int B = ∅    when they overlap (< 0),

that is, the separation distance, or minus the penetration depth: the length of the shortest translation that
separates them (the minimum translation distance). Touching shapes have 0. It is the signed distance of the
origin to the boundary of the Minkowski difference B - A, positive outside.

Every shape is a core swept by a ball: a sphere is a point and a radius, a capsule a segment and a radius, a box
is its own core with radius 0. For convex cores, sweeping by balls subtracts the radii exactly, in overlap as well
as apart (the Minkowski difference of the cores grows by the ball of radius r_A + r_B)::

    sd(core_A ⊕ ball(r_A), core_B ⊕ ball(r_B)) = sd(core_A, core_B) - r_A - r_B

So every function below computes the signed distance of the cores and subtracts the radii. Two points or two
segments never penetrate (their Minkowski difference is at most two-dimensional), so there sd is the distance.
A point is a segment of length 0, so three cores cover every pair: segment–segment (:func:`_segment_segment`),
box–segment (:func:`_box_segment`) and box–box (:func:`_box_box`). Where one shape is a point (a sphere, or a
capsule of length 0) its own cores are shorter and cheaper: segment–point (:func:`_segment_point`) and box–point
(:func:`_box_point`); they give the same distances as the general cores to rounding.

Results
-------
:class:`Separation` holds ``distance`` (batch shape) and the witness points: ``point_a`` on the surface of A,
``point_b`` on the surface of B, and the unit ``normal`` from A towards B, with

    point_b - point_a = distance · normal

so translating A by ``point_b - point_a`` makes the shapes touch. Apart, the points are the closest points; in
overlap they are the deepest points along the separating direction. Where the witness is not unique (parallel
segments, concentric spheres) one of them is given.

Conventions
-----------
* Points have shape (..., 3), radii and half sizes shape (...) and (..., 3), rotations (..., 3, 3) with the box's
  edges along their columns (``world_R_box``). Every input broadcasts against the others; their broadcast shape,
  the *batch shape*, leads every result. All in one frame and one length unit; the results are in it too.
* A box is given by its centre, rotation and half sizes (half its edge lengths, each > 0). Rotations are taken as
  orthonormal: the penetration depths use the identities of an orthonormal matrix (a rotation off by δ moves
  results by about δ times the boxes' size). :class:`~._shapes.Box` records hold orthonormal rotations, and
  link frames from :func:`~service.kinematics.link_frames` are products of rotations.
* Inputs are not checked (these run inside the collision model, after validation). A non-finite input gives a
  NaN or infinite result in its row only.
* Internally vectors are component-first, shape (3, ...), and a shape's reference points are stacked: a segment's
  ends (3, 2, ...), a box's centre and axes (3, 4, ...). Each arithmetic step is then one numpy call on
  contiguous blocks. The private cores run with 0/0 and x/0 allowed (:func:`_quiet`): they stand for an axis
  that does not exist or a coordinate that does not move, and the cores handle the NaN and infinities they give.
  The collision model (:mod:`._model`) calls them directly in that layout, without witness points.

Accuracy
--------
Every step is either a clamped projection or a ratio whose rounding error is relative to the size of the inputs,
so distances are accurate to a few ulps of the coordinates' magnitude, including zero-length and (nearly) parallel
segments and edges (tests: within 1e-13 of an exact enumeration with Qhull on 10,000 random pairs of each kind,
and within 1e-14 of exact rational arithmetic for segments 1e-16 to 1e-2 rad from parallel).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from ._shapes import Box, Capsule, Shape, Sphere

#: Denominators are kept at or above this, so that a zero-length segment gives the parameter 0 instead of 0/0.
#: Where it applies, the numerator is 0 as well (the vector is exactly 0), or the parameter is clamped.
_TINY = float(np.finfo(float).tiny)


class Separation(NamedTuple):
    """Signed distances and their witnesses; see the module docstring.

    ``distance`` has the batch shape; ``point_a``, ``point_b`` and ``normal`` the batch shape + (3,).
    """

    distance: np.ndarray
    point_a: np.ndarray
    point_b: np.ndarray
    normal: np.ndarray


# --- component-first helpers --------------------------------------------------------------------------------------


def _dot(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """u · v for component-first vectors (3, ...)."""
    return np.einsum("i...,i...->...", u, v)


def _cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """u × v for component-first vectors (3, ...)."""
    return np.stack(np.broadcast_arrays(u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                                        u[0] * v[1] - u[1] * v[0]))


def _clip_unit(t: np.ndarray) -> np.ndarray:
    """Clamp to [0, 1] in place (NaN becomes 1: ``fmin`` drops it); returns ``t``."""
    np.fmin(t, 1.0, out=t)
    np.maximum(t, 0.0, out=t)
    return t


def _to_box(R: np.ndarray, v: np.ndarray) -> np.ndarray:
    """R^T v: a world vector (3, ...) in the frame of a box whose axes are the columns of R (3, 3, ...)."""
    return np.einsum("ij...,i...->j...", R, v)


def _from_box(R: np.ndarray, v: np.ndarray) -> np.ndarray:
    """R v: a box-frame vector (3, ...) in the world frame."""
    return np.einsum("ij...,j...->i...", R, v)


def _unit(v: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    """v / |v|, and ``fallback`` (a unit vector, broadcastable) where v is 0."""
    length = np.sqrt(_dot(v, v))
    return np.where(length > 0.0, v / np.where(length > 0.0, length, 1.0), fallback)


def _any_perpendicular(d: np.ndarray) -> np.ndarray:
    """A unit vector perpendicular to d (3, ...); e_z where d is 0."""
    x = np.zeros_like(d)
    x[0] = 1.0
    y = np.zeros_like(d)
    y[1] = 1.0
    across_x, across_y = _cross(d, x), _cross(d, y)
    larger = _dot(across_x, across_x) >= _dot(across_y, across_y)
    return _unit(np.where(larger, across_x, across_y), _E_Z.reshape((3,) + (1,) * (d.ndim - 1)))


_E_Z = np.array([0.0, 0.0, 1.0])


class _Core(NamedTuple):
    """Signed distance of the cores, with witnesses on the cores: point_b - point_a = distance · normal."""

    distance: np.ndarray
    point_a: np.ndarray
    point_b: np.ndarray
    normal: np.ndarray


def _swept(core: _Core, radius_a, radius_b) -> _Core:
    """The cores swept by balls of radii ``radius_a`` and ``radius_b``: the radii come off the distance and the
    witnesses move out along the normal."""
    return _Core(core.distance - radius_a - radius_b, core.point_a + radius_a * core.normal,
                 core.point_b - radius_b * core.normal, core.normal)


# --- points and segments ------------------------------------------------------------------------------------------


#: Rows of ``ends`` (p0, p1, q0, q1) whose differences are d1 = p1 - p0, d2 = q1 - q0 and r = p0 - q0.
_SEGMENT_HEADS = np.array([1, 3, 0])
_SEGMENT_TAILS = np.array([0, 2, 2])


def _segment_segment(ends: np.ndarray, witness: bool):
    """Distance between the segments P(s) = p0 + s·d1 and Q(t) = q0 + t·d2, 0 ≤ s, t ≤ 1; ``ends`` is
    (3, 4, ...): p0, p1, q0, q1.

    With d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0, and a = d1·d1, b = d1·d2, c = d1·r, e = d2·d2, f = d2·r,
    the squared distance |r + s d1 - t d2|² is a convex quadratic on the unit square. Its minimiser is reached
    by three clamped steps (Ericson's order, with the roles of s and t swapped):

        t₀ = (r⊥ · d2⊥) / (d2⊥ · d2⊥),   v⊥ = v - ((v · d1)/a) d1    the lines' common perpendicular foot on Q
        s  = clamp((b t - c) / a)          with t = clamp(t₀): the point of P nearest Q(t)
        t  = clamp((b s + f) / e)          the point of Q nearest P(s)

    and sd = |P(s) - Q(t)|. The first step projects out d1 rather than forming a e - b² (the Gram determinant),
    whose cancellation would lose digits for nearly parallel segments: d2⊥ is a difference of vectors whose
    rounding is relative to |d2|, so t₀ is the exact answer for inputs perturbed by a few ulps, and the distance
    (evaluated from actual points of both segments) stays accurate to a few ulps of the coordinates. Parallel
    segments (d2⊥ = 0) take t₀ = 0: every t is then a minimiser before clamping. Zero-length segments (a
    sphere's centre) take s = 0 or t = 0, for which the numerators vanish too; for two of them the distance is
    |p0 - q0|, for one the clamped projection of the point on the other segment.
    """
    vectors = ends[:, _SEGMENT_HEADS] - ends[:, _SEGMENT_TAILS]  # d1, d2, r
    gram = np.einsum("iu...,iv...->uv...", vectors[:, :2], vectors)  # [[a, b, c], [b, e, f]]
    d1 = vectors[:, 0]
    along = gram[0, 1:] / np.maximum(gram[0, 0], _TINY)  # b/a, c/a
    perpendicular = vectors[:, 1:] - along * d1[:, None]  # d2⊥, r⊥
    products = np.einsum("i...,iv...->v...", perpendicular[:, 0], perpendicular)  # d2⊥·d2⊥, d2⊥·r⊥
    t = products[1] / np.maximum(products[0], _TINY)
    _clip_unit(t)
    s = t * along[0]
    s -= along[1]
    _clip_unit(s)
    t = gram[0, 1] * s
    t += gram[1, 2]
    t /= np.maximum(gram[1, 1], _TINY)
    _clip_unit(t)
    gap = s * d1  # P(s) - Q(t) = r + s d1 - t d2
    gap += vectors[:, 2]
    gap -= t * vectors[:, 1]
    distance = np.sqrt(_dot(gap, gap))
    if not witness:
        return distance
    # the normal runs from P to Q; where they coincide, across both segments (or any way across a segment)
    d2 = vectors[:, 1]
    across = _cross(d1, d2)
    fallback = _unit(across, _any_perpendicular(np.where(gram[0, 0] >= gram[1, 1], d1, d2)))
    return _Core(distance, ends[:, 0] + s * d1, ends[:, 2] + t * d2, _unit(-gap, fallback))


def _nearest_on_segment(offset: np.ndarray, segment: np.ndarray, inverse_square_length) -> np.ndarray:
    """The parameter s* = clamp((offset · segment) / (segment · segment)) of the point of a segment P(s) = p0 + s
    segment nearest a point q, given ``offset`` = q - p0 (3, ...) and 1 / (segment · segment) (any finite number
    for a segment of length 0, whose s* is then 0); ``offset`` becomes the gap q - P(s*) in place."""
    along = _dot(offset, segment)
    along *= inverse_square_length
    _clip_unit(along)
    offset -= along * segment
    return along


def _segment_point(ends: np.ndarray, witness: bool):
    """Distance between the segment P(s) = p0 + s·d, 0 ≤ s ≤ 1, and the point q; ``ends`` is (3, 3, ...): p0,
    p1, q. The nearest point of the segment is the clamped projection s* = clamp(((q - p0) · d) / (d · d))
    (:func:`_nearest_on_segment`; s* = 0 for d = 0, two points), and sd = |q - P(s*)|."""
    segment = ends[:, 1] - ends[:, 0]
    gap = ends[:, 2] - ends[:, 0]
    along = _nearest_on_segment(gap, segment, 1.0 / np.maximum(_dot(segment, segment), _TINY))
    distance = np.sqrt(_dot(gap, gap))
    if not witness:
        return distance
    # the normal runs from the segment to the point; where the point is on it, any way across it
    return _Core(distance, ends[:, 0] + along * segment, ends[:, 2], _unit(gap, _any_perpendicular(segment)))


# --- boxes --------------------------------------------------------------------------------------------------------


def _box_point_local(x: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Signed distance from the box |x_i| ≤ h_i to the point x, both in the box frame (3, ...).

    With m = |x| - h (componentwise),

        sd = |max(m, 0)| + min(max_i m_i, 0)

    the distance to the box outside it, and minus the distance to the nearest face inside it (for a point, the
    penetration depth is the distance to the boundary).
    """
    m = np.abs(x)
    m -= h
    outside = np.maximum(m, 0.0)
    inside = np.minimum(np.maximum(np.maximum(m[0], m[1]), m[2]), 0.0)
    return np.sqrt(_dot(outside, outside)) + inside


def _box_point(box: np.ndarray, h: np.ndarray, point: np.ndarray, witness: bool):
    """A box and a point: ``box`` (3, 4, ...) is the centre and the three axes (the columns of R), ``h`` the half
    sizes (3, ...), ``point`` (3, ...). In the box frame x = R^T (point - centre), sd is the box's signed
    distance field at x (:func:`_box_point_local`). Apart, the witness on the box is the clamp of x; inside, the
    point of the nearest face straight out from x (the first such face when several are nearest)."""
    center, R = box[:, 0], box[:, 1:4]
    x = _to_box(R, point - center)
    distance = _box_point_local(x, h)
    if not witness:
        return distance
    on_box = np.clip(x, -h, h)
    normal_box = _unit(x - on_box, _E_Z.reshape((3,) + (1,) * (x.ndim - 1)))
    inside = distance <= 0.0  # on the surface too: the face's normal
    if inside.any():
        nearest_face = np.argmax(np.abs(x) - h, axis=0)  # the axis of the largest |x_i| - h_i
        face = np.arange(3).reshape((3,) + (1,) * (x.ndim - 1)) == nearest_face
        outward = np.where(x >= 0.0, 1.0, -1.0)
        on_box = np.where(inside & face, outward * h, np.where(inside, x, on_box))
        normal_box = np.where(inside, np.where(face, outward, 0.0), normal_box)
    return _Core(distance, center + _from_box(R, on_box), point, _from_box(R, normal_box))


def _segment_box_parameter(a: np.ndarray, d: np.ndarray, h: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The parameter t in [0, 1] of the point of the segment a + t·d nearest the box |x_i| ≤ h_i (box frame),
    and whether the segment meets the box.

    Along the line, coordinate i is within its slab |x_i| ≤ h_i for t between the entry and exit times

        entry_i = (-|d_i| h_i - d_i a_i) / d_i²,   exit_i = (|d_i| h_i - d_i a_i) / d_i²

    (every t, or none, when d_i = 0), and the squared distance to the box is

        f(t) = Σ_i d_i² dist(t, [entry_i, exit_i])²

    convex, so the segment's t* is the line's minimiser clamped to [0, 1]. With X = min exit_i and
    Y = max entry_i: if Y ≤ X the line meets the box for t in [Y, X] (f = 0 there). Otherwise f' ≤ 0 before X
    and ≥ 0 after Y, so the minimiser lies in [X, Y]; there the axes whose exit is X are past their slab and
    those whose entry is Y before it. Their terms alone vanish at

        t₀ = Σ_{exit_i = X} (|d_i| h_i - d_i a_i) + Σ_{entry_i = Y} (-|d_i| h_i - d_i a_i)
             ─────────────────────────────────────────────────────────────────────────────
                              Σ_{exit_i = X or entry_i = Y} d_i²

    and the remaining axis (if any) is past its slab at the minimiser exactly when t₀ > exit_i, before it when
    t₀ < entry_i (f' is nondecreasing). The minimiser is the same ratio over the terms active there:

        t* = (Σ_past (|d_i| h_i - d_i a_i) + Σ_before (-|d_i| h_i - d_i a_i)) / Σ_{past or before} d_i²

    The numerators are formed without dividing by d_i, so t* is as accurate as its inputs. The segment meets
    the box when Y ≤ X, Y ≤ 1 and X ≥ 0, and no coordinate that stays put (d_i = 0) is outside its slab;
    t* is then the middle of [Y, X] ∩ [0, 1], inside the box.
    """
    reach = np.abs(d)
    reach *= h  # |d_i| h_i
    numerators = np.multiply.outer(_EXIT_ENTRY, reach)
    numerators -= d * a  # exit and entry numerators, (2, 3, ...)
    weight = d * d
    times = numerators / weight  # NaN where d_i = 0: ignored by fmin and fmax, false in comparisons
    bounds = np.empty((2,) + times.shape[2:])  # X and Y, +inf and -inf where no coordinate moves
    np.fmin.reduce(times[0], axis=0, initial=np.inf, out=bounds[0])
    np.fmax.reduce(times[1], axis=0, initial=-np.inf, out=bounds[1])
    active = times == bounds[:, None]  # past the slab at X, before it at Y
    t0 = np.einsum("ui...,ui...->...", active, numerators)
    t0 /= _dot(active[0] | active[1], weight)
    active[0] |= times[0] < t0
    active[1] |= times[1] > t0
    t = np.einsum("ui...,ui...->...", active, numerators)
    t /= _dot(active[0] | active[1], weight)
    first_exit, last_entry = bounds
    line_meets = last_entry <= first_exit
    if line_meets.any():
        # the middle of [Y, X] ∩ [0, 1], or the end of [Y, X] nearest [0, 1] when they do not meet
        first, last = last_entry[line_meets], first_exit[line_meets]
        t[line_meets] = np.clip(0.5 * (np.maximum(first, 0.0) + np.minimum(last, 1.0)), first, last)
    _clip_unit(t)
    meets = line_meets
    meets &= last_entry <= 1.0
    meets &= first_exit >= 0.0
    still = d == 0.0
    if still.any():  # a coordinate that does not move is within its slab for all t, or for none
        meets &= ~(still & (np.abs(a) > h)).any(axis=0)
    return t, meets


#: Signs of the exit and entry numerators: ±|d_i| h_i - d_i a_i.
_EXIT_ENTRY = np.array([1.0, -1.0])


#: Index arrays of the next and the one after, cyclically: (i, _NEXT[i], _AFTER[i]) is (0, 1, 2), (1, 2, 0), (2, 0, 1).
_NEXT = np.array([1, 2, 0])
_AFTER = np.array([2, 0, 1])


class _Overlaps(NamedTuple):
    """Overlaps along the separating-axis candidates (m, ...), NaN for an axis that does not exist, and the unit
    axes (m, 3, ...) along which B leaves A (with ``axes`` only)."""

    overlaps: np.ndarray
    axes: np.ndarray | None


def _deepest(candidates: _Overlaps) -> tuple[np.ndarray, np.ndarray]:
    """The smallest overlap and its axis."""
    best = np.argmin(np.where(np.isnan(candidates.overlaps), np.inf, candidates.overlaps), axis=0)
    depth = np.take_along_axis(candidates.overlaps, best[None], axis=0)[0]
    return depth, np.take_along_axis(candidates.axes, best[None, None], axis=0)[0]


def _segment_box_overlaps(a: np.ndarray, d: np.ndarray, h: np.ndarray, axes: bool) -> _Overlaps:
    """Overlaps of the segment a + t·d (0 ≤ t ≤ 1) and the box |x_i| ≤ h_i (box frame) along the separating
    axes; where the segment meets the box, the smallest is its penetration depth.

    The Minkowski difference of a box and a segment is a zonotope with facet normals e_i (the box's faces) and
    e_i × d (a box edge and the segment). The depth is the smallest overlap along these axes (the separating
    axis theorem, exact for polytopes):

        face i:   min(h_i - min(a_i, b_i), max(a_i, b_i) + h_i),   b = a + d
        e_i × d:  (h_j |d_k| + h_k |d_j| - |a_k d_j - a_j d_k|) / sqrt(d_j² + d_k²),   (i, j, k) cyclic

    Each term is formed from the components, so its rounding is relative to the inputs' size even when d is
    nearly along e_i; an axis with d exactly along e_i does not exist (0/0: NaN). For a segment of length 0
    (a sphere's centre) only the faces remain: the depth is min_i (h_i - |a_i|).
    """
    b = a + d
    out_up = h - np.minimum(a, b)  # moving the segment +e_i by this takes it out
    out_down = np.maximum(a, b)
    out_down += h  # and -e_i by this
    d_next, d_after = d[_NEXT], d[_AFTER]
    extent = h[_NEXT] * np.abs(d_after)
    extent += h[_AFTER] * np.abs(d_next)
    offset = a[_AFTER] * d_next
    offset -= a[_NEXT] * d_after  # (e_i × d) · a, with e_i × d = -d_k e_j + d_j e_k
    norm = np.hypot(d_next, d_after)
    extent -= np.abs(offset)
    extent /= norm
    overlaps = np.concatenate([np.minimum(out_up, out_down), extent])
    if not axes:
        return _Overlaps(overlaps, None)
    directions = np.zeros((6, 3) + overlaps.shape[1:])
    sign = np.where(offset >= 0.0, 1.0, -1.0) / np.where(norm > 0.0, norm, 1.0)
    for i in range(3):
        directions[i, i] = np.where(out_up[i] <= out_down[i], 1.0, -1.0)
        directions[3 + i, _NEXT[i]] = -d_after[i] * sign[i]
        directions[3 + i, _AFTER[i]] = d_next[i] * sign[i]
    return _Overlaps(overlaps, directions)


def _box_segment(box: np.ndarray, h: np.ndarray, ends: np.ndarray, witness: bool):
    """A box and a segment: ``box`` (3, 4, ...) is the centre and the three axes (the columns of R), ``h`` the
    half sizes (3, ...), ``ends`` (3, 2, ...) the segment's start and end.

    In the box frame, a = R^T (start - centre) and d = R^T (end - start). Apart, sd = |x* - clamp(x*, -h, h)|
    at x* = a + t* d (:func:`_segment_box_parameter`); where the segment meets the box, sd = -depth
    (:func:`_segment_box_overlaps`). A segment of length 0 gives the box's signed distance field at the point.
    """
    center, R = box[:, 0], box[:, 1:4]
    local = np.einsum("ij...,iu...->ju...", R, ends - np.stack([center, ends[:, 0]], axis=1))
    a, d = local[:, 0], local[:, 1]
    t, meets = _segment_box_parameter(a, d, h)
    x = t * d
    x += a
    gap = np.minimum(x, h)
    np.maximum(gap, -h, out=gap)
    np.subtract(x, gap, out=gap)
    distance = np.sqrt(_dot(gap, gap))
    if not witness:
        if meets.any():
            overlaps = _segment_box_overlaps(a[:, meets], d[:, meets], _masked(h, meets), False).overlaps
            distance[meets] = -np.fmin.reduce(overlaps, axis=0)
        return distance
    apart = _box_segment_apart(center, R, h, a, d, t)
    if not meets.any():
        return apart
    depth, normal_box = _deepest(_segment_box_overlaps(a, d, h, True))
    # Move the segment out by the depth along the axis: the shapes then touch, and the closest points of that
    # position are the contact; the segment's witness moves back by the depth.
    moved = a + depth * normal_box
    touching = _box_segment_apart(center, R, h, moved, d, _segment_box_parameter(moved, d, h)[0])
    normal = _from_box(R, normal_box)
    inside = _Core(-depth, touching.point_a, touching.point_b - depth * normal, normal)
    return _Core(np.where(meets, inside.distance, apart.distance),
                 *(np.where(meets, when_in, when_apart) for when_in, when_apart in zip(inside[1:], apart[1:])))


def _masked(h: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """h (3, ...) at the batch positions of ``mask``, broadcasting h first."""
    return np.broadcast_to(h, (3,) + mask.shape)[:, mask]


def _box_segment_apart(center, R, h, a, d, t) -> _Core:
    """Witnesses of a segment (box frame a, d) at the parameter t and the box: the segment point and its clamp."""
    x = a + t * d
    on_box = np.clip(x, -h, h)
    gap = x - on_box
    distance = np.sqrt(_dot(gap, gap))
    normal_box = _unit(gap, _E_Z.reshape((3,) + (1,) * (gap.ndim - 1)))
    return _Core(distance, center + _from_box(R, on_box), center + _from_box(R, x), _from_box(R, normal_box))


def _box_box_overlaps(hA: np.ndarray, hB: np.ndarray, C: np.ndarray, t: np.ndarray, axes: bool) -> _Overlaps:
    """Overlaps of two boxes along the separating axes, in A's frame: B's axes are the columns of
    C = R_A^T R_B (3, 3, ...) and its centre is t = R_A^T (c_B - c_A).

    The Minkowski difference of two boxes is a zonotope whose facet normals are A's axes e_i, B's axes C_j and
    the products e_i × C_j. Along each, the overlap is the sum of the projected half extents less the projected
    centre distance; with |C| the entrywise absolute value (orthonormality gives the edge-axis extents):

        A's face i:   hA_i + Σ_j hB_j |C_ij| - |t_i|
        B's face j:   hB_j + Σ_i hA_i |C_ij| - |Σ_i C_ij t_i|
        e_i × C_j:    (hA_i1 |C_i2j| + hA_i2 |C_i1j| + hB_j1 |C_ij2| + hB_j2 |C_ij1| - |C_i1j t_i2 - C_i2j t_i1|)
                      / sqrt(C_i1j² + C_i2j²)              (i, i1, i2) and (j, j1, j2) cyclic

    The smallest overlap is the penetration depth when it is ≥ 0 (the boxes overlap); when it is < 0 the boxes
    are apart and minus it is only a lower bound on their distance. An axis with C_j exactly along e_i does not
    exist (NaN or +inf).
    """
    absC = np.abs(C)
    faces_a = hA + np.einsum("j...,ij...->i...", hB, absC)
    faces_a -= np.abs(t)
    along = np.einsum("ij...,i...->j...", C, t)  # t in B's axes
    faces_b = hB + np.einsum("i...,ij...->j...", hA, absC)
    faces_b -= np.abs(along)
    C_next, C_after = C[_NEXT], C[_AFTER]  # [i, j] -> C[i1, j], C[i2, j]
    extent = hA[_NEXT][:, None] * absC[_AFTER]
    extent += hA[_AFTER][:, None] * absC[_NEXT]
    extent += hB[_NEXT][None] * absC[:, _AFTER]
    extent += hB[_AFTER][None] * absC[:, _NEXT]
    offset = C_next * t[_AFTER][:, None]
    offset -= C_after * t[_NEXT][:, None]
    norm = np.hypot(C_next, C_after)
    extent -= np.abs(offset)
    extent /= norm
    overlaps = np.concatenate([faces_a, faces_b, extent.reshape((9,) + extent.shape[2:])])
    if not axes:
        return _Overlaps(overlaps, None)
    directions = np.zeros((15, 3) + overlaps.shape[1:])
    for i in range(3):
        directions[i, i] = np.where(t[i] >= 0.0, 1.0, -1.0)
        directions[3 + i] = np.where(along[i] >= 0.0, 1.0, -1.0) * C[:, i]
        for j in range(3):
            sign = np.where(offset[i, j] >= 0.0, 1.0, -1.0) / np.where(norm[i, j] > 0.0, norm[i, j], 1.0)
            directions[6 + 3 * i + j, _NEXT[i]] = -C_after[i, j] * sign
            directions[6 + 3 * i + j, _AFTER[i]] = C_next[i, j] * sign
    return _Overlaps(overlaps, directions)


def _edge_coefficients() -> tuple[np.ndarray, np.ndarray]:
    """For the 12 edges of a box (axis i, signs s1, s2): the start -u_i + s1 u_i1 + s2 u_i2 and the direction
    2 u_i as coefficients (12, 3) of the half axes u = h_a R[:, a]."""
    starts, directions = [], []
    for i in range(3):
        for s1 in (1.0, -1.0):
            for s2 in (1.0, -1.0):
                start = np.zeros(3)
                start[i], start[_NEXT[i]], start[_AFTER[i]] = -1.0, s1, s2
                starts.append(start)
                directions.append(2.0 * np.eye(3)[i])
    return np.array(starts), np.array(directions)


_EDGE_STARTS, _EDGE_DIRECTIONS = _edge_coefficients()
_CORNER_SIGNS = np.array([[s0, s1, s2] for s0 in (1.0, -1.0) for s1 in (1.0, -1.0) for s2 in (1.0, -1.0)])


def _box_box_apart(hA, hB, C, t):
    """Distances of the features of two boxes (A's frame: see :func:`_box_box_overlaps`): A's 12 edges to B and
    B's 8 corners to A, shape (20, ...); for boxes that do not overlap their minimum is the boxes' distance.

    A closest pair either has its point of A on an edge of A, or its point of B at a corner of B: if the point
    of A is inside a face of A, the other point lies along that face's normal from it, and sliding both along a
    direction of that face (B's edge at the point, or any direction when it is inside a face of B too) keeps
    their distance until one reaches an edge of A or a corner of B. So

        sd = min( min over A's 12 edges of dist(edge, B),  min over B's 8 corners of dist(corner, A) )

    by the exact segment–box distance (in B's frame) and point–box distance (:func:`_box_point_local`). Also
    returns the edges (starts, directions), their parameters and the corners, for witnesses.
    """
    CT = np.swapaxes(C, 0, 1)  # A's axes in B's frame, as columns
    half_axes_a = CT * hA[None]
    t_in_b = -np.einsum("ij...,j...->i...", CT, t)  # A's centre in B's frame
    starts = t_in_b[:, None] + np.einsum("ea,ca...->ce...", _EDGE_STARTS, half_axes_a)
    directions = np.einsum("ea,ca...->ce...", _EDGE_DIRECTIONS, half_axes_a)
    hB_edges = hB[:, None]
    parameters = _segment_box_parameter(starts, directions, hB_edges)[0]
    x = parameters * directions
    x += starts
    gap = np.minimum(x, hB_edges)
    np.maximum(gap, -hB_edges, out=gap)
    np.subtract(x, gap, out=gap)
    corners = t[:, None] + np.einsum("ea,ca...->ce...", _CORNER_SIGNS, C * hB[None])
    candidates = np.concatenate([np.sqrt(_dot(gap, gap)), _box_point_local(corners, hA[:, None])])
    return candidates, (starts, directions, parameters, corners)


def _box_box(box_a: np.ndarray, hA: np.ndarray, box_b: np.ndarray, hB: np.ndarray, witness: bool):
    """Two boxes, each given by its centre and three axes (3, 4, ...) and its half sizes (3, ...).

    In A's frame, C = R_A^T R_B and t = R_A^T (c_B - c_A). Where the smallest separating-axis overlap is ≥ 0 the
    boxes overlap and sd = -overlap (:func:`_box_box_overlaps`); elsewhere they are apart and sd is the feature
    distance of :func:`_box_box_apart`.
    """
    cA, RA = box_a[:, 0], box_a[:, 1:4]
    C = np.einsum("ci...,cj...->ij...", RA, box_b[:, 1:4])
    t = _to_box(RA, box_b[:, 0] - cA)
    if not witness:
        depth = np.fmin.reduce(_box_box_overlaps(hA, hB, C, t, False).overlaps, axis=0)
        distance = np.negative(depth)
        apart = depth < 0.0
        if apart.any():
            candidates, _ = _box_box_apart(_masked(hA, apart), _masked(hB, apart), C[:, :, apart], t[:, apart])
            distance[apart] = candidates.min(axis=0)
        return distance
    depth, axis = _deepest(_box_box_overlaps(hA, hB, C, t, True))
    apart = depth < 0.0
    point_a_apart, point_b_apart, distance_apart = _box_box_contact(hA, hB, C, t)
    normal_apart = _unit(point_b_apart - point_a_apart, _E_Z.reshape((3,) + (1,) * distance_apart.ndim))
    # Overlapping: move B out along the axis by the depth; the closest points of that touching position are the
    # contact, and B's witness moves back by the depth.
    shift = np.maximum(depth, 0.0) * axis
    contact, _, _ = _box_box_contact(hA, hB, C, t + shift)
    point_a = np.where(apart, point_a_apart, contact)
    point_b = np.where(apart, point_b_apart, contact - shift)
    normal = np.where(apart, normal_apart, axis)
    distance = np.where(apart, distance_apart, -depth)
    return _Core(distance, cA + _from_box(RA, point_a), cA + _from_box(RA, point_b), _from_box(RA, normal))


def _box_box_contact(hA, hB, C, t):
    """The closest points (A's frame) of two boxes that do not overlap, from the feature of
    :func:`_box_box_apart` that attains their distance, and that distance."""
    candidates, (starts, directions, parameters, corners) = _box_box_apart(hA, hB, C, t)
    best = np.argmin(candidates, axis=0)
    edge = np.minimum(best, 11)[None, None]
    corner = np.maximum(best - 12, 0)[None, None]
    # an edge of A (B's frame): its point x and x clamped to B, both taken to A's frame (x_A = t + C x_B)
    x = (np.take_along_axis(starts, edge, axis=1)[:, 0]
         + np.take_along_axis(parameters[None], edge, axis=1)[:, 0] * np.take_along_axis(directions, edge, axis=1)[:, 0])
    from_edge_a = t + _from_box(C, x)
    from_edge_b = t + _from_box(C, np.clip(x, -hB, hB))
    # a corner of B (A's frame) and its clamp to A
    at_corner = np.take_along_axis(corners, corner, axis=1)[:, 0]
    on_edge = best < 12
    point_a = np.where(on_edge, from_edge_a, np.clip(at_corner, -hA, hA))
    point_b = np.where(on_edge, from_edge_b, at_corner)
    return point_a, point_b, np.take_along_axis(candidates, best[None], axis=0)[0]


# --- public kernels: (..., 3) in, Separation out ------------------------------------------------------------------


class _Batch(NamedTuple):
    """Public inputs broadcast to one batch shape (at least one axis), component-first."""

    shape: tuple[int, ...]
    points: list[np.ndarray]
    rotations: list[np.ndarray]
    scalars: list[np.ndarray]


def _batch(points=(), rotations=(), scalars=()) -> _Batch:
    """Points (..., 3) as (3, N...), rotations (..., 3, 3) as (3, 3, N...) and scalars (...) as (N...), all
    broadcast to their common batch shape, with one axis of length 1 added when that shape is ()."""
    points = [np.asarray(p, dtype=float) for p in points]
    rotations = [np.asarray(R, dtype=float) for R in rotations]
    scalars = [np.asarray(x, dtype=float) for x in scalars]
    shape = np.broadcast_shapes(*(p.shape[:-1] for p in points), *(R.shape[:-2] for R in rotations),
                                *(x.shape for x in scalars))
    work = shape or (1,)
    return _Batch(shape,
                  [np.moveaxis(np.broadcast_to(p, work + (3,)), -1, 0) for p in points],
                  [np.moveaxis(np.broadcast_to(R, work + (3, 3)), (-2, -1), (0, 1)) for R in rotations],
                  [np.broadcast_to(x, work) for x in scalars])


def _separation(core: _Core, shape: tuple[int, ...]) -> Separation:
    """The component-first core result as a Separation of batch shape ``shape``."""
    return Separation(np.broadcast_to(core.distance, core.distance.shape).reshape(shape).copy(),
                      *(np.moveaxis(v, 0, -1).reshape(shape + (3,)).copy()
                        for v in (core.point_a, core.point_b, core.normal)))


def sphere_sphere(center_a: ArrayLike, radius_a: ArrayLike, center_b: ArrayLike, radius_b: ArrayLike) -> Separation:
    """Signed distance of two spheres: sd = |c_b - c_a| - r_a - r_b (a capsule of length 0 and a sphere, in
    :func:`capsule_sphere`).

    >>> sphere_sphere([0, 0, 0], 1.0, [3, 4, 0], 0.5).distance.item()
    3.5
    """
    return capsule_sphere(center_a, center_a, radius_a, center_b, radius_b)


def capsule_sphere(start_a: ArrayLike, end_a: ArrayLike, radius_a: ArrayLike, center_b: ArrayLike,
                   radius_b: ArrayLike) -> Separation:
    """Signed distance of a capsule (segment ``start_a``–``end_a``, radius ``radius_a``) and a sphere: the
    distance of the centre to its clamped projection on the segment, s* = clamp(((c - start) · d) / (d · d), 0,
    1) (:func:`_segment_point`), less both radii.

    >>> capsule_sphere([0, 0, 0], [2, 0, 0], 0.5, [1, 2, 0], 0.25).distance.item()
    1.25
    """
    batch = _batch([start_a, end_a, center_b], [], [radius_a, radius_b])
    with _quiet():
        core = _segment_point(np.stack(batch.points, axis=1), True)
    return _separation(_swept(core, *batch.scalars), batch.shape)


def capsule_capsule(start_a: ArrayLike, end_a: ArrayLike, radius_a: ArrayLike, start_b: ArrayLike,
                    end_b: ArrayLike, radius_b: ArrayLike) -> Separation:
    """Signed distance of two capsules: the segments' distance (:func:`_segment_segment`) less both radii.

    Crossed segments:

    >>> capsule_capsule([-1, 0, 0], [1, 0, 0], 0.1, [0, -1, 0.5], [0, 1, 0.5], 0.2).distance.item()
    0.2
    """
    batch = _batch([start_a, end_a, start_b, end_b], [], [radius_a, radius_b])
    with _quiet():
        core = _segment_segment(np.stack(batch.points, axis=1), True)
    return _separation(_swept(core, *batch.scalars), batch.shape)


def box_sphere(center_a: ArrayLike, rotation_a: ArrayLike, half_size_a: ArrayLike, center_b: ArrayLike,
               radius_b: ArrayLike) -> Separation:
    """Signed distance of a box (centre, ``world_R_box``, half edge lengths) and a sphere: the box's signed
    distance field at the centre (:func:`_box_point`), less the radius.

    A sphere of radius 0.5 whose centre is 0.2 inside a face:

    >>> box_sphere([0, 0, 0], np.eye(3), [1, 1, 1], [0.8, 0, 0], 0.5).distance.item()
    -0.7
    """
    batch = _batch([center_a, half_size_a, center_b], [rotation_a], [radius_b])
    (center, half_size, point), (rotation,), (radius,) = batch.points, batch.rotations, batch.scalars
    with _quiet():
        core = _box_point(_box_rows(center, rotation), half_size, point, True)
    return _separation(_swept(core, 0.0, radius), batch.shape)


def box_capsule(center_a: ArrayLike, rotation_a: ArrayLike, half_size_a: ArrayLike, start_b: ArrayLike,
                end_b: ArrayLike, radius_b: ArrayLike) -> Separation:
    """Signed distance of a box and a capsule: the segment–box distance apart, or minus its penetration depth
    (:func:`_box_segment`), less the radius.

    >>> box_capsule([0, 0, 0], np.eye(3), [1, 1, 1], [2, 2, -5], [2, 2, 5], 0.5).distance.item()  # doctest: +ELLIPSIS
    0.914213562373...
    """
    batch = _batch([center_a, half_size_a, start_b, end_b], [rotation_a], [radius_b])
    (center, half_size, start, end), (rotation,), (radius,) = batch.points, batch.rotations, batch.scalars
    with _quiet():
        core = _box_segment(_box_rows(center, rotation), half_size, np.stack([start, end], axis=1), True)
    return _separation(_swept(core, 0.0, radius), batch.shape)


def box_box(center_a: ArrayLike, rotation_a: ArrayLike, half_size_a: ArrayLike, center_b: ArrayLike,
            rotation_b: ArrayLike, half_size_b: ArrayLike) -> Separation:
    """Signed distance of two boxes: the separating-axis depth where they overlap, the feature distance where
    they are apart (:func:`_box_box`).

    >>> box_box([0, 0, 0], np.eye(3), [1, 1, 1], [3, 0, 0], np.eye(3), [0.5, 0.5, 0.5]).distance.item()
    1.5
    """
    batch = _batch([center_a, half_size_a, center_b, half_size_b], [rotation_a, rotation_b])
    (ca, ha, cb, hb), (Ra, Rb) = batch.points, batch.rotations
    with _quiet():
        core = _box_box(_box_rows(ca, Ra), ha, _box_rows(cb, Rb), hb, True)
    return _separation(core, batch.shape)


def _box_rows(center: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """A box's centre (3, ...) and rotation (3, 3, ...) as the rows the kernels take: (3, 4, ...)."""
    return np.concatenate([center[:, None], rotation], axis=1)


def _quiet():
    """The floating-point state the kernels run in: 0/0 and x/0 are expected (an axis that does not exist, a
    coordinate that does not move) and give the NaN or infinity the kernels handle."""
    return np.errstate(divide="ignore", invalid="ignore")


def separation(shape_a: Shape, shape_b: Shape) -> Separation:
    """Signed distance and witnesses of two shape records given in one frame; either order of kinds.

    >>> separation(Sphere([0, 0, 0], 1.0), Capsule([3, -1, 0], [3, 1, 0], 0.5)).distance.item()
    1.5
    """
    kinds = (type(shape_a), type(shape_b))
    order = (Box, Capsule, Sphere)
    if order.index(kinds[0]) > order.index(kinds[1]):
        flipped = separation(shape_b, shape_a)
        return Separation(flipped.distance, flipped.point_b, flipped.point_a, -flipped.normal)
    a, b = shape_a, shape_b
    if isinstance(a, Box):
        if isinstance(b, Box):
            return box_box(a.center, a.rotation, a.half_size, b.center, b.rotation, b.half_size)
        if isinstance(b, Capsule):
            return box_capsule(a.center, a.rotation, a.half_size, b.start, b.end, b.radius)
        return box_sphere(a.center, a.rotation, a.half_size, b.center, b.radius)
    if isinstance(a, Capsule):
        if isinstance(b, Capsule):
            return capsule_capsule(a.start, a.end, a.radius, b.start, b.end, b.radius)
        return capsule_sphere(a.start, a.end, a.radius, b.center, b.radius)
    return sphere_sphere(a.center, a.radius, b.center, b.radius)
