"""The optional API key: when ``KIN_API_KEY`` is set, every ``/v1`` request needs ``X-API-Key``.

The check is an ASGI middleware, so it runs before the body is read or parsed:
an unauthenticated client gets 401 whatever it sent. Health (``/healthz``,
``/readyz``) and ``/metrics`` stay open for probes and scrapers. The key is
compared with :func:`hmac.compare_digest`, in time independent of where the
first differing byte is.
"""

from __future__ import annotations

import hmac
import json

from starlette.types import ASGIApp, Receive, Scope, Send

from .problems import PROBLEM_MEDIA_TYPE, PROBLEM_TYPE_BASE

API_KEY_HEADER = "X-API-Key"
#: Name of the security scheme in the OpenAPI document.
API_KEY_SCHEME = "ApiKeyHeader"
PROTECTED_PREFIX = "/v1"


def is_protected(path: str) -> bool:
    return path == PROTECTED_PREFIX or path.startswith(PROTECTED_PREFIX + "/")


class ApiKeyMiddleware:
    """Answer 401 problem+json to a ``/v1`` request whose ``X-API-Key`` is missing or wrong."""

    def __init__(self, app: ASGIApp, api_key: str) -> None:
        if not api_key:
            raise ValueError("an empty API key would match every client")
        self.app = app
        self._expected = api_key.encode("utf-8")

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http" or not is_protected(scope.get("path", "")):
            await self.app(scope, receive, send)
            return
        provided = b""
        for name, value in scope.get("headers", ()):
            if name == b"x-api-key":
                provided = value
                break
        # Header values arrive as latin-1 octets; compare bytes, never str, so no decoding error can leak timing.
        if provided and hmac.compare_digest(provided, self._expected):
            await self.app(scope, receive, send)
            return
        detail = ("This service requires an API key: send it in the X-API-Key header." if not provided
                  else "The API key in X-API-Key is not valid.")
        body = json.dumps({"type": PROBLEM_TYPE_BASE + "unauthorized", "title": "Unauthorized", "status": 401,
                           "detail": detail, "instance": scope.get("path", "")}).encode()
        await send({"type": "http.response.start", "status": 401,
                    "headers": [(b"content-type", PROBLEM_MEDIA_TYPE.encode()),
                                (b"content-length", str(len(body)).encode()),
                                (b"www-authenticate", f'ApiKey header="{API_KEY_HEADER}"'.encode())]})
        await send({"type": "http.response.body", "body": body})
