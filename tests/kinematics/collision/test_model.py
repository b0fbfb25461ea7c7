"""The compiled collision model: which pairs it checks, what it names them, its distances for batches of link
frames (against the exact reference on shapes moved into the world by the test itself), the close pairs, and
hostile inputs."""

from __future__ import annotations

import doctest
import itertools
from pathlib import Path

import numpy as np
import pytest

from service.kinematics import InvalidInputError, link_frames
from service.kinematics.collision import Box, Capsule, LinkShape, Obstacle, Sphere, collision_model
from service.kinematics.collision import _model
from service.robots.catalogue import load_robot_file
from tests.oracles.collision import signed_distance, signed_distances
from tests.oracles.rotations import random_rotations

ROBOTS = Path(__file__).resolve().parents[3] / "robots"


def random_rigid(rng: np.random.Generator) -> np.ndarray:
    """A random rigid transform (4, 4): a rotation from a QR decomposition (not from the service's rotations), then
    a translation of standard normal coordinates."""
    T = np.eye(4)
    T[:3, :3] = random_rotations(rng, 1)[0]
    T[:3, 3] = rng.normal(size=3)
    return T


def moved(shape, T: np.ndarray):
    """The shape expressed in the world, given world_T_link."""
    R, t = T[:3, :3], T[:3, 3]
    if isinstance(shape, Capsule):
        return Capsule(R @ shape.start + t, R @ shape.end + t, shape.radius)
    if isinstance(shape, Sphere):
        return Sphere(R @ shape.center + t, shape.radius)
    return Box(R @ shape.center + t, shape.size, R @ shape.rotation)


def arm_shapes() -> list[LinkShape]:
    """Shapes of every kind on the links of a 5-joint arm (frames 0 … 5), two on link 2."""
    return [
        LinkShape(0, Box([0, 0, -0.2], [0.3, 0.3, 0.4])),
        LinkShape(1, Capsule([0, 0, 0], [0, 0, 0.3], 0.08)),
        LinkShape(2, Capsule([0, 0, 0], [0.4, 0, 0], 0.06)),
        LinkShape(2, Sphere([0.2, 0.05, 0], 0.07)),
        LinkShape(3, Box([0.1, 0, 0], [0.3, 0.1, 0.1])),
        LinkShape(4, Capsule([0, 0, 0], [0, 0, 0.2], 0.05)),
        LinkShape(5, Sphere([0, 0, 0.1], 0.04)),
    ]


OBSTACLES = [
    Obstacle("table", Box([0.6, 0, -0.05], [1.2, 0.8, 0.1])),
    Obstacle("post", Capsule([0.4, 0.4, 0], [0.4, 0.4, 1.0], 0.05)),
    Obstacle("lamp", Sphere([0.0, -0.5, 0.8], 0.1)),
]


# --- which pairs -------------------------------------------------------------------------------------------


def expected_pairs(shapes, obstacles, self_collision, ignore):
    """The rules of the issue, written out: (shape a, shape b or obstacle name)."""
    pairs = {(i, obstacle.name, k) for i in range(len(shapes)) for k, obstacle in enumerate(obstacles)}
    if self_collision:
        skipped = {tuple(sorted(pair)) for pair in ignore}
        for i, j in itertools.combinations(range(len(shapes)), 2):
            low, high = sorted((shapes[i].link, shapes[j].link))
            if high - low > 1 and (low, high) not in skipped:
                first, second = (i, j) if shapes[i].link <= shapes[j].link else (j, i)
                pairs.add((first, second, None))
    return pairs


def model_pairs(model):
    return {(pair.shape_a, model.obstacles[pair.shape_b].name, pair.shape_b) if pair.link_b is None
            else (pair.shape_a, pair.shape_b, None) for pair in model.pairs}


@pytest.mark.parametrize("self_collision", [True, False])
@pytest.mark.parametrize("ignore", [[], [[0, 2]], [[4, 2], [0, 5]]])
def test_the_model_checks_exactly_the_pairs_the_rules_give(self_collision, ignore):
    shapes = arm_shapes()
    model = collision_model(shapes, 6, OBSTACLES, self_collision=self_collision, ignore=ignore)
    assert model_pairs(model) == expected_pairs(shapes, OBSTACLES, self_collision, ignore)
    assert len(model.pairs) == len(model_pairs(model))  # no pair twice
    for pair in model.pairs:
        assert pair.link_a != pair.link_b
        assert pair.link_b is None or pair.link_b - pair.link_a > 1


