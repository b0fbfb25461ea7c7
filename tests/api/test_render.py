"""Pictures: the SVG of an arm at joint vectors, and of every IK solution of a target.

Geometry is checked against forward kinematics computed here: in the top view a panel's screen coordinates
are world (x, −y) times one scale shared by every panel, so the base-to-tool vector of each panel must be
the FK tool position (minus the base) times that scale.

``python -m tests.api.test_render`` rewrites the pictures of the README and docs/api-guide.md
(docs/puma560_over_table.svg and docs/puma560_ik_solutions.svg).
"""

from __future__ import annotations

import re
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from service.kinematics import forward_kinematics
from tests.conftest import assert_problem, catalogue_robot
from tests.doc_pages import README, pages, text

SVG = "{http://www.w3.org/2000/svg}"
ROOT = Path(__file__).resolve().parent.parent.parent
README_PICTURE = ROOT / "docs" / "puma560_ik_solutions.svg"
#: docs/api-guide.md's picture: every IK solution of a PUMA 560 target, nearest to the configuration it came from.
README_Q_DEG = [20.0, 60.0, -60.0, 10.0, 35.0, -15.0]
UR5_Q = [0.1, -1.2, 1.0, 0.3, 1.5, 0.2]


def _panels(svg: str) -> list[ET.Element]:
    root = ET.fromstring(svg)
    return [g for g in root.iter(f"{SVG}g") if "configuration" in g.get("class", "").split()]


def _chain(panel: ET.Element) -> np.ndarray:
    points = panel.find(f"{SVG}polyline").get("points")
    return np.array([[float(v) for v in pair.split(",")] for pair in points.split()])


def test_one_panel_per_joint_vector_with_its_limit_status(client):
    rows = [[0.0] * 6, [0.35, 1.05, -1.05, 0.17, 0.61, -0.26], [0.0, 0.0, 1.2, 0.0, 0.0, 0.0]]
    response = client.post("/v1/robots/puma560_standard/render", json={"joints": rows})
    assert response.status_code == 200 and response.headers["content-type"] == "image/svg+xml"
    panels = _panels(response.text)
    assert len(panels) == 3
    # theta3's limits are [-225, 45] deg: 1.2 rad = 68.8 deg is outside
    assert [p.get("data-within-limits") for p in panels] == ["true", "true", "false"]
    status = [p.find(f"{SVG}text[@class='status']").text for p in panels]
    assert status == ["within limits", "within limits", "outside limits: theta3"]
    for panel in panels:
        assert panel.find(f"{SVG}g[@class='base-frame']") is not None
        assert len(panel.find(f"{SVG}g[@class='tool-frame']").findall(f"{SVG}line")) == 3
        assert len(panel.findall(f"{SVG}line[@class='axis']")) == 6  # one segment per joint axis


@pytest.mark.parametrize("robot_id", ["ur5", "puma560_modified", "puma560_khalil", "spong_ex3_5_stanford",
                                      "kinova_jaco2"])  # the last from a URDF (a screw robot)
def test_top_view_is_the_fk_tool_position_at_one_scale(client, robot_id):
    robot = catalogue_robot(client, robot_id)
    rng = np.random.default_rng(7)
    rows = rng.uniform(-1.0, 1.0, size=(4, robot.dof))
    response = client.post(f"/v1/robots/{robot_id}/render", json={"joints": rows.tolist(), "view": "top"})
    scales = []
    for panel, q in zip(_panels(response.text), rows):
        chain = _chain(panel)
        tool = forward_kinematics(robot, q)[:3, 3] - robot.world_T_base[:3, 3]
        drawn = chain[-1] - chain[0]
        np.testing.assert_allclose(drawn[1], -drawn[0] * tool[1] / tool[0], atol=0.05 + 0.01 * abs(drawn[1]))
        scales.append(drawn[0] / tool[0])
    np.testing.assert_allclose(scales, scales[0], rtol=1e-3)


@pytest.mark.parametrize("view", ["iso", "front", "side", "top"])
def test_every_view_draws(client, view):
    response = client.post("/v1/robots/ur5/render", json={"joints": [UR5_Q], "view": view})
    assert ET.fromstring(response.text).get("data-view") == view


