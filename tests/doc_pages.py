"""The README and the pages under docs/: their sections and fenced code blocks, for the tests that keep them true."""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
DOCS = ROOT / "docs"


def pages() -> list[Path]:
    """The README first, then every Markdown page under docs/, by name."""
    return [README, *sorted(DOCS.glob("*.md"))]


def text(page: Path | str) -> str:
    """A page's text; a bare name such as ``"api-guide.md"`` is a page under docs/."""
    path = page if isinstance(page, Path) else DOCS / page
    return path.read_text(encoding="utf-8")


def section(page: Path | str, heading: str) -> str:
    """The body under ``heading`` (e.g. ``"## Python SDK"``) up to the next heading of the same or a higher level."""
    level = len(heading.split(" ", 1)[0])
    body, in_code = [], False
    for line in text(page).split(f"\n{heading}\n", 1)[1].split("\n"):
        in_code ^= line.startswith("```")
        if not in_code and re.match(rf"#{{1,{level}}} ", line):
            break
        body.append(line)
    return "\n".join(body)


@dataclass(frozen=True)
class Block:
    """One fenced code block: its page, the line of its opening fence (1-based), its language and its body."""

    page: Path
    line: int
    language: str
    body: str

    @property
    def where(self) -> str:
        return f"{self.page.relative_to(ROOT)}:{self.line}"


_FENCE = re.compile(r"^```(\w*)\n(.*?)^```$", re.M | re.S)


def blocks(language: str) -> list[Block]:
    """Every fenced block of ``language`` in the README and docs/ pages, in page order."""
    found = []
    for page in pages():
        content = text(page)
        for match in _FENCE.finditer(content):
            if match.group(1) == language:
                found.append(Block(page, content.count("\n", 0, match.start()) + 1, language, match.group(2)))
    return found