def test_no_two_shapes_of_one_link_and_no_joined_links():
    shapes = [LinkShape(2, Capsule([0, 0, 0], [1, 0, 0], 0.1)), LinkShape(2, Sphere([0, 0, 0], 0.2)),
              LinkShape(3, Sphere([0, 0, 0], 0.2)), LinkShape(1, Sphere([0, 0, 0], 0.2))]
    assert [(pair.a, pair.b) for pair in collision_model(shapes, 4).pairs] == [("link 1", "link 3")]


def test_every_link_shape_meets_every_obstacle_the_base_too():
    model = collision_model([LinkShape(0, Sphere([0, 0, 0], 0.1))], 3, OBSTACLES)
    assert sorted((pair.a, pair.b) for pair in model.pairs) == [("link 0", "lamp"), ("link 0", "post"),
                                                                ("link 0", "table")]


def test_pairs_are_named_by_link_and_obstacle():
    model = collision_model(arm_shapes(), 6, OBSTACLES)
    names = {(pair.a, pair.b) for pair in model.pairs}
    assert ("link 0", "table") in names and ("link 2", "link 5") in names and ("link 2", "link 4") in names
    assert all(pair.a == f"link {pair.link_a}" for pair in model.pairs)
    kinds = {pair.kind for pair in model.pairs}
    assert kinds == {"box-box", "box-capsule", "box-sphere", "capsule-capsule", "capsule-sphere",
                     "sphere-sphere"}
    named = collision_model(arm_shapes(), 6, OBSTACLES, link_names=["base", "l1", "l2", "l3", "l4", "tool"])
    assert ("l2", "tool") in {(pair.a, pair.b) for pair in named.pairs}


def test_body_pairs_merge_the_shapes_of_one_link_and_obstacles_of_one_name():
    table_legs = [Obstacle("table", Box([0.0, 0.0, -0.5], [0.1, 0.1, 1.0])),
                  Obstacle("table", Box([1.0, 0.0, -0.5], [0.1, 0.1, 1.0]))]
    model = collision_model(arm_shapes(), 6, table_legs, self_collision=False)
    # link 2 carries two shapes and the table two legs: four shape pairs, one body pair
    assert sum(pair.a == "link 2" for pair in model.pairs) == 4
    assert model.body_pairs.count(("link 2", "table")) == 1
    assert len(model.body_pairs) == 6
    for pair, body in zip(model.pairs, model.body_pair_of):
        assert model.body_pairs[body] == (pair.a, pair.b)


# --- distances ---------------------------------------------------------------------------------------------


def world_shapes(model, frames: np.ndarray, configuration: int, column: int):
    """Pair ``column``'s two shapes in the world, in configuration ``configuration``."""
    pair = model.pairs[column]
    a = moved(model.link_shapes[pair.shape_a].shape, frames[configuration, pair.link_a])
    b = (model.obstacles[pair.shape_b].shape if pair.link_b is None
         else moved(model.link_shapes[pair.shape_b].shape, frames[configuration, pair.link_b]))
    return a, b


def reference_distances(model, frames: np.ndarray) -> np.ndarray:
    """The exact reference on the shapes moved by :func:`moved`, batched by the kinds of the pairs."""
    by_kinds: dict[tuple, list] = {}
    for s, k in itertools.product(range(frames.shape[0]), range(len(model.pairs))):
        a, b = world_shapes(model, frames, s, k)
        by_kinds.setdefault((type(a), type(b)), []).append((s, k, a, b))
    result = np.full((frames.shape[0], len(model.pairs)), np.nan)
    for entries in by_kinds.values():
        values = signed_distances([entry[2] for entry in entries], [entry[3] for entry in entries])
        for (s, k, _, _), value in zip(entries, values):
            result[s, k] = value
    return result


def random_frames(rng: np.random.Generator, count: int, links: int) -> np.ndarray:
    return np.array([[random_rigid(rng) for _ in range(links)] for _ in range(count)])


