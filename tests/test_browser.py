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


def test_viewer_draws_every_ik_solution_of_the_ur5(browser, base_url):
    import numpy as np

    browser.clear()
    browser.navigate(f"{base_url}/viewer")
    browser.wait_for("Number(document.querySelector('#robot').dataset.loaded || 0) > 0")
    # choose the UR5 as a user does: pick the option, which fires "change"
    browser.evaluate("(() => { const s = document.querySelector('#robot'); s.value = 'ur5';"
                     " s.dispatchEvent(new Event('change')); })()")
    browser.wait_for("document.querySelectorAll('#joints input[type=range]').length === 6"
                     " && document.querySelector('#current-picture svg') !== null")
    # type each joint into its number box, then take the pose as the target and solve
    for index, value in enumerate(UR5_Q_DEG):
        browser.evaluate(f"(() => {{ const box = document.querySelector('#joints input[type=number][data-joint=\"{index}\"]');"
                         f" box.value = '{value}'; box.dispatchEvent(new Event('input')); }})()")
    sliders = browser.evaluate("[...document.querySelectorAll('#joints input[type=range]')].map(r => Number(r.value))")
    assert sliders == UR5_Q_DEG  # the number boxes moved their sliders
    browser.evaluate("new Promise(r => setTimeout(r, 600))")  # the redraw after the last joint is debounced
    browser.wait_for("document.querySelector('#tool-pose').textContent !== ''")
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
