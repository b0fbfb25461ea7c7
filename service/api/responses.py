"""JSON responses encoded with orjson.

orjson writes numpy arrays directly (``OPT_SERIALIZE_NUMPY``), so the column
form of a large batch goes from arrays to bytes without building Python lists,
and it encodes lists and dicts several times faster than the standard library.
"""

from __future__ import annotations

from typing import Any

import orjson
from starlette.responses import JSONResponse

#: Items of a long list encoded per orjson call (see :func:`encoded`).
ENCODING_PIECE = 256
_OPTIONS = orjson.OPT_SERIALIZE_NUMPY


def encoded(content: Any) -> bytes:
    """``content`` as JSON bytes; a long list (alone, or a value of the top dict) a piece per orjson call.

    One orjson call holds the GIL from start to end: the objects form of a 10,000-target answer is tens of
    megabytes, and the server's loop could not answer ``/healthz`` while it was written. Between the calls the
    interpreter hands the GIL to a thread that waits for it. The bytes are the same as one call's.
    """
    if isinstance(content, list) and len(content) > ENCODING_PIECE:
        pieces = (orjson.dumps(content[start:start + ENCODING_PIECE], option=_OPTIONS)[1:-1]
                  for start in range(0, len(content), ENCODING_PIECE))
        return b"[" + b",".join(pieces) + b"]"
    if isinstance(content, dict) and any(isinstance(value, list) and len(value) > ENCODING_PIECE
                                         for value in content.values()):
        return b"{" + b",".join(orjson.dumps(key) + b":" + encoded(value) for key, value in content.items()) + b"}"
    return orjson.dumps(content, option=_OPTIONS)


class FastJSONResponse(JSONResponse):
    """``application/json`` rendered by orjson; numpy arrays and scalars are accepted as they are."""

    def render(self, content: Any) -> bytes:
        return encoded(content)
