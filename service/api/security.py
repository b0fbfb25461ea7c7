"""The optional API key: when ``KIN_API_KEY`` is set, every ``/v1`` request needs ``X-API-Key``.

The check runs in the service's ASGI layer (:class:`~.gate.RequestGate`), before the body is read or parsed: an
unauthenticated client gets 401 whatever it sent. Health (``/healthz``, ``/readyz``) and ``/metrics`` stay open for
probes and scrapers. The key is compared with :func:`hmac.compare_digest`, in time independent of where the first
differing byte is.
"""

from __future__ import annotations

import hmac

API_KEY_HEADER = "X-API-Key"
#: Name of the security scheme in the OpenAPI document.
API_KEY_SCHEME = "ApiKeyHeader"
PROTECTED_PREFIX = "/v1"


def is_protected(path: str) -> bool:
    return path == PROTECTED_PREFIX or path.startswith(PROTECTED_PREFIX + "/")


class ApiKeyCheck:
    """The configured key, and why a request's ``X-API-Key`` (as sent: latin-1 octets) does not pass it."""

    def __init__(self, api_key: str) -> None:
        if not api_key:
            raise ValueError("an empty API key would match every client")
        self._expected = api_key.encode("utf-8")

    def refusal(self, provided: bytes) -> str | None:
        """None when ``provided`` is the key, else the 401's detail. Bytes, never str, are compared, so that no
        decoding error can leak timing."""
        if provided and hmac.compare_digest(provided, self._expected):
            return None
        return ("This service requires an API key: send it in the X-API-Key header." if not provided
                else "The API key in X-API-Key is not valid.")
