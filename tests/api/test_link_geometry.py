"""Link geometry over HTTP: GET shows a robot's shapes and their source, every form carries them (description →
robot → export → robot gives the same shapes in the world), and bad shapes are 422s located at the field."""

from __future__ import annotations

import math

import numpy as np
import pytest

from service.kinematics import link_frames
from service.robots.build import robot_from_description
from service.robots.export import description_in_form
from service.robots.schemas import RobotDescription
from pydantic import TypeAdapter
from tests.conftest import assert_problem, catalogue_robot

DESCRIPTIONS = TypeAdapter(RobotDescription)
ARM = {"convention": "standard", "angle_unit": "deg", "length_unit": "mm",
       "joints": [{"alpha": 90, "d": 300}, {"a": 400}, {"a": 50, "alpha": -90}, {"alpha": 90, "d": 380},
                  {"alpha": -90}, {"d": 80}],
       "collision": [{"link": 2, "capsule": {"from": [-400, 0, 0], "to": [0, 0, 0], "radius": 60}},
                     {"link": 6, "sphere": {"center": [0, 0, 30], "radius": 40}},
                     {"link": 0, "box": {"center": [0, 0, -150], "size": [300, 250, 300],
                                         "orientation": {"type": "rpy", "angles": [10, 20, 30]}}}]}


def _world(robot, q, metres_per_unit: float = 1.0) -> list[tuple]:
    """Every shape of ``robot`` placed in its base frame at q, in metres, sorted (a URDF groups them by link)."""
    frames = link_frames(robot.with_frames(np.eye(4), np.eye(4)), q)
    placed = []
    for item in robot.collision:
        R, p, shape = frames[item.link][:3, :3], frames[item.link][:3, 3], item.shape
        points = [getattr(shape, name) for name in ("start", "end", "center") if hasattr(shape, name)]
        entry = [type(shape).__name__, *[(R @ point + p) * metres_per_unit for point in points]]
        if hasattr(shape, "radius"):
            entry.append(np.array([shape.radius * metres_per_unit]))
        if hasattr(shape, "rotation"):
            entry += [R @ shape.rotation, shape.size * metres_per_unit]
        placed.append(entry)
    return sorted(placed, key=lambda e: (e[0], tuple(np.round(e[1], 6))))


def _assert_same(a, b):
    assert [e[0] for e in a] == [e[0] for e in b]
    for x, y in zip(a, b):
        for u, v in zip(x[1:], y[1:]):
            np.testing.assert_allclose(u, v, atol=1e-9)


@pytest.mark.parametrize("form", ["screws", "urdf", "modified"])
def test_every_form_carries_the_same_shapes(form):
    """description → robot → ?form= export → robot: the shapes sit in the same places at random joint values."""
    description = DESCRIPTIONS.validate_python({**ARM, "id": "arm"})
    robot = robot_from_description(description, max_joints=32)
    exported = description_in_form(description, robot, form)
    again = robot_from_description(DESCRIPTIONS.validate_python(exported.model_dump(by_alias=True)), max_joints=32)
    scale = 1000.0 if form == "urdf" else 1.0  # the URDF is in metres, the table in mm
    for q in np.random.default_rng(2).uniform(-math.pi, math.pi, (5, 6)):
        _assert_same(_world(robot, q, 0.001), _world(again, q, 0.001 * scale))
    if form == "urdf":
        assert "<cylinder" in exported.urdf and "cylinder" in exported.notes


@pytest.mark.parametrize("robot_id, form", [("ur5e", "screws"), ("ur5e", "urdf"), ("puma560_standard", "modified"),
                                            ("puma560_khalil", "standard"), ("franka_panda", "screws")])
def test_catalogue_shapes_survive_the_exports_over_http(client, robot_id, form):
    robot = catalogue_robot(client, robot_id)
    response = client.get(f"/v1/robots/{robot_id}", params={"form": form})
    assert response.status_code == 200, response.text
    exported = response.json()
    assert exported["collision_source"] == client.get(f"/v1/robots/{robot_id}").json()["collision_source"]
    again = robot_from_description(DESCRIPTIONS.validate_python(exported), max_joints=32)
    for q in np.random.default_rng(4).uniform(-math.pi, math.pi, (3, robot.dof)):
        _assert_same(_world(robot, q), _world(again, q))


def test_get_robot_shows_the_shapes_in_the_files_units(client):
    body = client.get("/v1/robots/ur5e").json()
    assert body["collision_source"].startswith("Capsules on the arm's kinematic skeleton")
    first = body["collision"][0]
    assert set(first) == {"link", "capsule"} and set(first["capsule"]) == {"from", "to", "radius"}
    robot = catalogue_robot(client, "ur5e")
    assert [entry["link"] for entry in body["collision"]] == [item.link for item in robot.collision]
    assert [entry["capsule"]["radius"] for entry in body["collision"]] == [item.shape.radius for item in
                                                                          robot.collision]


def _fk(client, collision, robot=None):
    robot = robot or {"convention": "standard", "joints": [{"a": 1.0}, {"a": 0.5}]}
    return client.post("/v1/fk", json={"robot": {**robot, "collision": collision}, "joints": [0.1, 0.2]})


