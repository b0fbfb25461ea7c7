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