def test_distances_match_the_reference_on_shapes_moved_by_the_test():
    rng = np.random.default_rng(0)
    model = collision_model(arm_shapes(), 6, OBSTACLES)
    frames = random_frames(rng, 40, 6)
    frames[..., :3, 3] *= 0.4  # nearer each other: some shapes overlap
    ours = model.distances(frames)
    reference = reference_distances(model, frames)
    np.testing.assert_allclose(ours, reference, rtol=0, atol=1e-9)
    assert (reference < 0).any() and (reference > 0).any()


def test_a_real_arm_through_link_frames():
    robot = load_robot_file(ROBOTS / "puma560_standard.yaml", max_joints=16).robot
    shapes = [LinkShape(1, Capsule([0, 0, -0.2], [0, 0, 0.2], 0.10)),
              LinkShape(2, Capsule([-0.4318, 0, 0], [0, 0, 0], 0.08)),
              LinkShape(3, Capsule([0, 0, 0], [0, -0.4318, 0], 0.06)),
              LinkShape(6, Box([0, 0, 0.05], [0.06, 0.06, 0.1]))]
    model = collision_model(shapes, robot.dof + 1, [Obstacle("table", Box([0.6, 0, -0.7], [1.2, 0.8, 0.02]))])
    q = np.random.default_rng(1).uniform(-np.pi, np.pi, (60, robot.dof))
    frames = link_frames(robot, q)
    np.testing.assert_allclose(model.distances(frames), reference_distances(model, frames), rtol=0, atol=1e-9)


def point_and_base_model(robot):
    """A PUMA model with a base capsule, a capsule of length 0 and a sphere (the kernels of a point), a capsule
    and a box, and one obstacle of each kind."""
    shapes = [LinkShape(0, Capsule([0, 0, -0.25], [0, 0, -0.7], 0.2)),
              LinkShape(1, Capsule([0, 0, 0.05], [0, 0, 0.05], 0.075)),
              LinkShape(2, Capsule([-0.4318, 0, 0], [-0.09, 0, 0], 0.12)),
              LinkShape(4, Capsule([0, -0.34, 0], [0, -0.08, 0], 0.045)),
              LinkShape(5, Sphere([0, 0, 0], 0.05)),
              LinkShape(6, Box([0, 0, 0.05], [0.06, 0.06, 0.1]))]
    obstacles = [Obstacle("table", Box([0.55, 0, -0.15], [0.5, 1.0, 0.1])),
                 Obstacle("post", Capsule([0.27, -0.2, -0.6], [0.27, -0.2, 0.6], 0.06)),
                 Obstacle("lamp", Sphere([0.3, 0.3, 0.4], 0.1))]
    return collision_model(shapes, robot.dof + 1, obstacles, ignore=[(0, 2), (4, 6)])  # touching at home


@pytest.mark.parametrize("base", ["still", "moving"])
def test_points_and_base_shapes_through_link_frames(base):
    """Spheres and capsules of length 0 take the point kernels; a base shape against an obstacle is measured
    once per block when the base frame stays put, per configuration when it moves. Either way every distance
    is the reference's, and the check's clearance and close pairs are the distances' own."""
    robot = load_robot_file(ROBOTS / "puma560_standard.yaml", max_joints=16).robot
    model = point_and_base_model(robot)
    rng = np.random.default_rng(12)
    frames = link_frames(robot, rng.uniform(-np.pi, np.pi, (600, robot.dof)))
    if base == "moving":
        frames[::3, 0] = [random_rigid(rng) for _ in range(len(frames[::3]))]
        frames[::3, 0, :3, 3] *= 0.1
    distances = model.distances(frames)
    chosen = rng.choice(len(frames), 60, replace=False)
    np.testing.assert_allclose(distances[chosen], reference_distances(model, frames[chosen]), rtol=0, atol=1e-9)
    fixed = [k for k, pair in enumerate(model.pairs) if pair.link_a == 0 and pair.link_b is None]
    assert len(fixed) == 3
    assert (np.ptp(distances[:, fixed], axis=0) == 0).all() == (base == "still")
    margin = 0.01
    check = model.check(frames, margin)
    np.testing.assert_array_equal(check.clearance, distances.min(axis=1))
    # the base's pairs with the obstacles are measured in full, once per block while the base stays put
    np.testing.assert_array_equal(check.pair_distances[:, fixed], distances[:, fixed])
    assert (check.pair_distances != distances).any()  # the bounds left some pairs unmeasured
    assert 0 < check.colliding.mean() < 1
    for s in range(0, len(frames), 11):
        nearest: dict = {}
        for pair, d in zip(model.pairs, distances[s]):
            if d < margin:
                nearest[(pair.a, pair.b)] = min(nearest.get((pair.a, pair.b), np.inf), d)
        listed = check.close_pairs(model, s)
        assert sorted(((a, b), d) for a, b, d in listed) == sorted(nearest.items())
        assert [d for _, _, d in listed] == sorted(d for _, _, d in listed)


