"""Signed distances between capsules, spheres and boxes, against independent references.

The references (``tests/oracles/collision.py``) share no code with the service:

* An exact enumeration of active sets (apart) with Qhull facets of the Minkowski difference (overlap): for
  10,000 random pairs of each kind at sizes from 0.1 to 10 m, apart, touching and overlapping, and for
  millimetre-sized pairs with a box.
* Bullet (pybullet's ``getClosestPoints``, boxes without their collision margin) for the same 10,000 pairs of
  each kind, in the regimes where it holds (``BULLET_HOLDS``, within 2e-12 there): everywhere for spheres and
  capsules and box–sphere, apart and at touch for box–capsule, apart for box–box. Its penetration depths with
  boxes, its box–box contacts at touch and its millimetre-sized boxes miss by up to 1e-3, 0.2 and 1e-3 (shown
  below), so those regimes rest on the exact reference.
* Exact rational arithmetic for nearly parallel segments.

Every comparison asserts 1e-9 m.
"""

from __future__ import annotations

import doctest
import math
from typing import NamedTuple

import numpy as np
import pytest

from service.kinematics.collision import (
    Box,
    Capsule,
    Sphere,
    box_box,
    box_capsule,
    box_sphere,
    capsule_capsule,
    capsule_sphere,
    separation,
    sphere_sphere,
)
from service.kinematics.collision import _distances
from tests.oracles.collision import Bullet, kind_of, segment_distance_exact, signed_distance, signed_distances
from tests.oracles.rotations import matrix_of_quaternion

TOLERANCE = 1e-9
KINDS = [("sphere", "sphere"), ("capsule", "sphere"), ("capsule", "capsule"), ("box", "sphere"),
         ("box", "capsule"), ("box", "box")]
PAIRS_PER_KIND = 10_000


@pytest.fixture(scope="module")
def bullet():
    client = Bullet()
    yield client
    client.close()


# --- random shapes ------------------------------------------------------------------------------------------


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    """A uniformly random rotation (from a random unit quaternion)."""
    q = rng.normal(size=4)
    return matrix_of_quaternion(*(q / np.linalg.norm(q)))


class LightBox(NamedTuple):
    """A box with the service record's fields, without its validation (fast to make by the ten thousand)."""

    center: np.ndarray
    half_size: np.ndarray
    rotation: np.ndarray


class LightCapsule(NamedTuple):
    start: np.ndarray
    end: np.ndarray
    radius: float


class LightSphere(NamedTuple):
    center: np.ndarray
    radius: float


def random_shape(kind: str, rng: np.random.Generator, scale: float, center: np.ndarray, half_size=None):
    if kind == "sphere":
        return LightSphere(center, rng.uniform(0.01, 0.5) * scale)
    if kind == "capsule":
        length = 0.0 if rng.random() < 0.05 else rng.uniform(0.0, 1.5) * scale
        direction = rng.normal(size=3)
        half = 0.5 * length * direction / np.linalg.norm(direction)
        return LightCapsule(center - half, center + half, rng.uniform(0.01, 0.5) * scale)
    if half_size is None:
        half_size = rng.uniform(0.025, 1.0, 3) * scale
    return LightBox(center, half_size, random_rotation(rng))


