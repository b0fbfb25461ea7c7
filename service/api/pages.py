"""Pages for people: the landing page, the API docs (Swagger UI, ReDoc) and the viewer, all served offline.

The docs' JavaScript and CSS come from the ``fastapi-offline`` package, which ships the Swagger UI and
ReDoc distribution bundles; they are served from ``/static/docs`` so that a robot-cell network without
internet still gets working docs. The landing page and the viewer are static files of this package
(``service/api/static``). None of these routes is in the OpenAPI document, and none is behind the API key:
the viewer sends the key the user types, through the public ``/v1`` API only.
"""

from __future__ import annotations

from pathlib import Path

import fastapi_offline
from fastapi import FastAPI, Request
from fastapi.openapi.docs import get_redoc_html, get_swagger_ui_html, get_swagger_ui_oauth2_redirect_html
from fastapi.responses import FileResponse, HTMLResponse
from fastapi.staticfiles import StaticFiles

#: The Swagger UI and ReDoc bundles (swagger-ui-bundle.js, swagger-ui.css, redoc.standalone.js, favicon.png).
DOCS_ASSETS_DIR = Path(fastapi_offline.__file__).resolve().parent / "static"
#: The landing page, the viewer and their scripts.
PAGES_DIR = Path(__file__).resolve().parent / "static"
DOCS_ASSETS_URL = "/static/docs"
#: Pages may load only what the service serves: ReDoc's sidebar links a logo from its makers' CDN, which a
#: browser on an offline network would try (and fail) to fetch. Inline script and style are the docs' own
#: set-up; ReDoc runs its search index in a blob: worker.
PAGE_POLICY = ("default-src 'self'; img-src 'self' data:; style-src 'self' 'unsafe-inline'; "
               "script-src 'self' 'unsafe-inline'; worker-src 'self' blob:; connect-src 'self'; "
               "font-src 'self' data:; frame-ancestors 'self'; base-uri 'self'")
PAGES_URL = "/static/pages"


def install_pages(app: FastAPI) -> None:
    """Add ``/``, ``/docs``, ``/redoc`` and ``/viewer`` to ``app`` (built with ``docs_url=None, redoc_url=None``)."""
    app.mount(DOCS_ASSETS_URL, StaticFiles(directory=DOCS_ASSETS_DIR), name="docs-assets")
    app.mount(PAGES_URL, StaticFiles(directory=PAGES_DIR), name="pages")
    favicon = f"{DOCS_ASSETS_URL}/favicon.png"

    @app.get("/", include_in_schema=False)
    def landing() -> FileResponse:
        return FileResponse(PAGES_DIR / "index.html", media_type="text/html", headers=_POLICY)

    @app.get("/viewer", include_in_schema=False)
    def viewer() -> FileResponse:
        return FileResponse(PAGES_DIR / "viewer.html", media_type="text/html", headers=_POLICY)

    @app.get("/docs", include_in_schema=False)
    def swagger_ui(request: Request) -> HTMLResponse:
        root = request.scope.get("root_path", "")
        return _with_policy(get_swagger_ui_html(
            openapi_url=f"{root}{app.openapi_url}", title=f"{app.title}: Swagger UI",
            oauth2_redirect_url=f"{root}/docs/oauth2-redirect",
            swagger_js_url=f"{root}{DOCS_ASSETS_URL}/swagger-ui-bundle.js",
            swagger_css_url=f"{root}{DOCS_ASSETS_URL}/swagger-ui.css",
            swagger_favicon_url=f"{root}{favicon}",
            # no call to the public validator service from an offline network
            swagger_ui_parameters={"validatorUrl": None, "tryItOutEnabled": True, "displayRequestDuration": True}))

    @app.get("/docs/oauth2-redirect", include_in_schema=False)
    def swagger_ui_redirect() -> HTMLResponse:
        return get_swagger_ui_oauth2_redirect_html()

    @app.get("/redoc", include_in_schema=False)
    def redoc(request: Request) -> HTMLResponse:
        root = request.scope.get("root_path", "")
        return _with_policy(get_redoc_html(openapi_url=f"{root}{app.openapi_url}", title=f"{app.title}: ReDoc",
                              redoc_js_url=f"{root}{DOCS_ASSETS_URL}/redoc.standalone.js",
                              redoc_favicon_url=f"{root}{favicon}", with_google_fonts=False))


_POLICY = {"Content-Security-Policy": PAGE_POLICY}


def _with_policy(page: HTMLResponse) -> HTMLResponse:
    page.headers.update(_POLICY)
    return page