def test_single_configuration_zero_and_many():
    rng = np.random.default_rng(2)
    model = collision_model(arm_shapes(), 6, OBSTACLES)
    frames = random_frames(rng, 3000, 6)  # more than one block of every group
    many = model.distances(frames)
    assert many.shape == (3000, len(model.pairs))
    np.testing.assert_array_equal(model.distances(frames[17]), many[17])
    checked = model.check(frames, 0.05)  # the bounds leave other pairs to measure alone: the same bits
    np.testing.assert_array_equal(model.check(frames[17], 0.05).clearance, checked.clearance[17:18])
    np.testing.assert_array_equal(model.check(frames[:1000], 0.05).clearance, checked.clearance[:1000])
    np.testing.assert_array_equal(np.concatenate([model.distances(frames[:1000]), model.distances(frames[1000:])]),
                                  many)
    np.testing.assert_allclose(many[:30], reference_distances(model, frames[:30]), rtol=0, atol=1e-9)
    assert model.distances(frames[:0]).shape == (0, len(model.pairs))
    empty = model.check(frames[:0])
    assert empty.clearance.shape == (0,) and empty.offsets.tolist() == [0]


def test_a_model_without_pairs_has_infinite_clearance():
    model = collision_model([LinkShape(1, Sphere([0, 0, 0], 0.1))], 3, self_collision=True)
    check = model.check(np.tile(np.eye(4), (4, 3, 1, 1)))
    assert model.pairs == () and check.pair_distances.shape == (4, 0)
    assert np.isinf(check.clearance).all() and not check.colliding.any()


# --- clearance and the close pairs -------------------------------------------------------------------------


def test_clearance_is_the_smallest_distance_and_close_pairs_are_those_below_the_margin():
    rng = np.random.default_rng(3)
    model = collision_model(arm_shapes(), 6, OBSTACLES)
    frames = random_frames(rng, 200, 6)
    frames[..., :3, 3] *= 0.3
    margin = 0.05
    check = model.check(frames, margin)
    distances = model.distances(frames)
    np.testing.assert_array_equal(check.clearance, distances.min(axis=1))
    # a pair is measured where it can be the clearance or close; elsewhere its lower bound stands, above both
    bounded = check.pair_distances != distances
    assert 0.2 < bounded.mean() < 0.8  # the bounds spare work here
    assert (check.pair_distances[bounded] <= distances[bounded] + 1e-12).all()  # spheres: bounds meet
    assert (check.pair_distances > np.maximum(check.clearance, margin)[:, None])[bounded].all()
    for s in range(frames.shape[0]):
        expected = {}
        for k, pair in enumerate(model.pairs):
            if distances[s, k] < margin:
                key = (pair.a, pair.b)
                expected[key] = min(expected.get(key, np.inf), distances[s, k])
        listed = check.close_pairs(model, s)
        assert {(a, b): d for a, b, d in listed} == expected
        assert [d for _, _, d in listed] == sorted(d for _, _, d in listed)  # nearest first
        assert check.colliding[s] == bool(expected)
    assert check.colliding.any() and not check.colliding.all()


def test_touching_is_not_closer_than_a_zero_margin():
    model = collision_model([LinkShape(0, Sphere([0, 0, 0], 1.0))], 2,
                            [Obstacle("touch", Sphere([2, 0, 0], 1.0)), Obstacle("in", Sphere([1.5, 0, 0], 1.0))])
    check = model.check(np.tile(np.eye(4), (2, 1, 1)), 0.0)
    assert check.close_pairs(model, 0) == [("link 0", "in", -0.5)]
    assert check.clearance.tolist() == [-0.5]