def outward_normal_at_surface(box: LightBox, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A random point of the box's surface on a face, an edge or at a corner, and a unit outward normal there
    (any direction of the normal cone), both in the world frame."""
    feature = rng.integers(3)  # how many coordinates sit on a bound: 1 face, 2 edge, 3 corner
    axes = rng.permutation(3)[: feature + 1]
    signs = rng.choice([-1.0, 1.0], size=3)
    local = rng.uniform(-1.0, 1.0, 3) * box.half_size
    normal_local = np.zeros(3)
    weights = rng.uniform(0.05, 1.0, axes.size)
    for axis, weight in zip(axes, weights):
        local[axis] = signs[axis] * box.half_size[axis]
        normal_local[axis] = signs[axis] * weight
    normal_local /= np.linalg.norm(normal_local)
    return box.center + box.rotation @ local, box.rotation @ normal_local


def touching_pair(kind_a: str, kind_b: str, rng: np.random.Generator, scale: float, half_sizes=(None, None)):
    """Two shapes that touch, by construction from a contact point and a normal that separates them.

    For a contact point F on A's core with a unit normal n in the normal cone there, A lies on one side of the
    plane through F + r_A n perpendicular to n; B is placed on the other side, its core's support point in the
    direction -n at F + (r_A + r_B) n. Their signed distance is 0.
    """
    center = rng.normal(size=3) * scale
    a = random_shape(kind_a, rng, scale, center, half_sizes[0])
    if isinstance(a, LightBox):
        contact, normal = outward_normal_at_surface(a, rng)
        radius_a = 0.0
    else:
        core = (a.start, a.end) if isinstance(a, LightCapsule) else (a.center, a.center)
        t = rng.choice([0.0, 1.0, rng.uniform()])
        on_core = core[0] + t * (core[1] - core[0])
        axis = core[1] - core[0]
        normal = rng.normal(size=3)
        if np.linalg.norm(axis) > 0.0:
            along = normal @ axis / (axis @ axis)
            if 0.0 < t < 1.0 or (t == 0.0 and along > 0.0) or (t == 1.0 and along < 0.0):
                normal -= along * axis  # inside the segment, or an end's cap facing inwards: perpendicular
        normal /= np.linalg.norm(normal)
        contact, radius_a = on_core, a.radius
    b = random_shape(kind_b, rng, scale, np.zeros(3), half_sizes[1])
    touch = contact + radius_a * normal
    if isinstance(b, LightBox):
        corner = b.rotation @ (np.sign(b.rotation.T @ normal) * b.half_size)  # B's support in -n, from its centre
        b = b._replace(center=touch + corner)
    elif isinstance(b, LightSphere):
        b = b._replace(center=touch + b.radius * normal)
    else:
        # a segment in the plane through touch + r_B n perpendicular to n, crossing that point, or ending there
        direction = np.cross(normal, rng.normal(size=3))
        direction *= np.linalg.norm(b.end - b.start) / np.linalg.norm(direction)
        if rng.random() < 0.3:  # ending at that point, leaving the plane away from A
            start = touch + b.radius * normal
            b = b._replace(start=start, end=start + direction + rng.uniform() * np.linalg.norm(direction) * normal)
        else:
            t = rng.uniform()
            point = touch + b.radius * normal
            b = b._replace(start=point - t * direction, end=point + (1.0 - t) * direction)
    return a, b


def random_pairs(kind_a: str, kind_b: str, count: int, seed: int, scales: tuple[float, float]):
    """Pairs apart (near and far), touching and overlapping (shallow and deep), sizes log-uniform in ``scales``.

    Boxes take their half sizes from a pool of 500 random ones (with the pair's size), so that Bullet makes each
    box shape once; their poses are all different."""
    rng = np.random.default_rng(seed)
    pool_scales = np.exp(rng.uniform(*np.log(scales), 500))
    pool = rng.uniform(0.025, 1.0, (500, 3)) * pool_scales[:, None]
    shapes_a, shapes_b, touching = [], [], []
    for k in range(count):
        picks = rng.integers(500, size=2)
        scale = pool_scales[picks[0]] if "box" in (kind_a, kind_b) else math.exp(rng.uniform(*np.log(scales)))
        half_sizes = (pool[picks[0]] if kind_a == "box" else None,
                      pool[picks[0] if kind_a != "box" else picks[1]] if kind_b == "box" else None)
        mode = k % 5
        if mode == 4:
            a, b = touching_pair(kind_a, kind_b, rng, scale, half_sizes)
        else:
            center = rng.normal(size=3) * scale
            spread = {0: 0.3, 1: 1.0, 2: 1.0, 3: 8.0}[mode]  # deep, near, near, far
            a = random_shape(kind_a, rng, scale, center, half_sizes[0])
            b = random_shape(kind_b, rng, scale, center + rng.normal(size=3) * spread * scale, half_sizes[1])
        shapes_a.append(a)
        shapes_b.append(b)
        touching.append(mode == 4)
    return shapes_a, shapes_b, np.array(touching)


def service_distances(shapes_a, shapes_b) -> np.ndarray:
    """The service's vectorised kernels on all pairs at once (one call per kind)."""

    def fields(shapes, *names):
        return [np.array([getattr(shape, name) for shape in shapes], dtype=float) for name in names]

    a, b = shapes_a[0], shapes_b[0]
    if isinstance(a, LightBox):
        box = fields(shapes_a, "center", "rotation", "half_size")
        if isinstance(b, LightBox):
            return box_box(*box, *fields(shapes_b, "center", "rotation", "half_size")).distance
        if isinstance(b, LightCapsule):
            return box_capsule(*box, *fields(shapes_b, "start", "end", "radius")).distance
        return box_sphere(*box, *fields(shapes_b, "center", "radius")).distance
    if isinstance(a, LightCapsule):
        capsule = fields(shapes_a, "start", "end", "radius")
        if isinstance(b, LightCapsule):
            return capsule_capsule(*capsule, *fields(shapes_b, "start", "end", "radius")).distance
        return capsule_sphere(*capsule, *fields(shapes_b, "center", "radius")).distance
    return sphere_sphere(*fields(shapes_a, "center", "radius"), *fields(shapes_b, "center", "radius")).distance


def record(shape):
    """The service's record of a light shape."""
    if isinstance(shape, LightBox):
        return Box(shape.center, 2.0 * shape.half_size, shape.rotation)
    if isinstance(shape, LightCapsule):
        return Capsule(shape.start, shape.end, shape.radius)
    return Sphere(shape.center, shape.radius)


@pytest.fixture(scope="module")
def measured(bullet):
    """For each kind: 10,000 pairs at 0.1 to 10 m, the service's distances and both references'."""
    results = {}
    for seed, (kind_a, kind_b) in enumerate(KINDS):
        shapes_a, shapes_b, touching = random_pairs(kind_a, kind_b, PAIRS_PER_KIND, seed, (0.1, 10.0))
        results[kind_a, kind_b] = dict(
            ours=service_distances(shapes_a, shapes_b),
            bullet=np.array([bullet.distance(a, b) for a, b in zip(shapes_a, shapes_b)]),
            exact=signed_distances(shapes_a, shapes_b),
            touching=touching)
    return results


def _regimes(reference: np.ndarray, touching: np.ndarray) -> dict[str, np.ndarray]:
    return {"apart": ~touching & (reference > 0.0), "touching": touching,
            "overlapping": ~touching & (reference < 0.0)}


#: Where Bullet holds 1e-9 on these pairs (measured: within 2e-12 there). Elsewhere its EPA penetration depths
#: (box–capsule and box–box overlap) and its box–box contacts at touch miss by up to 1e-3 and 0.2 (see
#: test_bullet_misses_boxes_in_overlap_and_box_pairs_at_touch), and the exact reference holds alone.
BULLET_HOLDS = {("sphere", "sphere"): {"apart", "touching", "overlapping"},
                ("capsule", "sphere"): {"apart", "touching", "overlapping"},
                ("capsule", "capsule"): {"apart", "touching", "overlapping"},
                ("box", "sphere"): {"apart", "touching", "overlapping"},
                ("box", "capsule"): {"apart", "touching"},
                ("box", "box"): {"apart"}}


@pytest.mark.parametrize("kind", KINDS, ids=["-".join(kind) for kind in KINDS])
def test_random_pairs_agree_with_the_exact_reference_in_every_regime(measured, kind):
    result = measured[kind]
    for regime, chosen in _regimes(result["exact"], result["touching"]).items():
        assert chosen.sum() >= 1000, f"{regime}: only {chosen.sum()} pairs"  # every regime is exercised
        errors = np.abs(result["ours"][chosen] - result["exact"][chosen])
        assert errors.max() <= TOLERANCE, (regime, errors.max())
    assert np.abs(result["ours"][result["touching"]]).max() <= TOLERANCE


@pytest.mark.parametrize("kind", KINDS, ids=["-".join(kind) for kind in KINDS])
def test_random_pairs_agree_with_bullet_where_it_holds(measured, kind):
    result = measured[kind]
    for regime, chosen in _regimes(result["exact"], result["touching"]).items():
        if regime in BULLET_HOLDS[kind]:
            errors = np.abs(result["ours"][chosen] - result["bullet"][chosen])
            assert errors.max() <= TOLERANCE, (regime, errors.max())


@pytest.mark.parametrize("kind, regime", [(("box", "capsule"), "overlapping"), (("box", "box"), "touching"),
                                          (("box", "box"), "overlapping")])
def test_bullet_misses_boxes_in_overlap_and_box_pairs_at_touch(measured, kind, regime):
    """Why those regimes rest on the exact reference alone: there Bullet is off by far more than 1e-9, while the
    exact reference and the service agree to rounding on the same pairs."""
    result = measured[kind]
    chosen = _regimes(result["exact"], result["touching"])[regime]
    assert np.abs(result["bullet"][chosen] - result["exact"][chosen]).max() > 1e-6
    assert np.abs(result["ours"][chosen] - result["exact"][chosen]).max() <= 1e-12


def test_the_random_pairs_reach_deep_overlap_and_far_apart(measured):
    for kind, result in measured.items():
        assert result["exact"].min() < -0.5, kind  # well inside, at the smallest of the sizes
        assert result["exact"].max() > 20.0, kind


@pytest.mark.parametrize("kind", [kind for kind in KINDS if "box" in kind], ids=lambda kind: "-".join(kind))
def test_millimetre_pairs_with_a_box_agree_with_the_exact_reference(kind):
    shapes_a, shapes_b, touching = random_pairs(*kind, 2000, 100 + KINDS.index(kind), (1e-3, 1e-2))
    ours = service_distances(shapes_a, shapes_b)
    exact = signed_distances(shapes_a, shapes_b)
    assert np.abs(ours - exact).max() <= 1e-12
    assert np.abs(ours[touching]).max() <= 1e-12


def test_bullet_misses_by_about_1e_4_at_millimetre_sizes_with_boxes(bullet):
    """Why millimetre pairs with a box are checked against the exact reference only: there Bullet's absolute
    GJK/EPA tolerances show, while the exact reference and the service agree to rounding."""
    shapes_a, shapes_b, _ = random_pairs("box", "capsule", 300, 7, (1e-3, 2e-3))
    ours = service_distances(shapes_a, shapes_b)
    exact = signed_distances(shapes_a, shapes_b)
    from_bullet = np.array([bullet.distance(a, b) for a, b in zip(shapes_a, shapes_b)])
    assert np.abs(ours - exact).max() <= 1e-12
    assert np.abs(from_bullet - exact).max() > 1e-6


def test_bullet_rounds_box_corners_by_its_default_margin():
    """With its default collision margin Bullet measures a box with rounded edges: off by (√3 - 1)·0.001 at a
    corner, which is why the oracle sets the margin to 0."""
    box = Box([0, 0, 0], [1.0, 0.8, 0.6])
    sphere = Sphere([0.7, 0.6, 0.5], 0.1)  # 0.2 beyond the corner (0.5, 0.4, 0.3) along each axis
    exact = math.sqrt(3 * 0.2**2) - 0.1
    assert separation(box, sphere).distance == pytest.approx(exact, abs=1e-15)
    default = Bullet(box_margin=None)
    try:
        assert default.distance(box, sphere) - exact == pytest.approx((math.sqrt(3) - 1) * 1e-3, rel=1e-3)
    finally:
        default.close()


# --- degenerate and hand-computed cases ---------------------------------------------------------------------


def _capsules(p0, p1, q0, q1, ra=0.1, rb=0.2):
    return Capsule(p0, p1, ra), Capsule(q0, q1, rb)


DEGENERATE_CAPSULES = {
    "both of length 0": _capsules([0, 0, 0], [0, 0, 0], [1, 2, 2], [1, 2, 2]),
    "one of length 0, beyond an end": _capsules([0, 0, 0], [1, 0, 0], [2, 1, 0], [2, 1, 0]),
    "one of length 0, beside the middle": _capsules([0, 0, 0], [1, 0, 0], [0.3, 1, 0], [0.3, 1, 0]),
    "parallel, side by side": _capsules([0, 0, 0], [2, 0, 0], [0.5, 1, 0], [3, 1, 0]),
    "parallel, end to end": _capsules([0, 0, 0], [1, 0, 0], [2, 0.5, 0], [3, 0.5, 0]),
    "antiparallel, side by side": _capsules([0, 0, 0], [2, 0, 0], [3, 1, 0], [0.5, 1, 0]),
    "collinear, overlapping": _capsules([0, 0, 0], [2, 0, 0], [1, 0, 0], [3, 0, 0]),
    "collinear, apart": _capsules([0, 0, 0], [1, 0, 0], [1.5, 0, 0], [3, 0, 0]),
    "one inside the other": _capsules([0, 0, 0], [3, 0, 0], [1, 0, 0], [2, 0, 0], 0.5, 0.1),
    "crossing": _capsules([-1, 0, 0], [1, 0, 0], [0, -1, 0], [0, 1, 0]),
    "touching at the ends": _capsules([0, 0, 0], [1, 0, 0], [1.3, 0, 0], [2, 0, 0]),
    "parallel, tilted in space": _capsules([0.1, 0.2, 0.3], [1.1, 2.2, 3.3], [0.4, 0.2, 0.3], [2.4, 4.2, 6.3]),
}


@pytest.mark.parametrize("name", list(DEGENERATE_CAPSULES))
def test_degenerate_capsules(name, bullet):
    a, b = DEGENERATE_CAPSULES[name]
    exact = segment_distance_exact(a.start, a.end, b.start, b.end) - a.radius - b.radius
    ours = separation(a, b)
    assert ours.distance == pytest.approx(exact, abs=1e-15)
    assert bullet.distance(a, b) == pytest.approx(exact, abs=TOLERANCE)
    assert np.linalg.norm(ours.normal) == pytest.approx(1.0, abs=1e-15)


def test_hand_computed_capsule_distances():
    """One inside the other: the cores meet, so the depth is the sum of the radii; crossing at height 0.5."""
    assert separation(*DEGENERATE_CAPSULES["one inside the other"]).distance == pytest.approx(-0.6, abs=1e-15)
    assert separation(*DEGENERATE_CAPSULES["crossing"]).distance == pytest.approx(-0.3, abs=1e-15)
    assert separation(*DEGENERATE_CAPSULES["collinear, apart"]).distance == pytest.approx(0.2, abs=1e-15)
    assert separation(*DEGENERATE_CAPSULES["parallel, side by side"]).distance == pytest.approx(0.7, abs=1e-15)


@pytest.mark.parametrize("exponent", range(-16, -1))
def test_nearly_parallel_segments_against_exact_arithmetic(exponent):
    """Segments crossing (or passing within 1e-9 or 1e-3 of each other) at an angle of 10^exponent radians:
    where the Gram determinant a e - b² would lose all its digits."""
    rng = np.random.default_rng(exponent + 100)
    worst = 0.0
    for _ in range(60):
        length = rng.uniform(0.1, 2.0)
        u = rng.normal(size=3)
        u /= np.linalg.norm(u)
        w = np.cross(u, rng.normal(size=3))
        w /= np.linalg.norm(w)
        angle = 10.0**exponent * rng.uniform(1.0, 10.0)
        v = math.cos(angle) * u + math.sin(angle) * w
        middle = rng.normal(size=3)
        gap = rng.choice([0.0, 1e-9, 1e-3]) * np.cross(u, w)
        start = middle + rng.uniform(-1.5, 1.5) * length * v - 0.5 * length * v + gap
        p0, p1, q0, q1 = middle - 0.5 * length * u, middle + 0.5 * length * u, start, start + length * v
        exact = segment_distance_exact(p0, p1, q0, q1)
        worst = max(worst, abs(capsule_capsule(p0, p1, 0.0, q0, q1, 0.0).distance - exact))
    assert worst <= 1e-14


BOX = Box([0.0, 0.0, 0.0], [2.0, 4.0, 6.0])  # half sizes 1, 2, 3


@pytest.mark.parametrize("shape, expected", [
    (Sphere([3, 0, 0], 0.5), 1.5),  # beyond a face
    (Sphere([2, 3, 0], 0.5), math.sqrt(2) - 0.5),  # beyond an edge
    (Sphere([2, 3, 4], 0.0), math.sqrt(3)),  # beyond a corner, radius 0
    (Sphere([0.5, 0, 0], 0.25), -0.75),  # centre inside, nearest the x faces
    (Sphere([0, 0, 0], 1.0), -2.0),  # at the centre
    (Capsule([3, -5, 1], [3, 5, 1], 0.5), 1.5),  # parallel to a face, beyond it
    (Capsule([0.5, -5, 0], [0.5, 5, 0], 0.25), -0.75),  # through the box along y
    (Capsule([0, 0, -1], [0, 0, 1], 0.0), -1.0),  # inside, along z: out through an x face
    (Capsule([2, 3, -1], [2, 3, 1], 0.0), math.sqrt(2)),  # parallel to an edge
    (Capsule([-3, 2.5, 0], [3, 2.5, 0], 0.0), 0.5),  # parallel to a face, across its whole width
    (Box([3, 0, 0], [1, 1, 1]), 1.5),  # face to face
    (Box([2, 3, 4], [2, 2, 2]), 0.0),  # corner on corner
    (Box([0, 0, 0], [2, 4, 6]), -2.0),  # the same box: out through the x faces
    (Box([0, 0, 0.5], [0.5, 0.5, 0.5]), -1.25),  # small inside, nearest a x or y face
])
def test_hand_computed_box_distances(shape, expected, bullet):
    assert separation(BOX, shape).distance == pytest.approx(expected, abs=1e-15)
    assert separation(shape, BOX).distance == pytest.approx(expected, abs=1e-15)
    assert signed_distance(BOX, shape) == pytest.approx(expected, abs=1e-12)
    regime = "apart" if expected > 0 else "touching" if expected == 0 else "overlapping"
    if regime in BULLET_HOLDS["box", kind_of(shape)] and getattr(shape, "radius", 1.0) > 0.0:  # Bullet needs r > 0
        assert bullet.distance(BOX, shape) == pytest.approx(expected, abs=TOLERANCE)


def test_boxes_rotated_by_tiny_angles_keep_their_depth():
    """Edges nearly parallel (1e-9 rad): the edge-cross axes are nearly degenerate, and the depth stays exact."""
    angle = 1e-9
    c, s = math.cos(angle), math.sin(angle)
    turned = Box([1.0, 0.2, 0.1], [1.0, 1.0, 1.0], [[c, -s, 0], [s, c, 0], [0, 0, 1]])
    exact = signed_distance(BOX, turned)
    assert separation(BOX, turned).distance == pytest.approx(exact, abs=1e-12)
    assert exact == pytest.approx(-0.5, abs=1e-8)


def test_a_box_rotation_written_with_few_decimals_becomes_the_nearest_rotation():
    """Rotations are accepted within 1e-6 of orthonormal; a box is measured as a box, so its record holds the
    nearest rotation (and one orthonormal to rounding exactly as given)."""
    c, s = math.cos(0.3), math.sin(0.3)
    exact = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    assert np.array_equal(Box([0, 0, 0], [1, 1, 1], exact).rotation, exact)
    written = np.round(exact, 7)
    projected = Box([0, 0, 0], [1, 1, 1], written).rotation
    assert np.abs(projected.T @ projected - np.eye(3)).max() < 1e-15
    assert np.abs(projected - exact).max() < 1e-7


# --- witnesses, symmetry, batches ---------------------------------------------------------------------------


@pytest.mark.parametrize("kind", KINDS, ids=["-".join(kind) for kind in KINDS])
def test_witness_points_lie_on_the_surfaces_and_span_the_distance(kind):
    shapes_a, shapes_b, _ = random_pairs(*kind, 300, 50 + KINDS.index(kind), (0.1, 10.0))
    for a, b in zip(shapes_a, shapes_b):
        result = separation(record(a), record(b))
        assert np.linalg.norm(result.normal) == pytest.approx(1.0, abs=1e-12)
        gap = result.point_b - result.point_a
        assert np.linalg.norm(gap - result.distance * result.normal) <= 1e-9
        # each point is on its shape's surface: a sphere of radius 0 there is at signed distance 0
        assert abs(signed_distance(Sphere(result.point_a, 0.0), a)) <= 1e-9
        assert abs(signed_distance(Sphere(result.point_b, 0.0), b)) <= 1e-9


def test_either_order_gives_the_same_distance_and_the_opposite_normal():
    rng = np.random.default_rng(3)
    for kind_a, kind_b in KINDS:
        a = record(random_shape(kind_a, rng, 1.0, rng.normal(size=3)))
        b = record(random_shape(kind_b, rng, 1.0, rng.normal(size=3)))
        forward, backward = separation(a, b), separation(b, a)
        assert forward.distance == pytest.approx(backward.distance, abs=1e-15)
        np.testing.assert_allclose(forward.normal, -backward.normal, atol=1e-12)
        np.testing.assert_allclose(forward.point_a, backward.point_b, atol=1e-12)


def test_kernels_broadcast_over_any_batch_shape():
    rng = np.random.default_rng(5)
    starts, ends = rng.normal(size=(2, 4, 3)), rng.normal(size=(2, 4, 3))
    batch = capsule_capsule(starts[:, :, None], ends[:, :, None], 0.1, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.2)
    assert batch.distance.shape == (2, 4, 1) and batch.point_a.shape == (2, 4, 1, 3)
    one = capsule_capsule(starts[1, 2], ends[1, 2], 0.1, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.2)
    assert one.distance.shape == () and one.normal.shape == (3,)
    assert batch.distance[1, 2, 0] == one.distance
    boxes = box_capsule(np.zeros((5, 3)), np.eye(3), [0.5, 0.5, 0.5], [2.0, 0.0, 0.0], [3.0, 0.0, 0.0], 0.25)
    np.testing.assert_array_equal(boxes.distance, np.full(5, 1.25))


def test_non_finite_inputs_give_nan_in_their_row_only():
    result = capsule_capsule([[0, 0, 0], [np.nan, 0, 0]], [[1, 0, 0], [1, 0, 0]], 0.1, [0, 1, 0], [1, 1, 0], 0.1)
    assert result.distance[0] == pytest.approx(0.8, abs=1e-15)
    assert np.isnan(result.distance[1])


def test_docstring_examples():
    assert doctest.testmod(_distances, optionflags=doctest.ELLIPSIS).failed == 0
