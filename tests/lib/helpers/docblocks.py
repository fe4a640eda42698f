"""The code blocks of a documentation page, for the tests that run the
examples the page shows (so that documented code cannot rot)."""

from __future__ import annotations

import textwrap
from pathlib import Path


def code_blocks(page: Path, language: str) -> list[str]:
    """The bodies of the ``.. code-block:: LANGUAGE`` directives of an
    reStructuredText ``page``, in page order, dedented."""
    lines = page.read_text(encoding="utf-8").splitlines()
    blocks = []
    i = 0
    while i < len(lines):
        if lines[i].strip() != f".. code-block:: {language}":
            i += 1
            continue
        i += 1
        while i < len(lines) and lines[i].strip().startswith(":"):
            i += 1                      # the directive's options
        body = []
        while i < len(lines) and (not lines[i].strip()
                                  or lines[i].startswith(" ")):
            body.append(lines[i])
            i += 1
        blocks.append(textwrap.dedent("\n".join(body)).strip() + "\n")
    return blocks


def fenced_blocks(page: Path, language: str) -> list[str]:
    """The bodies of the fenced code blocks (three backquotes and
    LANGUAGE) of a Markdown ``page``, in page order."""
    lines = page.read_text(encoding="utf-8").splitlines()
    blocks = []
    i = 0
    while i < len(lines):
        if lines[i].strip() != f"```{language}":
            i += 1
            continue
        i += 1
        body = []
        while i < len(lines) and lines[i].strip() != "```":
            body.append(lines[i])
            i += 1
        blocks.append("\n".join(body).strip() + "\n")
    return blocks
