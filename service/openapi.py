"""Export the OpenAPI document: ``python -m service.openapi`` rewrites ``openapi/openapi.json``.

``--check`` exits non-zero when the committed file differs from the app's spec.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from .api.app import create_app
from .config import Settings

SPEC_PATH = Path(__file__).resolve().parent.parent / "openapi" / "openapi.json"


def current_spec() -> dict:
    """The spec the app serves, independent of the environment's settings."""
    return create_app(Settings(_env_file=None)).openapi()


def render(spec: dict) -> str:
    return json.dumps(spec, indent=2, ensure_ascii=False, sort_keys=False) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--check", action="store_true", help="only compare; exit 1 when the file is stale")
    args = parser.parse_args(argv)
    text = render(current_spec())
    if args.check:
        if not SPEC_PATH.exists() or SPEC_PATH.read_text(encoding="utf-8") != text:
            print(f"{SPEC_PATH} is out of date: run python -m service.openapi", file=sys.stderr)
            return 1
        return 0
    SPEC_PATH.parent.mkdir(exist_ok=True)
    SPEC_PATH.write_text(text, encoding="utf-8")
    print(f"wrote {SPEC_PATH}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
