"""Reading a joint's lead-screw compensation file ([JOINT_n]COMP_FILE).

The file holds one entry per line: three numbers separated by blanks, the
nominal (commanded) position first.  What the other two mean depends on
COMP_FILE_TYPE:

* type 0: the actual positions reached moving in the positive and in the
  negative direction;
* type 1: the trims (actual minus nominal) moving positive and negative.

:func:`read_comp_file` returns ``(nominal, forward_trim, reverse_trim)``
triplets in both cases, ready for the motion controller's
SET_JOINT_COMP command: nominal positions strictly increasing, at most
:data:`COMP_SIZE` of them.  ``#`` starts a comment; blank lines are
allowed.  Anything else is a :class:`CompFileError` naming the file and
the line.
"""

from __future__ import annotations

import math
import os

from halsdk.errors import HalError

COMP_SIZE = 256
"""The most entries a joint's table holds (the realtime table size)."""


class CompFileError(HalError, ValueError):
    """A malformed compensation file; the message is ``FILE:LINE: what
    is wrong``."""


def parse_comp(text: str, comp_type: int = 1, filename: str = "<string>"
               ) -> list[tuple[float, float, float]]:
    """Parse the text of a compensation file (see :func:`read_comp_file`)."""
    if comp_type not in (0, 1) or isinstance(comp_type, bool):
        raise CompFileError(f"{filename}: COMP_FILE_TYPE must be 0 or 1, "
                            f"not {comp_type!r}")
    entries: list[tuple[float, float, float]] = []
    last_line = 0
    for lineno, line in enumerate(text.splitlines(), 1):
        words = line.split("#", 1)[0].split()
        if not words:
            continue

        def fail(what: str, lineno: int = lineno) -> CompFileError:
            return CompFileError(f"{filename}:{lineno}: {what}")

        if len(words) != 3:
            plural = "" if len(words) == 1 else "s"
            raise fail("expected 3 numbers (nominal, forward, reverse), "
                       f"found {len(words)} value{plural}")
        values = []
        for name, word in zip(("nominal", "forward", "reverse"), words):
            try:
                value = float(word)
            except ValueError:
                raise fail(f"{name} value {word!r} is not a number"
                           ) from None
            if not math.isfinite(value):
                raise fail(f"{name} value {word!r} is not a finite number")
            values.append(value)
        nominal, fwd, rev = values
        if entries and not nominal > entries[-1][0]:
            raise fail(f"nominal position {words[0]} is not greater than "
                       f"{entries[-1][0]!r} on line {last_line} (nominal "
                       "positions must increase)")
        if len(entries) >= COMP_SIZE:
            raise fail(f"more than {COMP_SIZE} entries")
        if comp_type == 0:
            fwd, rev = fwd - nominal, rev - nominal
        entries.append((nominal, fwd, rev))
        last_line = lineno
    return entries


def read_comp_file(path: str | os.PathLike, comp_type: int = 1
                   ) -> list[tuple[float, float, float]]:
    """Read the compensation file ``path`` of COMP_FILE_TYPE ``comp_type``
    (0: actual positions, 1: trims) and return its entries as
    ``(nominal, forward_trim, reverse_trim)`` triplets.

    Raises :class:`CompFileError` (``FILE:LINE: what is wrong``) for a
    line without exactly three numbers, a value that is not a finite
    number, nominal positions not strictly increasing, more than 256
    entries, or a file that cannot be read.
    """
    name = os.fspath(path)
    try:
        with open(name, encoding="utf-8") as f:
            text = f.read()
    except (OSError, UnicodeDecodeError) as e:
        raise CompFileError(f"{name}: cannot read the compensation file: "
                            f"{e}") from None
    return parse_comp(text, comp_type, name)
