"""What every console script of halsdk shares: the Unix rule for a
reader that went away.

``halcmd show pin | head -1`` closes the pipe after one line. A C tool
is then killed by SIGPIPE: no message, exit status 141 in the shell
(128 + 13). Python instead raises :class:`BrokenPipeError` and, left
alone, prints a traceback. :func:`run` applies the Unix rule in one
place for every console script: the exception ends the program
quietly, ``finally`` blocks and context managers still run (so halrun
still removes its instance), nothing more is written to the closed
pipe, and the exit status is :data:`EXIT_BROKEN_PIPE` (0: the reader
took what it wanted, and the reference's halcmd also ends with 0).
halcmd and halrun go further, as the reference does: their output
writer calls :func:`silence_stdout` and the rest of the file still
runs, so a HAL file is never left half applied.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from typing import Callable, Optional

#: the exit status after the reader went away: a normal end, as the
#: reference's halcmd (not 128 + SIGPIPE, which would fail every
#: ``set -o pipefail`` script that reads only the first lines)
EXIT_BROKEN_PIPE = 0


def silence_stdout() -> None:
    """Point stdout at /dev/null, so that what is still buffered (and
    Python's own flush at exit) cannot fail on the closed pipe."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
    except OSError:
        return
    try:
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):
        pass
    finally:
        os.close(devnull)


def run(main: Callable[..., Optional[int]],
        argv: Optional[Sequence[str]] = None) -> int:
    """Call ``main(argv)`` (``main()`` when ``argv`` is None) and return
    its exit status; a broken stdout pipe ends it quietly with
    :data:`EXIT_BROKEN_PIPE`."""
    try:
        code = main() if argv is None else main(list(argv))
        sys.stdout.flush()
    except BrokenPipeError:
        silence_stdout()
        return EXIT_BROKEN_PIPE
    return int(code or 0)


def entry(main: Callable[..., Optional[int]]) -> Callable[[], int]:
    """A console-script entry point that runs ``main`` under :func:`run`
    (the ``[project.scripts]`` targets are made with it)."""
    def console_main() -> int:
        return run(main)
    console_main.__name__ = getattr(main, "__name__", "console_main")
    console_main.__doc__ = getattr(main, "__doc__", None)
    return console_main
