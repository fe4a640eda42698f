"""halcmd: the HAL command language (executor, lexer, output formats).

From Python::

    from halsdk import Hal, halcmd
    with Hal() as hal:
        failures = halcmd.source(hal, "machine.hal")
        halcmd.command(hal, "show pin")
"""

from __future__ import annotations

from typing import Any

from halsdk.halcmd.commands import CommandError, CommandRunner, Quit, parse_value
from halsdk.halcmd.lexer import logical_lines, tokenize


def source(hal: Any, path: str, **options: Any) -> int:
    """Run a HAL file against ``hal``; returns the number of failures.

    ``options`` are those of :class:`CommandRunner` (``keep_going``, ``ini``,
    ``script``, ``out``, ``err`` ...).  No ``halcmd<pid>`` component is
    registered.
    """
    ex = CommandRunner(hal, register=False, **options)
    try:
        return ex.run_file(path)
    except Quit:
        return ex.errors


def command(hal: Any, line: str, **options: Any) -> bool:
    """Run one command line; True when it succeeded."""
    ex = CommandRunner(hal, register=False, **options)
    try:
        return ex.run_line(line)
    except Quit:
        return True


__all__ = ["CommandError", "CommandRunner", "Quit", "parse_value",
           "logical_lines", "tokenize", "source", "command"]