def test_the_front_view_is_x_and_z(client):
    robot = catalogue_robot(client, "ur5")
    response = client.post("/v1/robots/ur5/render", json={"joints": [UR5_Q], "view": "front"})
    drawn = np.diff(_chain(_panels(response.text)[0])[[0, -1]], axis=0)[0]
    tool = forward_kinematics(robot, np.array(UR5_Q))[:3, 3]
    np.testing.assert_allclose(drawn[1] / drawn[0], -tool[2] / tool[0], rtol=1e-2)


def test_captions_are_escaped_and_counted(client):
    body = {"joints": [UR5_Q, UR5_Q], "captions": ["<script>x</script>", "two\nlines"], "title": "A & B"}
    svg = client.post("/v1/robots/ur5/render", json=body).text
    assert "<script>" not in svg and "&lt;script&gt;" in svg and "A &amp; B" in svg
    second = [t.text for t in _panels(svg)[1].findall(f"{SVG}text[@class='caption']")]
    assert second == ["two", "lines"]
    assert_problem(client.post("/v1/robots/ur5/render", json={"joints": [UR5_Q], "captions": ["a", "b"]}), 422,
                   loc=["body", "captions"], match="expected 1 captions")


def test_bad_render_requests_are_422(client):
    assert_problem(client.post("/v1/robots/ur5/render", json={"joints": [UR5_Q], "view": "back"}), 422,
                   loc=["body", "view"])
    assert_problem(client.post("/v1/robots/ur5/render", json={"joints": [[0.0, 0.0]]}), 422, loc=["body", "joints"])
    assert_problem(client.post("/v1/robots/ur5/render", json={"joints": []}), 422, loc=["body", "joints"])
    assert_problem(client.post("/v1/robots/ur-5/render", json={"joints": [UR5_Q]}), 404, match="'ur5'")


def test_inline_render(client):
    robot = {"convention": "standard", "joints": [{"a": 1.0}, {"a": 0.5}]}
    response = client.post("/v1/render", json={"robot": robot, "joints": [[0.5, -0.7]], "view": "top"})
    chain = _chain(_panels(response.text)[0])
    drawn = chain[-1] - chain[0]
    expected = [np.cos(0.5) + 0.5 * np.cos(-0.2), np.sin(0.5) + 0.5 * np.sin(-0.2)]
    np.testing.assert_allclose(-drawn[1] / drawn[0], expected[1] / expected[0], rtol=1e-3)


def test_ik_answers_with_the_picture_of_every_distinct_solution(client):
    robot = catalogue_robot(client, "ur5")
    matrix = forward_kinematics(robot, np.array(UR5_Q)).tolist()
    answer = client.post("/v1/robots/ur5/ik", json={"target": {"matrix": matrix}, "reference": UR5_Q}).json()
    picture = client.post("/v1/robots/ur5/ik", json={"target": {"matrix": matrix}, "reference": UR5_Q},
                          headers={"Accept": "image/svg+xml"})
    assert picture.headers["content-type"] == "image/svg+xml"
    panels = _panels(picture.text)
    wrapped = {tuple(np.round(np.angle(np.exp(1j * np.array(s["joints"]))), 6)) for s in answer["solutions"]}
    assert len(panels) == len(wrapped) == 8  # 512 solutions, eight arm configurations
    counts = [int(re.match(r"(\d+) solutions", t.text).group(1))
              for p in panels for t in p.findall(f"{SVG}text[@class='caption']") if "solutions" in t.text]
    assert sum(counts) == len(answer["solutions"]) == 512
    first = [t.text for t in panels[0].findall(f"{SVG}text[@class='caption']")]
    assert first[0] == "#1 (nearest the reference)"
    labels = answer["solutions"][0]["branch"]
    assert first[1] == " · ".join(f"{k} {v}" for k, v in labels.items())


@pytest.mark.parametrize("accept, picture", [
    ("image/svg+xml", True),
    ("image/svg+xml, application/json", True),  # equal weights: the one listed first
    ("application/json, image/svg+xml", False),
    ("image/svg+xml;q=0.1, application/json", False),  # a probe got the picture here
    ("application/json;q=0.5, image/svg+xml", True),
    ("image/svg+xml;q=0.9, */*;q=0.8", True),
    ("*/*", False),
    ("image/svg+xml;q=0", False),
    ("image/svg+xml;q=oops, application/json", False),
    ("text/html, image/webp", False),
])
def test_the_ik_picture_follows_the_accept_weights(client, accept, picture):
    robot = catalogue_robot(client, "puma560_standard")
    body = {"target": {"matrix": forward_kinematics(robot, np.radians(README_Q_DEG)).tolist()}}
    response = client.post("/v1/robots/puma560_standard/ik", json=body, headers={"Accept": accept})
    assert response.status_code == 200
    assert response.headers["content-type"] == ("image/svg+xml" if picture else "application/json")


