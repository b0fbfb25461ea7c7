"""The pages people see, in a real browser with no network: docs, ReDoc, the landing page and the viewer.

A live ``python -m service`` and a headless Chromium (tests/browser.py) whose every host name but 127.0.0.1
resolves to nothing. Each test also asserts that the page fetched nothing from anywhere but the service.
Screenshots are saved under ``test-artifacts/`` (``KIN_TEST_ARTIFACTS`` overrides it) and their paths printed.
"""

from __future__ import annotations

import json

import pytest

from service.openapi import current_spec
from tests.browser import Browser, chromium_path
from tests.live import serve


@pytest.fixture(scope="module")
def base_url():
    chromium_path()  # skip (or fail under CI) before starting anything
    with serve() as url:
        yield url


@pytest.fixture(scope="module")
def browser(base_url):
    with Browser() as chromium:
        yield chromium


def _operation_ids() -> set[str]:
    return {operation["operationId"] for operations in current_spec()["paths"].values()
            for operation in operations.values()}


def test_swagger_ui_renders_every_operation_offline(browser, base_url):
    browser.clear()
    browser.navigate(f"{base_url}/docs")
    expected = _operation_ids()
    # Swagger UI gives each operation block the id operations-<tag>-<operationId>
    browser.wait_for(f"document.querySelectorAll('.opblock').length >= {len(expected)}")
    rendered = set(browser.evaluate(
        "[...document.querySelectorAll('.opblock')].map(b => b.id.split('-').slice(2).join('-'))"))
    assert rendered == expected
    title = browser.evaluate("document.querySelector('.info .title')?.textContent || ''")
    assert "Robot kinematics service" in title
    browser.screenshot("docs.png")
    assert browser.foreign_requests(base_url) == []
    assert f"{base_url}/static/docs/swagger-ui-bundle.js" in browser.requests


def test_swagger_try_it_out_runs_the_prefilled_ik_example(browser, base_url):
    """The issue's first complaint: "Try it out" on IK pre-filled an invalid body and answered 422."""
    browser.clear()
    browser.navigate(f"{base_url}/docs?try-it-out")  # a new document, so the load event fires again
    block = "document.querySelector('#operations-inverse_kinematics-inverse_kinematics')"
    browser.wait_for(f"{block} !== null")
    browser.evaluate(f"(() => {{ const b = {block}; if (!b.classList.contains('is-open'))"
                     " b.querySelector('.opblock-summary-control').click(); })()")
    browser.wait_for(f"{block}.querySelector('button.execute') !== null")
    prefilled = browser.wait_for(f"{block}.querySelector('textarea.body-param__text')?.value")
    assert json.loads(prefilled)["target"]["orientation"]["type"] == "quaternion"
    robot_id = browser.evaluate(f"{block}.querySelector('tr[data-param-name=robot_id] input')?.value")
    assert robot_id == "ur5"
    browser.evaluate(f"{block}.querySelector('button.execute').click()")
    status = browser.wait_for(f"{block}.querySelector('.live-responses-table .response .response-col_status')"
                              "?.textContent.trim()", timeout=60)
    assert status.startswith("200"), status
    browser.screenshot("docs-try-it-out.png")
    assert browser.foreign_requests(base_url) == []


def test_redoc_renders_every_operation_offline(browser, base_url):
    browser.clear()
    browser.navigate(f"{base_url}/redoc")
    expected = _operation_ids()
    sections = browser.wait_for(
        "(() => { const s = [...document.querySelectorAll('[data-section-id^=\"operation/\"]')]"
        ".map(e => e.getAttribute('data-section-id').slice('operation/'.length));"
        f" return s.length >= {len(expected)} ? s : null; }})()")
    assert set(sections) == expected
    browser.screenshot("redoc.png")
    assert browser.foreign_requests(base_url) == []


def test_landing_page_links_docs_catalogue_and_viewer(browser, base_url):
    browser.clear()
    browser.navigate(f"{base_url}/")
    links = browser.evaluate("Object.fromEntries([...document.querySelectorAll('a[id^=link-]')]"
                             ".map(a => [a.id, a.getAttribute('href')]))")
    assert links == {"link-docs": "/docs", "link-redoc": "/redoc", "link-catalogue": "/v1/robots",
                     "link-viewer": "/viewer", "link-spec": "/openapi.json"}
    browser.navigate(f"{base_url}/v1/robots")
    listed = json.loads(browser.evaluate("document.body.innerText"))
    assert "ur5" in {robot["id"] for robot in listed["robots"]}
    assert browser.foreign_requests(base_url) == []


# --------------------------------------------------------------------------- the viewer

UR5_Q_DEG = [10.0, -60.0, 70.0, 20.0, 80.0, 15.0]