def test_witnesses_are_on_the_pairs_shapes_in_the_world():
    rng = np.random.default_rng(4)
    model = collision_model(arm_shapes(), 6, OBSTACLES)
    frames = random_frames(rng, 10, 6)
    configurations = np.repeat(np.arange(10), len(model.pairs))
    pairs = np.tile(np.arange(len(model.pairs)), 10)
    result = model.witnesses(frames, configurations, pairs)
    np.testing.assert_allclose(result.distance, model.distances(frames).reshape(-1), rtol=0, atol=1e-12)
    for k, (s, p) in enumerate(zip(configurations, pairs)):
        a, b = world_shapes(model, frames, s, p)
        assert abs(signed_distance(Sphere(result.point_a[k], 0.0), a)) <= 1e-9
        assert abs(signed_distance(Sphere(result.point_b[k], 0.0), b)) <= 1e-9
        np.testing.assert_allclose(result.point_b[k] - result.point_a[k], result.distance[k] * result.normal[k],
                                   atol=1e-9)


def test_the_model_is_a_value():
    model = collision_model(arm_shapes(), 6, OBSTACLES)
    frames = random_frames(np.random.default_rng(5), 50, 6)
    first = model.distances(frames)
    model.distances(frames[:3])
    np.testing.assert_array_equal(model.distances(frames), first)


# --- hostile inputs ----------------------------------------------------------------------------------------


@pytest.mark.parametrize("arguments, location", [
    (dict(link_shapes=[]), ("link_shapes",)),
    (dict(link_shapes=[LinkShape(6, Sphere([0, 0, 0], 0.1))]), ("link_shapes", 0, "link")),
    (dict(link_shapes=[LinkShape(-1, Sphere([0, 0, 0], 0.1))]), ("link_shapes", 0, "link")),
    (dict(link_shapes=[LinkShape(True, Sphere([0, 0, 0], 0.1))]), ("link_shapes", 0, "link")),
    (dict(link_shapes=[LinkShape(1.0, Sphere([0, 0, 0], 0.1))]), ("link_shapes", 0, "link")),
    (dict(link_shapes=[Sphere([0, 0, 0], 0.1)]), ("link_shapes", 0)),
    (dict(link_shapes=[LinkShape(1, "capsule")]), ("link_shapes", 0)),
    (dict(ignore=[[1, 9]]), ("ignore", 0, 1)),
    (dict(ignore=[[2, 2]]), ("ignore", 0)),
    (dict(ignore=[[1, 2, 3]]), ("ignore", 0)),
    (dict(ignore=[3]), ("ignore", 0)),
    (dict(ignore=[[0, "1"]]), ("ignore", 0, 1)),
    (dict(obstacles=[Obstacle("", Sphere([0, 0, 0], 1.0))]), ("obstacles", 0, "name")),
    (dict(obstacles=[Obstacle("link 2", Sphere([0, 0, 0], 1.0))]), ("obstacles", 0, "name")),
    (dict(obstacles=[Sphere([0, 0, 0], 1.0)]), ("obstacles", 0)),
    (dict(link_names=["a", "b"]), ("link_names",)),
    (dict(link_names=["a", "b", "c", "d", "e", "a"]), ("link_names", 5)),
    (dict(link_names=["a", "b", "", "d", "e", "f"]), ("link_names", 2)),
    (dict(link_count=0), ("link_count",)),
    (dict(link_count=2.5), ("link_count",)),
])
def test_hostile_models_raise_located_errors(arguments, location):
    given = dict(link_shapes=arm_shapes(), link_count=6, obstacles=OBSTACLES)
    given.update(arguments)
    with pytest.raises(InvalidInputError) as error:
        collision_model(given.pop("link_shapes"), given.pop("link_count"), given.pop("obstacles"), **given)
    assert error.value.location == location


@pytest.mark.parametrize("frames, location", [
    (np.zeros((6, 4, 4)), None),  # zero matrices are finite: no error
    (np.zeros((2, 5, 4, 4)), ("frames",)),
    (np.zeros((4, 4)), ("frames",)),
    ("frames", ("frames",)),
    ([[1, 2], [3]], ("frames",)),
])
def test_frames_of_the_wrong_shape_raise_located_errors(frames, location):
    model = collision_model(arm_shapes(), 6, OBSTACLES)
    if location is None:
        model.distances(frames)
        return
    with pytest.raises(InvalidInputError) as error:
        model.distances(frames)
    assert error.value.location == location


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_frames_name_the_configuration_and_the_link(bad):
    model = collision_model(arm_shapes(), 6, OBSTACLES)
    frames = random_frames(np.random.default_rng(6), 5, 6)
    frames[3, 4, 1, 2] = bad
    with pytest.raises(InvalidInputError, match="link frame 4") as error:
        model.distances(frames)
    assert error.value.location == ("frames", 3, 4)
    with pytest.raises(InvalidInputError) as error:
        model.check(frames[3])
    assert error.value.location == ("frames", 4)
    frames[3, 4] = np.eye(4)
    model.distances(frames)