def test_ik_render_query_and_json_by_default(client):
    robot = catalogue_robot(client, "puma560_standard")
    matrix = forward_kinematics(robot, np.radians(README_Q_DEG)).tolist()
    body = {"target": {"matrix": matrix}}
    assert client.post("/v1/robots/puma560_standard/ik", json=body).headers["content-type"] == "application/json"
    assert client.post("/v1/robots/puma560_standard/ik", json=body,
                       headers={"Accept": "application/json, image/svg+xml"}).headers["content-type"] \
        == "application/json"
    side = client.post("/v1/robots/puma560_standard/ik?render=side", json=body)
    assert ET.fromstring(side.text).get("data-view") == "side"
    answer = client.post("/v1/robots/puma560_standard/ik", json=body).json()
    statuses = [p.get("data-within-limits") for p in _panels(side.text)]
    assert statuses.count("true") == len({tuple(np.round(np.angle(np.exp(1j * np.array(s["joints"]))), 6))
                                          for s in answer["solutions"]})
    assert statuses.count("false") == len(answer["rejected"])
    assert_problem(client.post("/v1/robots/puma560_standard/ik?render=back", json=body), 422,
                   loc=["query", "render"])


def test_an_unreachable_target_is_a_picture_that_says_so(client):
    body = {"target": {"position": [9.0, 9.0, 9.0], "orientation": {"type": "rpy", "angles": [0, 0, 0]}}}
    svg = client.post("/v1/robots/ur5/ik", json=body, headers={"Accept": "image/svg+xml"}).text
    assert _panels(svg) == [] and "unreachable, 0 solutions" in svg


def _readme_picture(client) -> str:
    robot = catalogue_robot(client, "puma560_standard")
    matrix = forward_kinematics(robot, np.radians(README_Q_DEG)).tolist()
    return client.post("/v1/robots/puma560_standard/ik", headers={"Accept": "image/svg+xml"},
                       json={"target": {"matrix": matrix}, "reference": README_Q_DEG, "angle_unit": "deg"}).text


COLLISION_PICTURE = ROOT / "docs" / "puma560_over_table.svg"


def _collision_picture(client) -> str:
    """The spec's PUMA over a table, beside a post (service/api/examples.py): every solution, colliding ones red."""
    from service.api.examples import _PUMA_OVER_TABLE

    return client.post("/v1/robots/puma560_standard/ik", headers={"Accept": "image/svg+xml"},
                       json=_PUMA_OVER_TABLE).text


PICTURES = {"puma560_ik_solutions.svg": (README_PICTURE, _readme_picture),
            "puma560_over_table.svg": (COLLISION_PICTURE, _collision_picture)}


def _numbers_and_text(svg: str) -> tuple[list[float], str]:
    pattern = r"-?\d+(?:\.\d+)?(?:e-?\d+)?"
    return [float(n) for n in re.findall(pattern, svg)], re.sub(pattern, "#", svg)


@pytest.mark.parametrize("name", sorted(PICTURES))
def test_the_readme_pictures_are_what_the_service_draws(client, name):
    """Regenerated and compared: the same text, and every coordinate within 0.02 px (rounding across numpy
    builds can move the last printed digit)."""
    path, draw = PICTURES[name]
    committed, drawn = _numbers_and_text(path.read_text(encoding="utf-8")), _numbers_and_text(draw(client))
    assert committed[1] == drawn[1], f"docs/{name} is stale: python -m tests.api.test_render"
    np.testing.assert_allclose(committed[0], drawn[0], atol=0.02)
    shown_by = [page for page in pages() if f"]({'docs/' if page == README else ''}{name})" in text(page)]
    assert shown_by, f"neither the README nor a docs/ page shows docs/{name}"


if __name__ == "__main__":
    from fastapi.testclient import TestClient

    from service.api.app import create_app

    with TestClient(create_app()) as test_client:
        README_PICTURE.parent.mkdir(exist_ok=True)
        for path, draw in PICTURES.values():
            path.write_text(draw(test_client), encoding="utf-8")
            print(f"wrote {path}", file=sys.stderr)
