"""Pictures with collisions (issue 25.4): `render` and the IK picture draw the obstacles and the robot's link
shapes, and mark the links and obstacles of every pair closer than the margin.

What is marked is compared with what the JSON answers say for the same joints (FK's and IK's `collisions`), and
the drawing's geometry with forward kinematics: in the top view a sphere is a disc at its centre, a vertical
capsule a disc of its radius, at the scale the stick figure is drawn to.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from service.kinematics import forward_kinematics
from tests.conftest import assert_problem, catalogue_robot

SVG = "{http://www.w3.org/2000/svg}"
#: tests/api/test_collisions.py's PUMA over a table beside a post: 1 of 8 solutions kept within the limits.
PUMA_Q = [0.4, 0.9, -2.4, 0.7, 1.1, -0.5]
PUMA_COLLISIONS = {"margin": 0.005, "obstacles": [
    {"name": "table", "box": {"center": [0.55, 0.0, -0.15], "size": [0.5, 1.0, 0.1]}},
    {"name": "post", "capsule": {"from": [0.27, -0.2, -0.6], "to": [0.27, -0.2, 0.6], "radius": 0.06}}]}


def _panels(svg: str) -> list[ET.Element]:
    return [g for g in ET.fromstring(svg).iter(f"{SVG}g") if "configuration" in g.get("class", "").split()]


def _solids(panel: ET.Element) -> list[ET.Element]:
    return [e for e in panel.iter() if "solid" in e.get("class", "").split()]


def _marked(panel: ET.Element) -> set[str]:
    return {e.get("data-name") for e in _solids(panel) if "colliding" in e.get("class", "").split()}


def _puma_ik(client, **extra) -> tuple[dict, dict]:
    robot = catalogue_robot(client, "puma560_standard")
    body = {"target": {"matrix": forward_kinematics(robot, np.array(PUMA_Q)).tolist()},
            "collisions": PUMA_COLLISIONS, **extra}
    return body, client.post("/v1/robots/puma560_standard/ik", json=body).json()


def test_render_draws_obstacles_and_link_shapes_and_marks_what_collides(client):
    _, answer = _puma_ik(client)
    rows = [s["joints"] for s in answer["solutions"] + answer["rejected"]]
    svg = client.post("/v1/robots/puma560_standard/render",
                      json={"joints": rows, "collisions": PUMA_COLLISIONS}).text
    shapes = client.get("/v1/robots/puma560_standard").json()["collision"]
    panels = _panels(svg)
    assert len(panels) == len(rows) == 8
    seen_colliding = 0
    for panel, q in zip(panels, rows):
        solids = _solids(panel)
        obstacles = [(e.get("data-name"), e.get("data-kind")) for e in solids if "obstacle" in e.get("class")]
        assert obstacles == [("table", "box"), ("post", "capsule")]  # obstacles first: under the arm's shapes
        links = sorted(int(e.get("data-link")) for e in solids if "link-shape" in e.get("class"))
        assert links == sorted(shape["link"] for shape in shapes)
        # what is marked is what FK's check of the same joints lists, links and obstacles alike
        fk = client.post("/v1/robots/puma560_standard/fk", json={"joints": q, "collisions": PUMA_COLLISIONS}).json()
        assert _marked(panel) == {name for pair in fk["collisions"] for name in (pair["a"], pair["b"])}
        assert panel.get("data-colliding") == str(bool(fk["collisions"])).lower()
        assert ("colliding" in panel.get("class").split()) == bool(fk["collisions"])
        status = panel.find(f"{SVG}text[@class='collision-status']").text
        if fk["collisions"]:
            seen_colliding += 1
            nearest = min(fk["collisions"], key=lambda pair: pair["distance"])
            assert status.startswith(f"colliding: {nearest['a']} – {nearest['b']} (−")
        else:
            assert status == f"clear by {fk['clearance']:.3g}"
    assert seen_colliding == len([s for s in answer["rejected"] if s["collisions"]]) >= 2
    # obstacles are drawn in the world: the same in every panel
    tables = {next(e for e in _solids(p) if e.get("data-name") == "table").find(f"{SVG}polygon").get("points")
              for p in panels}
    assert len(tables) == 1


def test_without_collisions_nothing_more_is_drawn(client):
    svg = client.post("/v1/robots/puma560_standard/render", json={"joints": [PUMA_Q]}).text
    assert _solids(_panels(svg)[0]) == [] and "collision-status" not in svg and "data-colliding" not in svg


def test_shapes_are_drawn_at_the_arms_scale(client):
    """Top view: the base-to-tool vector gives the scale; a sphere obstacle is a disc of its radius at its
    centre, and a vertical capsule a disc too (its segment is seen end on)."""
    robot = catalogue_robot(client, "ur5")
    q = [0.1, -1.2, 1.0, 0.3, 1.5, 0.2]
    collisions = {"self": False, "obstacles": [
        {"name": "ball", "sphere": {"center": [0.3, 0.2, 0.1], "radius": 0.05}},
        {"name": "pole", "capsule": {"from": [-0.3, 0.1, 0.0], "to": [-0.3, 0.1, 0.8], "radius": 0.04}}]}
    svg = client.post("/v1/robots/ur5/render", json={"joints": [q], "view": "top", "collisions": collisions}).text
    panel = _panels(svg)[0]
    points = panel.find(f"{SVG}polyline").get("points").split()
    chain = np.array([[float(v) for v in pair.split(",")] for pair in points])
    base = robot.world_T_base[:3, 3]
    tool = forward_kinematics(robot, np.array(q))[:3, 3] - base
    drawn = chain[-1] - chain[0]
    scale = drawn[0] / tool[0]
    for name, centre, radius in (("ball", [0.3, 0.2, 0.1], 0.05), ("pole", [-0.3, 0.1, 0.0], 0.04)):
        disc = next(e for e in _solids(panel) if e.get("data-name") == name)
        assert disc.tag == f"{SVG}circle"
        at = np.array([float(disc.get("cx")), float(disc.get("cy"))]) - chain[0]
        expected = scale * np.array([centre[0] - base[0], -(centre[1] - base[1])])
        np.testing.assert_allclose(at, expected, atol=0.02)
        np.testing.assert_allclose(float(disc.get("r")), scale * radius, atol=0.01)


def test_a_capsule_seen_side_on_is_a_stadium_of_its_radius(client):
    collisions = {"self": False, "obstacles": [
        {"name": "bar", "capsule": {"from": [0.2, -0.3, 0.4], "to": [0.6, -0.3, 0.4], "radius": 0.05}}]}
    svg = client.post("/v1/robots/ur5/render", json={"joints": [[0.0] * 6], "view": "front",
                                                    "collisions": collisions}).text
    path = next(e for e in _solids(_panels(svg)[0]) if e.get("data-name") == "bar")
    numbers = [float(v) for v in re.findall(r"-?\d+(?:\.\d+)?", path.get("d"))]
    # M a L b A r,r 0 0 0 c L d A r,r 0 0 0 a Z: two sides 2r apart, joined by half circles of radius r
    a, b, r, c, d = numbers[0:2], numbers[2:4], numbers[4], numbers[9:11], numbers[11:13]
    assert a[1] == pytest.approx(b[1]) and c[1] == pytest.approx(d[1])  # horizontal in the front view
    assert abs(a[1] - d[1]) == pytest.approx(2 * r, abs=0.02)
    assert abs(b[0] - a[0]) == pytest.approx(abs(c[0] - d[0]), abs=0.02)


def test_the_ik_picture_marks_what_each_answer_says_collides(client):
    body, answer = _puma_ik(client)
    svg = client.post("/v1/robots/puma560_standard/ik", json=body, headers={"Accept": "image/svg+xml"}).text
    panels = _panels(svg)
    solutions = answer["solutions"] + answer["rejected"]
    assert len(panels) == len(solutions) == 8  # the PUMA has no whole-turn equivalents within its limits here
    for panel, solution in zip(panels, solutions):
        assert _marked(panel) == {name for pair in solution["collisions"] for name in (pair["a"], pair["b"])}
        assert panel.get("data-colliding") == str(bool(solution["collisions"])).lower()
    colliding = sum(bool(s["collisions"]) for s in answer["rejected"])
    assert f"{len(answer['rejected'])} rejected (" in svg and f"{colliding} colliding)" in svg
    # the viewer's question: which survive once the table is there; without obstacles more of them do
    assert len(answer["solutions"]) == 1
    _, unobstructed = _puma_ik(client, collisions={"margin": 0.005})
    assert len(unobstructed["solutions"]) > len(answer["solutions"])


def test_bad_collisions_in_a_render_request_are_422_at_the_field(client):
    render = "/v1/robots/puma560_standard/render"
    assert_problem(client.post(render, json={"joints": [PUMA_Q], "collisions": {"obstacles": [{"name": "x"}]}}),
                   422, loc=["body", "collisions", "obstacles", 0])
    assert_problem(client.post(render, json={"joints": [PUMA_Q], "collisions": {"margin": -1}}), 422,
                   loc=["body", "collisions", "margin"])
    box = {"name": "flat", "box": {"center": [0, 0, 0], "size": [1, 0, 1]}}
    assert_problem(client.post(render, json={"joints": [PUMA_Q], "collisions": {"obstacles": [box]}}), 422,
                   loc=["body", "collisions", "obstacles", 0])
    assert_problem(client.post(render, json={"joints": [PUMA_Q], "collisions": {"ignore": [[0, 9]]}}), 422,
                   loc=["body", "collisions", "ignore", 0, 1])
    # a robot without link shapes cannot be checked: said at the field that asked for it
    robot = {"convention": "standard", "joints": [{"a": 1.0}, {"a": 0.5}]}
    assert_problem(client.post("/v1/render", json={"robot": robot, "joints": [[0.1, 0.2]], "collisions": {}}),
                   422, loc=["body", "collisions"], match="carries no collision shapes")


def test_inline_render_draws_the_described_shapes(client):
    robot = {"convention": "standard", "joints": [{"a": 1.0}, {"a": 0.5}],
             "collision": [{"link": 1, "capsule": {"from": [-1, 0, 0], "to": [0, 0, 0], "radius": 0.05}},
                           {"link": 2, "sphere": {"center": [0, 0, 0], "radius": 0.1}}]}
    wall = {"name": "wall", "box": {"center": [1.4, 0, 0], "size": [0.1, 2, 1]}}
    svg = client.post("/v1/render", json={"robot": robot, "joints": [[0.0, 0.0], [1.0, 0.5]], "view": "top",
                                          "collisions": {"obstacles": [wall]}}).text
    stretched, folded = _panels(svg)
    assert _marked(stretched) == {"link 2", "wall"} and _marked(folded) == set()
    assert [e.get("data-kind") for e in _solids(stretched)] == ["box", "capsule", "sphere"]


def test_a_picture_of_too_many_shapes_is_413_before_drawing(client):
    from service.api.budget import MAX_PICTURE_SHAPES

    balls = [{"name": f"ball {i}", "sphere": {"center": [1.0, 0.1 * i, 0.0], "radius": 0.01}} for i in range(100)]
    body = {"joints": [PUMA_Q] * 256, "collisions": {"obstacles": balls}}  # 256 × (100 + the PUMA's shapes)
    shapes = len(client.get("/v1/robots/puma560_standard").json()["collision"])
    assert 256 * (100 + shapes) > MAX_PICTURE_SHAPES, "the body must ask for more shapes than the cap"
    assert_problem(client.post("/v1/robots/puma560_standard/render", json=body), 413, match="shapes")
    assert client.post("/v1/robots/puma560_standard/render",
                       json={**body, "joints": [PUMA_Q] * 8}).status_code == 200
