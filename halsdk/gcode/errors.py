"""The error type of the G-code front end and interpreter."""

from __future__ import annotations

from typing import Optional

from halsdk.errors import HalError


class GCodeError(HalError, ValueError):
    """A problem in a G-code program, located by file, line and column.

    ``str(error)`` reads ``file:line:col: message``; an empty file name is
    shown as ``<string>``.  ``source`` is the line to show after the
    message when it is not the line ``line`` of ``file`` as written (a
    remapped code's call, as the reference shows it).
    """

    source: Optional[str] = None

    def __init__(self, message: str, file: str = "", line: int = 0,
                 column: int = 0) -> None:
        self.message = message
        self.file = file or "<string>"
        self.line = line
        self.column = column
        super().__init__(f"{self.file}:{line}:{column}: {message}")
