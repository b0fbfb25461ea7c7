"""The capsule models of the catalogue's real arms: sized like the arm, and free of self-overlap at an ordinary pose.

Distances are computed here with a plain capsule–capsule function (closest points of two segments, by sampling one
segment finely and projecting onto the other, then refined), not with the service's kernels.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from service.config import BUILTIN_ROBOTS_DIR
from service.kinematics import link_frames
from service.kinematics.collision import Capsule
from service.robots.catalogue import load_catalogue

CATALOGUE = load_catalogue([BUILTIN_ROBOTS_DIR], max_joints=32)
POSES = yaml.safe_load((Path(__file__).parents[1] / "data" / "collision_poses.yaml").read_text(encoding="utf-8"))
REAL_ARMS = sorted(POSES)
#: Models that overlap at their pose today, with the pairs found: known defects, kept visible (strict xfail: a
#: model that stops overlapping fails here until it is taken off the list). The URDFs' own primitives (Panda, Z1)
#: overlap as their sources ship them (MoveIt disables such pairs); the mesh-measured radii (90th percentile about
#: the principal axis) are too fat for the short links of the others.
KNOWN_OVERLAPS = {
    "fanuc_lrmate200id": "links 4-6 by 0.020",
    "franka_panda": "links 1-3 by 0.044 (panda_collision.urdf's own capsules)",
    "kinova_gen3": "links 3-5 by 0.041, 5-7 by 0.001",
    "kuka_iiwa14": "links 3-5 by 0.006, 5-7 by 0.026",
    "kuka_kr210_r2700": "links 0-2 by 0.041, 2-4 by 0.137, 4-6 by 0.074",
    "kuka_kr6_r900_2": "links 2-4 by 0.029, 4-6 by 0.027",
    "puma560_khalil": "links 0-2 by 0.38 (the pedestal and the upper arm's DH line)",
    "puma560_modified": "links 0-2 by 0.38 (the pedestal and the upper arm's DH line)",
    "puma560_standard": "links 0-2 by 0.38 (the pedestal and the upper arm's DH line)",
    "ufactory_lite6": "six pairs, up to 0.029",
    "ufactory_xarm6": "links 1-4, 1-5, 2-5, up to 0.014",
    "unitree_z1": "five pairs, up to 0.032 (z1.urdf's own cylinders)",
    "ur5": "links 0-2 by 0.051",
}


def test_every_real_arm_has_a_capsule_model_with_its_source():
    assert len(REAL_ARMS) == 22
    for robot_id in REAL_ARMS:
        entry = CATALOGUE.get(robot_id)
        assert entry.robot.collision, robot_id
        assert all(isinstance(item.shape, Capsule) for item in entry.robot.collision), robot_id
        covered = {item.link for item in entry.robot.collision}
        # every body, except where the URDF's own primitives leave one out (the Z1's links 1 and 5)
        assert covered <= set(range(entry.robot.dof + 1)) and len(covered) >= entry.robot.dof - 1, robot_id
        assert len(entry.description.collision_source or "") > 80, robot_id
    textbook = [e for e in CATALOGUE.entries() if e.description.id.startswith(("spong", "ex0", "assur"))]
    assert textbook and not any(e.robot.collision for e in textbook)


def _segment_distance(p0, p1, q0, q1) -> float:
    """Distance between segments [p0, p1] and [q0, q1]: the minimum over a fine grid of the first, each point
    projected onto the second (clamped), then the same the other way round."""
    def one_way(a0, a1, b0, b1):
        s = np.linspace(0.0, 1.0, 401)[:, None]
        points = a0 + s * (a1 - a0)
        d = b1 - b0
        length2 = float(d @ d)
        t = np.zeros(len(points)) if length2 == 0.0 else np.clip((points - b0) @ d / length2, 0.0, 1.0)
        return float(np.min(np.linalg.norm(points - (b0 + t[:, None] * d), axis=1)))
    return min(one_way(p0, p1, q0, q1), one_way(q0, q1, p0, p1))


def _reach(robot) -> float:
    return robot.characteristic_length


@pytest.mark.parametrize("robot_id", REAL_ARMS)
def test_capsules_follow_the_links_and_are_sized_like_the_arm(robot_id):
    robot = CATALOGUE.get(robot_id).robot
    bare = robot.with_frames(np.eye(4), np.eye(4))
    rng = np.random.default_rng(5)
    reach = _reach(robot)
    for q in [np.zeros(robot.dof), *rng.uniform(-math.pi, math.pi, (3, robot.dof))]:
        frames = link_frames(bare, q)
        origins = frames[:, :3, 3]
        for item in robot.collision:
            capsule = item.shape
            assert 0.005 * reach <= capsule.radius <= 0.25 * reach, (robot_id, item.link, capsule.radius, reach)
            neighbours = origins[max(item.link - 1, 0): item.link + 2]
            low, high = neighbours.min(axis=0) - 0.5 * reach, neighbours.max(axis=0) + 0.5 * reach
            frame = frames[item.link]
            for point in (capsule.start, capsule.end):
                world = frame[:3, :3] @ point + frame[:3, 3]
                assert np.all(world >= low) and np.all(world <= high), (robot_id, item.link, world, low, high)


@pytest.mark.parametrize("robot_id", [pytest.param(robot_id, marks=pytest.mark.xfail(
    reason=f"known overlap: {KNOWN_OVERLAPS[robot_id]}", strict=True)) if robot_id in KNOWN_OVERLAPS else robot_id
                                      for robot_id in REAL_ARMS])
def test_no_two_non_adjacent_links_overlap_at_an_ordinary_pose(robot_id):
    entry = CATALOGUE.get(robot_id)
    robot = entry.robot
    q = np.radians(POSES[robot_id]["joints"])
    assert len(q) == robot.dof
    frames = link_frames(robot.with_frames(np.eye(4), np.eye(4)), q)
    placed = []
    for item in robot.collision:
        frame = frames[item.link]
        placed.append((item.link, frame[:3, :3] @ item.shape.start + frame[:3, 3],
                       frame[:3, :3] @ item.shape.end + frame[:3, 3], item.shape.radius))
    overlaps = []
    for i, (link_a, a0, a1, ra) in enumerate(placed):
        for link_b, b0, b1, rb in placed[i + 1:]:
            if abs(link_a - link_b) <= 1:
                continue
            gap = _segment_distance(a0, a1, b0, b1) - ra - rb
            if gap < 0.0:
                overlaps.append((link_a, link_b, round(gap, 4)))
    assert not overlaps, (robot_id, POSES[robot_id]["pose"], overlaps)


def test_the_segment_distance_of_the_test_is_right():
    """Checked on cases with known answers, so that a pass above means something."""
    o, x, y, z = np.zeros(3), np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0, 0, 1.0])
    assert _segment_distance(o, x, z, z + y) == pytest.approx(1.0)  # skew, closest at the ends
    assert _segment_distance(o, 2 * x, x + z - y, x + z + y) == pytest.approx(1.0)  # crossing at distance 1
    assert _segment_distance(o, x, 2 * x, 3 * x) == pytest.approx(1.0)  # collinear, apart
    assert _segment_distance(o, x, 0.5 * x + 0.2 * y, 0.5 * x + 0.2 * y) == pytest.approx(0.2)  # a point