def _post(url: str, body: dict) -> dict:
    import urllib.request

    request = urllib.request.Request(url, data=json.dumps(body).encode(), method="POST",
                                     headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(request, timeout=30) as answer:
        return json.load(answer)


def _viewer_with_the_ur5_at(browser, base_url, joints_deg) -> None:
    """Open the viewer, choose the UR5 and type each joint, as a user does; wait for the redraw."""
    browser.clear()
    browser.navigate(f"{base_url}/viewer")
    browser.wait_for("Number(document.querySelector('#robot').dataset.loaded || 0) > 0")
    # choose the UR5 as a user does: pick the option, which fires "change"
    browser.evaluate("(() => { const s = document.querySelector('#robot'); s.value = 'ur5';"
                     " s.dispatchEvent(new Event('change')); })()")
    browser.wait_for("document.querySelectorAll('#joints input[type=range]').length === 6"
                     " && document.querySelector('#current-picture svg') !== null")
    # type each joint into its number box, then take the pose as the target and solve
    for index, value in enumerate(joints_deg):
        browser.evaluate(f"(() => {{ const box = document.querySelector('#joints input[type=number][data-joint=\"{index}\"]');"
                         f" box.value = '{value}'; box.dispatchEvent(new Event('input')); }})()")
    sliders = browser.evaluate("[...document.querySelectorAll('#joints input[type=range]')].map(r => Number(r.value))")
    assert sliders == joints_deg  # the number boxes moved their sliders
    browser.evaluate("new Promise(r => setTimeout(r, 600))")  # the redraw after the last joint is debounced
    browser.wait_for("document.querySelector('#tool-pose').textContent !== ''")


def test_viewer_draws_every_ik_solution_of_the_ur5(browser, base_url):
    import numpy as np

    _viewer_with_the_ur5_at(browser, base_url, UR5_Q_DEG)
    browser.evaluate("document.querySelector('#use-current').click()")
    browser.evaluate("document.querySelector('#solve').click()")
    count = int(browser.wait_for("document.querySelector('#summary').dataset.count", timeout=60))

    target = json.loads(browser.evaluate("document.querySelector('#target').value"))
    answer = _post(f"{base_url}/v1/robots/ur5/ik", {"target": target, "reference": UR5_Q_DEG, "angle_unit": "deg",
                                                     "filter_limits": False})
    assert count == len(answer["solutions"]) == 512
    # every solution is listed, nearest first, and marked within or outside the limits
    rows = browser.evaluate("[...document.querySelectorAll('#solution-table tbody tr')]"
                            ".map(r => [r.className, r.children[1].textContent])")
    assert len(rows) == len(answer["solutions"])
    for (css, joints), solution in zip(rows, answer["solutions"]):
        assert css == ("within" if solution["within_limits"] else "outside")
        np.testing.assert_allclose([float(v) for v in joints.split(", ")], solution["joints"], atol=0.006)
    # every solution is drawn: one panel per arm configuration, whose captions add up to the API's count
    distinct = {tuple(np.round(np.angle(np.exp(1j * np.radians(s["joints"]))), 6)) for s in answer["solutions"]}
    panels = browser.evaluate("[...document.querySelectorAll('#solutions g.configuration')].map(g => "
                              "[...g.querySelectorAll('text.caption')].map(t => t.textContent))")
    assert len(panels) == len(distinct) == 8
    represented = 0
    for panel in panels:
        multiples = [int(line.split()[0]) for line in panel if line.endswith("(whole turns of the joints)")]
        represented += multiples[0] if multiples else 1
    assert represented == len(answer["solutions"])
    assert panels[0][0] == "#1 (nearest the reference)"
    np.testing.assert_allclose(answer["solutions"][0]["joints"], UR5_Q_DEG, atol=1e-6)
    assert browser.evaluate("document.querySelector('#error').textContent") == ""
    browser.screenshot("viewer-ur5.png")
    assert browser.foreign_requests(base_url) == []
    assert browser.console_errors == []


#: A table under the UR5's two elbow-down configurations whose elbow dips below the base (z ≈ −0.14 m), clear of
#: the other six (their elbows at z ≥ 0.04 m, link radius 0.075 m): the box's top is at z = −0.10 m.
UR5_TABLE = {"name": "table", "center": [-0.35, -0.15, -0.15], "size": [0.5, 0.5, 0.1]}


def _marked(svg_selector: str) -> str:
    """JS: for each panel of the picture, the names of its solids marked colliding."""
    return (f"[...document.querySelectorAll('{svg_selector} g.configuration')].map(g => "
            "[...g.querySelectorAll('.solid.colliding')].map(e => e.dataset.name).sort())")


def test_viewer_draws_link_capsules_and_a_box_added_filters_the_solutions(browser, base_url):
    import numpy as np

    _viewer_with_the_ur5_at(browser, base_url, UR5_Q_DEG)
    shapes = json.loads(browser.evaluate("JSON.stringify(window.kinematicsViewer.state.description.collision)"))
    # the current joints: every link capsule of the UR5 drawn, none colliding, and the clearance said
    drawn = browser.wait_for("(() => { const s = [...document.querySelectorAll('#current-picture .solid.link-shape')]"
                             ".map(e => [Number(e.dataset.link), e.dataset.kind]);"
                             f" return s.length === {len(shapes)} ? s : null; }})()")
    assert sorted(map(tuple, drawn)) == sorted((shape["link"], "capsule") for shape in shapes)
    assert browser.evaluate("document.querySelector('#current-picture .solid.colliding')") is None
    assert browser.evaluate("document.querySelector('#clearance').textContent").startswith("current joints: clear by")

    browser.evaluate("document.querySelector('#use-current').click()")
    browser.evaluate("document.querySelector('#solve').click()")
    assert int(browser.wait_for("document.querySelector('#summary').dataset.count", timeout=60)) == 512
    assert browser.evaluate("document.querySelectorAll('#solutions g.configuration').length") == 8
    assert browser.evaluate("document.querySelectorAll('#solutions .solid.link-shape').length") == 8 * len(shapes)
    asked = browser.evaluate("window.kinematicsViewer.state.lastRequest.collisions")
    assert asked == {"self": True, "margin": 0, "obstacles": []}  # the viewer checks self-collision by default

    # add the table through the form, as a user does: the viewer solves again with it
    for field, value in (("#box-name", UR5_TABLE["name"]), ("#box-center", ", ".join(map(str, UR5_TABLE["center"]))),
                         ("#box-size", ", ".join(map(str, UR5_TABLE["size"])))):
        browser.evaluate(f"document.querySelector('{field}').value = {json.dumps(value)}")
    browser.evaluate("document.querySelector('#add-box').click()")
    browser.wait_for("document.querySelector('#summary').dataset.obstacles === '1'"
                     " && document.querySelector('#summary').dataset.count !== undefined", timeout=60)
    assert browser.evaluate("document.querySelector('#error').textContent") == ""
    assert browser.evaluate("[...document.querySelectorAll('#obstacles li')].map(li => li.dataset.name)") == ["table"]
    request = browser.evaluate("window.kinematicsViewer.state.lastRequest")
    assert request["collisions"]["obstacles"] == [{"name": "table", "box": {"center": UR5_TABLE["center"],
                                                                            "size": UR5_TABLE["size"]}}]

    # the survivors are those the API keeps for the same request, and only they are listed
    answer = _post(f"{base_url}/v1/robots/ur5/ik", request)
    count = int(browser.evaluate("document.querySelector('#summary').dataset.count"))
    assert count == len(answer["solutions"]) == 512 - 2 * 64  # two of eight configurations hit the table
    assert all(not s["collisions"] and s["clearance"] >= 0.0 for s in answer["solutions"])
    colliding = [s for s in answer["rejected"] if s["collisions"]]
    assert len(colliding) == int(browser.evaluate("document.querySelector('#summary').dataset.colliding")) == 2
    rows = browser.evaluate("[...document.querySelectorAll('#solution-table tbody tr')]"
                            ".map(r => [r.children[1].textContent, r.querySelector('td.clearance').textContent])")
    assert len(rows) == count
    for (joints, clearance), solution in zip(rows, answer["solutions"]):
        np.testing.assert_allclose([float(v) for v in joints.split(", ")], solution["joints"], atol=0.006)
        assert float(clearance) == pytest.approx(solution["clearance"], abs=6e-5)
    # the picture: the table in every panel; the two rejected configurations marked, links and table alike
    tables = browser.evaluate("[...document.querySelectorAll('#solutions g.configuration')].map(g => "
                              "g.querySelectorAll('.solid.obstacle[data-name=\"table\"][data-kind=\"box\"]').length)")
    assert tables == [1] * 8
    marked = browser.evaluate(_marked("#solutions"))
    expected = [sorted({name for pair in s["collisions"] for name in (pair["a"], pair["b"])}) for s in colliding]
    assert marked[:6] == [[]] * 6 and sorted(marked[6:]) == sorted(expected)
    assert all("table" in names and len(names) >= 2 for names in expected)
    assert browser.evaluate("[...document.querySelectorAll('#solutions g.configuration.colliding')].length") == 2
    browser.screenshot("viewer-ur5-table.png")

    # render, as the viewer calls it for the current joints, with a colliding configuration: the SVG has the
    # obstacle and the colliding links marked
    q_hit = colliding[0]["joints"]
    browser.evaluate(f"window.kinematicsViewer.setJoints({json.dumps(q_hit)})")
    browser.wait_for("document.querySelector('#current-picture .solid.colliding') !== null")
    current = browser.evaluate(_marked("#current-picture"))
    assert current == [sorted({name for pair in colliding[0]["collisions"] for name in (pair["a"], pair["b"])})]
    assert browser.evaluate("document.querySelector('#clearance').textContent").startswith("current joints collide:")
    svg = browser.evaluate("document.querySelector('#current-picture').innerHTML")
    assert 'data-name="table"' in svg and "solid link-shape colliding" in svg
    browser.screenshot("viewer-ur5-colliding.png")

    # removing the table gives every solution back
    browser.evaluate("document.querySelector('#obstacles li button').click()")
    browser.wait_for("document.querySelector('#summary').dataset.obstacles === '0'"
                     " && document.querySelector('#summary').dataset.count === '512'", timeout=60)
    assert browser.foreign_requests(base_url) == []
    assert browser.console_errors == []