def test_a_non_finite_frame_of_a_link_without_shapes_is_ignored():
    model = collision_model([LinkShape(1, Sphere([0, 0, 0], 0.1)), LinkShape(3, Sphere([0, 0, 0], 0.1))], 5)
    frames = np.tile(np.eye(4), (2, 5, 1, 1))
    frames[:, 2] = np.nan
    assert model.distances(frames).shape == (2, 1)


@pytest.mark.parametrize("margin", [np.nan, np.inf, "near", None])
def test_the_margin_must_be_a_finite_number(margin):
    model = collision_model(arm_shapes(), 6, OBSTACLES)
    with pytest.raises(InvalidInputError) as error:
        model.check(np.tile(np.eye(4), (6, 1, 1)), margin)
    assert error.value.location == ("margin",)


@pytest.mark.parametrize("configurations, pairs, location", [
    ([0, 5], [0, 1], ("configurations",)),
    ([0, 1], [0, 99], ("pairs",)),
    ([0, 1], [0], ("pairs",)),
    ([0.5], [0], ("configurations",)),
])
def test_witnesses_of_entries_that_do_not_exist_raise_located_errors(configurations, pairs, location):
    model = collision_model(arm_shapes(), 6, OBSTACLES)
    with pytest.raises(InvalidInputError) as error:
        model.witnesses(np.tile(np.eye(4), (2, 6, 1, 1)), configurations, pairs)
    assert error.value.location == location


def test_docstring_examples():
    assert doctest.testmod(_model).failed == 0



def scaled_shape(shape, factor: float):
    if isinstance(shape, Capsule):
        return Capsule(shape.start * factor, shape.end * factor, shape.radius * factor)
    if isinstance(shape, Sphere):
        return Sphere(shape.center * factor, shape.radius * factor)
    return Box(shape.center * factor, shape.size * factor, shape.rotation)


@pytest.mark.parametrize("factor", [1e-3, 1.0, 1e3, 1e6])
def test_the_single_precision_bounds_keep_clearance_and_close_pairs_at_any_scale(factor):
    """The check measures a pair only where its single-precision bounds leave it in doubt; in millimetres or
    kilometres as in metres, its clearance is every pair's exact minimum, bit for bit, and its close pairs are
    those the exact distances give."""
    rng = np.random.default_rng(9)
    model = collision_model([LinkShape(item.link, scaled_shape(item.shape, factor)) for item in arm_shapes()], 6,
                            [Obstacle(o.name, scaled_shape(o.shape, factor)) for o in OBSTACLES])
    frames = random_frames(rng, 400, 6)
    frames[..., :3, 3] *= 0.3 * factor
    margin = 0.05 * factor
    check, distances = model.check(frames, margin), model.distances(frames)
    np.testing.assert_array_equal(check.clearance, distances.min(axis=1))
    assert (check.pair_distances <= distances + 1e-12 * factor).all()
    assert (check.pair_distances != distances).mean() > 0.2
    for s in range(0, 400, 7):
        expected = sorted(((pair.a, pair.b), d) for pair, d in zip(model.pairs, distances[s]) if d < margin)
        listed = sorted(((a, b), d) for a, b, d in check.close_pairs(model, s))
        nearest: dict = {}
        for key, d in expected:
            nearest[key] = min(nearest.get(key, np.inf), d)
        assert listed == sorted(nearest.items())


def test_coordinates_past_single_precision_are_all_measured():
    model = collision_model(arm_shapes(), 6, OBSTACLES)
    frames = random_frames(np.random.default_rng(10), 50, 6)
    frames[..., :3, 3] += 1e16  # the arm far away: every pair's distance in double precision
    check = model.check(frames, 0.05)
    np.testing.assert_array_equal(check.pair_distances, model.distances(frames))
