"""Every Python snippet of README.md and docs/, with what the page says
about it (issue 22: every snippet a reader copies runs in the suite).

A snippet is a ``.. code-block:: python`` of a reStructuredText page or a
fenced ``python`` block of a Markdown page.  Comments just above it (rst:
``.. snippet: WORDS``, Markdown: ``<!-- snippet: WORDS -->``; invisible in
the built pages) say how the suite runs it; without one it runs as it is,
as a script in an empty folder:

``needs NAME...``
    run after the setups NAME (files the page tells the reader to make,
    see ``tests/docs/test_snippets.py``);
``continues``
    the page's previous snippet and this one run as one script;
``prints TEXT``
    its standard output is TEXT (stripped);
``fragment REASON``
    part of a bigger program (names defined elsewhere): only compiled;
``not-run REASON``
    needs what a test cannot have (hardware, a real machine): only
    compiled; the page says so in its text too;
``tested-by FILE::TEST``
    run by that test, which reads it from this page.
"""

from __future__ import annotations

import re
import textwrap
from dataclasses import dataclass, field
from pathlib import Path

KINDS = ("needs", "continues", "prints", "fragment", "not-run", "tested-by")

_RST_MARK = re.compile(r"^\.\. snippet: (\S+)\s*(.*)$")
_MD_MARK = re.compile(r"^<!-- snippet: (\S+)\s*(.*?)\s*-->$")


@dataclass
class Snippet:
    page: Path
    line: int                   # of the directive or the fence, from 1
    code: str
    marks: dict[str, str] = field(default_factory=dict)

    @property
    def id(self) -> str:
        return f"{self.page.name}:{self.line}"


def _marks(lines: list[str], start: int, pattern: re.Pattern[str],
           where: str) -> dict[str, str]:
    """The snippet comments just above line ``start`` (blank lines
    between are allowed)."""
    marks: dict[str, str] = {}
    k = start - 1
    while k >= 0 and not lines[k].strip():
        k -= 1
    while k >= 0:
        if not lines[k].strip():
            k -= 1                      # blank lines between marks
            continue
        found = pattern.match(lines[k].strip())
        if not found:
            break
        kind, text = found.group(1), found.group(2).strip()
        if kind not in KINDS:
            raise ValueError(f"{where}:{k + 1}: unknown snippet mark "
                             f"{kind!r} (one of {', '.join(KINDS)})")
        marks[kind] = text
        k -= 1
    return marks


def rst_snippets(page: Path) -> list[Snippet]:
    lines = page.read_text(encoding="utf-8").splitlines()
    found = []
    i = 0
    while i < len(lines):
        if lines[i].strip() != ".. code-block:: python":
            i += 1
            continue
        start = i
        i += 1
        while i < len(lines) and lines[i].strip().startswith(":"):
            i += 1                      # the directive's options
        body = []
        while i < len(lines) and (not lines[i].strip()
                                  or lines[i].startswith(" ")):
            body.append(lines[i])
            i += 1
        code = textwrap.dedent("\n".join(body)).strip() + "\n"
        found.append(Snippet(page, start + 1, code,
                             _marks(lines, start, _RST_MARK, str(page))))
    return found


def md_snippets(page: Path) -> list[Snippet]:
    lines = page.read_text(encoding="utf-8").splitlines()
    found = []
    i = 0
    while i < len(lines):
        if lines[i].strip() != "```python":
            i += 1
            continue
        start = i
        i += 1
        body = []
        while i < len(lines) and lines[i].strip() != "```":
            body.append(lines[i])
            i += 1
        code = textwrap.dedent("\n".join(body)).strip() + "\n"
        found.append(Snippet(page, start + 1, code,
                             _marks(lines, start, _MD_MARK, str(page))))
    return found


def pages(repo: Path) -> list[Path]:
    """README.md and every page of docs/ (not the generated docs/comp/)."""
    return ([repo / "README.md"] + sorted((repo / "docs").glob("*.rst"))
            + sorted((repo / "docs").glob("*.md")))


def snippets(repo: Path) -> list[Snippet]:
    found: list[Snippet] = []
    for page in pages(repo):
        found += (md_snippets(page) if page.suffix == ".md"
                  else rst_snippets(page))
    return found


def unmarked_python_blocks(page: Path) -> list[int]:
    """Lines of Python code blocks the collector would not see: another
    spelling of the directive (``code:: python``, ``sourcecode``, options
    on the directive line) or of the fence (``py``, ``python3``)."""
    lines = page.read_text(encoding="utf-8").splitlines()
    odd = re.compile(r"^(\.\. (code|sourcecode|code-block)::\s*(py|python3?)"
                     r"\b.*|```\s*(py|python3?)\b.*)$")
    ok = {".. code-block:: python", "```python"}
    return [n + 1 for n, line in enumerate(lines)
            if odd.match(line.strip()) and line.strip() not in ok]
