"""INI files of machine configurations, read as the reference reads them.

``[SECTION]`` headers, ``KEY = VALUE`` lines (a backslash at the end of
a line continues the value on the next one), ``#`` and ``;`` comment
lines.  The first occurrence of a key in a section wins and keys are case
sensitive, as in LinuxCNC (:meth:`IniFile.all` gives every value of a
repeated key, such as ``[HAL]HALFILE``).  Each entry remembers its line,
so that a program that finds a bad value can name the file and line.
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Iterator
from typing import Optional

#: lines a value may be continued on (a backslash at the end of a line
#: continues it), as in the reference
MAX_EXTEND_LINES = 20


class IniFile:
    """The entries of an INI file, looked up as ``[SECTION]KEY``."""

    def __init__(self, path: str):
        self.path = path
        self.values: dict[tuple[str, str], str] = {}
        self.lines: dict[tuple[str, str], int] = {}
        #: every occurrence (repeated keys such as [HAL]HALFILE), in order
        self.every: dict[tuple[str, str], list[tuple[str, int]]] = {}
        self.section_lines: dict[str, int] = {}
        #: every section header and its line, repeats included
        self.headers: list[tuple[str, int]] = []
        section = ""
        with open(path, encoding="utf-8", errors="replace") as f:
            # a NUL character ends its line, as in the reference's C
            # strings (and a file name never holds one)
            rows = [row.rstrip("\n").split("\0", 1)[0] for row in f]
        at = 0
        while at < len(rows):
            raw = rows[at]
            at += 1
            number = at
            line = raw.strip()
            if not line or line[0] in "#;":
                continue
            if line.startswith("[") and "]" in line:
                section = line[1:line.index("]")]
                self.section_lines.setdefault(section, number)
                self.headers.append((section, number))
                continue
            if "=" in line:
                key, _, value = line.partition("=")
                # a value ending in a backslash goes on on the next line
                extended = 0
                while raw.endswith("\\") and at < len(rows) and \
                        extended < MAX_EXTEND_LINES:
                    raw = rows[at]
                    at += 1
                    extended += 1
                    value = value[:-1] + raw.strip()
                where = (section, key.strip())
                self.every.setdefault(where, []).append(
                    (value.strip(), number))
                if where not in self.values:
                    self.values[where] = value.strip()
                    self.lines[where] = number

    def get(self, section: str, key: str) -> Optional[str]:
        return self.values.get((section, key))

    def all(self, section: str, key: str) -> list[str]:
        """Every value of ``[section]key``, in file order."""
        return [v for v, _ in self.every.get((section, key), [])]

    def line(self, section: str, key: Optional[str] = None) -> int:
        """Line of ``[section]key`` (of the section header when key is
        None); 0 when absent."""
        if key is None:
            return self.section_lines.get(section, 0)
        return self.lines.get((section, key), 0)

    def has_section(self, section: str) -> bool:
        return section in self.section_lines

    def items(self, section: str) -> Iterator[tuple[str, str]]:
        """The ``(key, value)`` entries of a section, in file order."""
        for (sec, key), value in self.values.items():
            if sec == section:
                yield key, value

    def repeats(self, sections: Callable[[str], bool] = lambda s: True,
                repeatable: Collection[str] = ()) -> list[tuple[int, str]]:
        """Section headers and keys given more than once in the sections
        that ``sections`` accepts (LinuxCNC merges the sections and keeps
        a key's first value, which hides typing mistakes), but keys in
        ``repeatable``: ``(line, message)`` of each later occurrence, in
        file order, such as ``[AXIS_X] is given again (first at line
        3)``."""
        found = []
        for name, number in self.headers:
            first = self.section_lines[name]
            if number != first and sections(name):
                found.append((number, f"[{name}] is given again (first at "
                                      f"line {first})"))
        for (section, key), places in self.every.items():
            if len(places) > 1 and key not in repeatable and \
                    sections(section):
                for _, number in places[1:]:
                    found.append((number, f"[{section}]{key} is given again "
                                          f"(first at line {places[0][1]})"))
        return sorted(found)

    def where(self, section: str, key: Optional[str] = None) -> str:
        """``path:line`` of an entry (or ``path`` when it is absent)."""
        n = self.line(section, key)
        return f"{self.path}:{n}" if n else self.path
