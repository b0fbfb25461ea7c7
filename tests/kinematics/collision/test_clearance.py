"""The clearance of joint vectors (clearances): the catalogue PUMA's capsules and a cell's obstacles, against every
pair's exact distance from the model and link frames from FK; the close pairs as columns, taken and joined."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from service.kinematics import link_frames
from service.kinematics.collision import Box, Capsule, CollisionRequest, Contacts, Obstacle, clearances, model_for
from service.robots.catalogue import load_robot_file

PUMA = load_robot_file(Path(__file__).resolve().parents[3] / "robots" / "puma560_standard.yaml", max_joints=16).robot
CELL = CollisionRequest(obstacles=(Obstacle("table", Box([0.55, 0.0, -0.15], [0.5, 1.0, 0.1])),
                                   Obstacle("post", Capsule([0.27, -0.2, -0.6], [0.27, -0.2, 0.6], 0.06))),
                        margin=0.005)


def expected_contacts(joints: np.ndarray) -> list[list[tuple[str, str, float]]]:
    """Each row's body pairs below the margin, nearest first, from every pair's exact distance."""
    model = model_for(PUMA, CELL)
    distances = model.distances(link_frames(PUMA, joints))
    rows = []
    for row in distances:
        nearest: dict[tuple[str, str], float] = {}
        for pair, distance in zip(model.pairs, row.tolist()):
            if distance < CELL.margin:
                nearest[(pair.a, pair.b)] = min(nearest.get((pair.a, pair.b), np.inf), distance)
        rows.append(sorted(((a, b, d) for (a, b), d in nearest.items()), key=lambda item: item[2]))
    return rows


def test_every_row_lists_its_close_pairs_nearest_first_and_its_clearance():
    joints = np.random.default_rng(4).uniform(PUMA.lower, PUMA.upper, (500, 6))
    checked = clearances(PUMA, CELL, joints)
    model = model_for(PUMA, CELL)
    exact = model.distances(link_frames(PUMA, joints))
    np.testing.assert_array_equal(checked.clearance, exact.min(axis=1))
    expected = expected_contacts(joints)
    assert [list(row) for row in checked.contacts] == expected
    assert checked.colliding.tolist() == [bool(row) for row in expected]
    assert 50 < checked.colliding.sum() < 450 and checked.contacts.pairs.shape[1] >= 2
    assert checked.contacts[int(np.argmax(checked.colliding))] == tuple(expected[int(np.argmax(checked.colliding))])


def test_contacts_are_taken_and_joined_as_columns_and_worded_alike():
    rng = np.random.default_rng(8)
    first = clearances(PUMA, CELL, rng.uniform(PUMA.lower, PUMA.upper, (200, 6))).contacts
    other = CollisionRequest(obstacles=(Obstacle("lamp", Capsule([0.3, 0.3, 0.0], [0.3, 0.3, 0.5], 0.2)),),
                             margin=0.005)
    second = clearances(PUMA, other, rng.uniform(PUMA.lower, PUMA.upper, (150, 6))).contacts
    assert set(first.names) != set(second.names)
    order = rng.permutation(200)
    joined = Contacts.concat([first.take(order), Contacts.none(7), second])
    assert len(joined) == 357
    assert list(joined) == [first[int(i)] for i in order] + [()] * 7 + list(second)
    mask = rng.random(357) < 0.5
    assert list(joined.take(mask)) == [row for row, kept in zip(list(joined), mask) if kept]
