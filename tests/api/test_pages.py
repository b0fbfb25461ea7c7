"""The landing page, the docs pages and the viewer: served by the service itself, nothing from a CDN."""

from __future__ import annotations

import re

import pytest
from fastapi.testclient import TestClient

from service.api.app import create_app
from service.config import Settings

PAGES = ["/", "/docs", "/redoc", "/viewer"]


@pytest.mark.parametrize("path", PAGES)
def test_pages_load_only_what_the_service_serves(client, path):
    page = client.get(path)
    assert page.status_code == 200 and page.headers["content-type"].startswith("text/html")
    policy = page.headers["content-security-policy"]
    assert "default-src 'self'" in policy and "img-src 'self' data:" in policy
    referenced = re.findall(r"""(?:src|href)\s*=\s*["']([^"']+)["']""", page.text)
    referenced += re.findall(r"""url:\s*'([^']+)'""", page.text)
    assert referenced, page.text
    for url in referenced:
        assert url.startswith("/") or url.startswith("#"), f"{path} references {url}"
        if url.startswith("/") and not url.startswith("/v1"):
            assert client.get(url).status_code == 200, url


def test_docs_assets_are_the_packaged_bundles(client):
    script = client.get("/static/docs/swagger-ui-bundle.js")
    assert script.status_code == 200 and "SwaggerUIBundle" in script.text[:2000]
    assert client.get("/static/docs/redoc.standalone.js").status_code == 200
    assert client.get("/static/docs/swagger-ui.css").headers["content-type"].startswith("text/css")


def test_pages_are_not_operations_of_the_spec(client):
    paths = client.get("/openapi.json").json()["paths"]
    assert not set(PAGES) & set(paths)
    assert not any(path.startswith("/static") for path in paths)


def test_pages_stay_open_when_the_api_needs_a_key():
    with TestClient(create_app(Settings(api_key="secret"))) as keyed:
        for path in [*PAGES, "/openapi.json", "/static/docs/swagger-ui.css", "/static/pages/viewer.js"]:
            assert keyed.get(path).status_code == 200, path
        assert keyed.get("/v1/robots").status_code == 401