@pytest.mark.parametrize("entry, loc, text", [
    ({"link": 1, "capsule": {"from": [0, 0, 0], "to": [1, 0, 0], "radius": -0.1}}, ["capsule", "radius"],
     "greater than or equal to 0"),
    ({"link": 0, "box": {"center": [0, 0, 0], "size": [0.1, 0, 0.1]}}, ["box", "size", 1], "greater than 0"),
    ({"link": 3, "sphere": {"center": [0, 0, 0], "radius": 0.1}}, ["link"], "from 0 (the base) to 2"),
    ({"link": -1, "sphere": {"center": [0, 0, 0], "radius": 0.1}}, ["link"], "frame index"),
    ({"link": "upper_arm", "sphere": {"center": [0, 0, 0], "radius": 0.1}}, ["link"], "URDF robots"),
    ({"link": 0, "box": {"center": [0, 0, 0], "size": [1, 1, 1],
                         "orientation": {"type": "matrix", "matrix": [[1, 0, 0], [0, 1, 0.1], [0, 0, 1]]}}},
     ["box", "orientation", "matrix"], "orthonormal"),
    ({"link": 0}, [], "exactly one of"),
    ({"link": 0, "sphere": {"center": [0, 0, 0], "radius": 1}, "box": {"center": [0, 0, 0], "size": [1, 1, 1]}},
     [], "exactly one of"),
])
def test_bad_shapes_are_422s_at_the_field(client, entry, loc, text):
    good = {"link": 1, "capsule": {"from": [0, 0, 0], "to": [-1, 0, 0], "radius": 0.1}}
    response = _fk(client, [good, entry])
    body = assert_problem(response, 422, loc=["body", "robot", "collision", 1, *loc])
    assert any(text in error["msg"] for error in body["errors"]) or text in body["detail"], body


URDF = ('<robot name="t"><link name="base"><collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>'
        '</link><link name="arm"><collision><origin xyz="0.25 0 0" rpy="0 1.5707963267948966 0"/><geometry>'
        '<cylinder radius="0.05" length="0.5"/></geometry></collision><collision><geometry><mesh filename="a.stl"/>'
        '</geometry></collision></link><link name="hand"/><link name="other"/>'
        '<joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>'
        '<limit lower="-1" upper="1"/></joint>'
        '<joint name="f" type="fixed"><parent link="arm"/><child link="hand"/><origin xyz="0.5 0 0"/></joint>'
        '<joint name="j2" type="revolute"><parent link="base"/><child link="other"/><axis xyz="0 0 1"/></joint>'
        '</robot>')


def test_urdf_link_names_and_errors(client):
    robot = {"format": "urdf", "urdf": URDF, "base_link": "base", "tip_link": "hand"}
    ok = client.post("/v1/fk", json={"robot": {**robot, "collision": [
        {"link": "hand", "sphere": {"center": [0, 0, 0], "radius": 0.03}}]}, "joints": [0.3]})
    assert ok.status_code == 200, ok.text
    for link, words in (("nowhere", "is not a link of this URDF"), ("other", "is not fixed to the chain")):
        response = client.post("/v1/fk", json={"robot": {**robot, "collision": [
            {"link": link, "sphere": {"center": [0, 0, 0], "radius": 0.03}}]}, "joints": [0.3]})
        assert_problem(response, 422, loc=["body", "robot", "collision", 0, "link"], match=words)
    bad = URDF.replace('radius="0.05"', 'radius="-0.05"')
    response = client.post("/v1/fk", json={"robot": {**robot, "urdf": bad}, "joints": [0.3]})
    assert_problem(response, 422, loc=["body", "robot", "urdf", "link", "arm"], match="≥ 0")
    # the URDF's own shapes: the box on frame 0, the cylinder's capsule on frame 1 (the arm's body)
    description = DESCRIPTIONS.validate_python(robot)
    built = robot_from_description(description, max_joints=4)
    assert [(item.link, type(item.shape).__name__, item.name) for item in built.collision] == [
        (0, "Box", "base"), (1, "Capsule", "arm")]
    frames = link_frames(built, np.array([0.3]))
    capsule = built.collision[1].shape
    ends = sorted((frames[1][:3, :3] @ point + frames[1][:3, 3]).round(12).tolist() for point in
                  (capsule.start, capsule.end))
    np.testing.assert_allclose(ends, [[0, 0, 0], [0.5 * math.cos(0.3), 0.5 * math.sin(0.3), 0]], atol=1e-12)


def test_a_dumped_catalogue_description_is_a_valid_inline_robot(client):
    """What a Python client dumps from the service's own description models is what the wire takes: a capsule's
    ``from`` (the field is ``start`` in Python) round-trips; CI's HTTP benchmark and the schemathesis test sent the
    field names and got 422s."""
    for robot_id in ("puma560_standard", "franka_panda"):
        entry = client.app.state.catalogue.get(robot_id)
        dumped = entry.description.model_dump(mode="json", exclude_none=True)
        assert "from" in str(dumped["collision"]) and "start" not in str(dumped["collision"])
        response = client.post("/v1/fk", json={"robot": dumped, "joints": [0.1] * entry.robot.dof})
        assert response.status_code == 200, response.text
