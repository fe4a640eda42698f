"""Reading HAL files: logical lines, comments, words and substitutions.

The rules follow the reference halcmd:

* a backslash at the very end of a line joins the next line to it (the
  line number reported for errors is the one of the last physical line);
* ``#`` starts a comment, except inside double or single quotes;
* ``$NAME`` and ``$(NAME)`` are replaced by environment variables,
  ``[SECTION]KEY`` and ``[SECTION](KEY)`` by entries of the INI file given
  with ``-i``, in the whole line before it is split into words (so a
  value with blanks makes several words unless it is quoted, and a value
  may bring quotes of its own);
* words are separated by blanks; a string in double or single quotes is
  one word and keeps its quotes (the reference does the same: ``loadusr``
  passes them on as they are, and ``loadrt`` leaves it to the module
  loader to remove double quotes); an unterminated quote is an error.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable, Iterator
from typing import Optional

from halsdk.ini import IniFile

__all__ = ["IniFile", "SubstitutionError", "logical_lines", "split_words",
           "strip_comment", "substitute", "tokenize"]


class SubstitutionError(Exception):
    """A line that cannot be read: a ``$VAR`` or ``[SECTION]KEY`` that
    cannot be replaced, or an unterminated quote."""


def logical_lines(lines: Iterable[str]) -> Iterator[tuple[int, str]]:
    """Yield ``(line_number, text)`` with backslash continuations joined."""
    pending = ""
    number = 0
    for number, raw in enumerate(lines, 1):
        text = raw.rstrip("\r\n")
        if text.endswith("\\"):
            pending += text[:-1]
            continue
        yield number, pending + text
        pending = ""
    if pending:
        yield number, pending


_QUOTES = "\"'"


def strip_comment(line: str) -> str:
    """Remove a ``#`` comment that is not inside quotes."""
    quote = ""
    for i, ch in enumerate(line):
        if quote:
            if ch == quote:
                quote = ""
        elif ch in _QUOTES:
            quote = ch
        elif ch == "#":
            return line[:i]
    return line


_ENV_PAREN = re.compile(r"\$\(([^)]*)\)")
_ENV_WORD = re.compile(r"\$([A-Za-z0-9_]+)")
_INI = re.compile(r"\[([^\]]+)\](\(([^)]*)\)|([A-Za-z0-9_]+))")



def substitute(word: str, ini: Optional[IniFile]) -> str:
    """Replace environment and INI references in one word."""
    out = []
    i = 0
    while i < len(word):
        ch = word[i]
        if ch == "$":
            m = _ENV_PAREN.match(word, i) or _ENV_WORD.match(word, i)
            if m is None:
                if word.startswith("$(", i):
                    raise SubstitutionError("Missing close parenthesis.")
                raise SubstitutionError("Empty variable name.")
            name = m.group(1)
            value = os.environ.get(name)
            if value is None:
                raise SubstitutionError(
                    f"Environment variable '{name}' not found.")
            out.append(value)
            i = m.end()
            continue
        if ch == "[":
            m = _INI.match(word, i)
            if m is not None:
                section = m.group(1)
                key = m.group(3) if m.group(3) is not None else m.group(4)
                value = ini.get(section, key) if ini is not None else None
                if value is None:
                    raise SubstitutionError(
                        f"Ini variable '[{section}]{key}' not found.")
                out.append(value)
                i = m.end()
                continue
        out.append(ch)
        i += 1
    return "".join(out)


def split_words(line: str) -> list[str]:
    """Split a comment-free line into words (quoted strings kept whole,
    with their quotes)."""
    words: list[str] = []
    cur: list[str] = []
    quote = ""
    for ch in line:
        if quote:
            cur.append(ch)
            if ch == quote:
                quote = ""
        elif ch in _QUOTES:
            quote = ch
            cur.append(ch)
        elif ch.isspace():
            if cur:
                words.append("".join(cur))
                cur = []
        else:
            cur.append(ch)
    if quote:
        raise SubstitutionError("unterminated quoted string")
    if cur:
        words.append("".join(cur))
    return words


def tokenize(line: str, ini: Optional[IniFile] = None) -> list[str]:
    """The words of one logical line: comments removed, then variables
    substituted in the whole line, then split (as the reference does).
    A NUL character ends the line, as it ends the reference's C string."""
    return split_words(substitute(strip_comment(line.split("\0", 1)[0]),
                                  ini))
