"""halstreamer: feed lines of numbers into a streamer FIFO.

    halstreamer [-c CHAN] [FILENAME]

Reads lines from FILENAME (default stdin) and writes each one as a record
to the stream ``streamer.CHAN`` (made by ``loadrt streamer``) of the HAL
instance named by ``$HALSDK_INSTANCE``.  A line holds one value per pin of
the channel, separated by blanks, as C reads them: floats as ``strtod``
(decimal, hex, inf, nan), integers in decimal as ``strtol``/``strtoul``
(out-of-range values wrap to the pin width as they do in C), bits as
the single character 0 or 1.
Lines starting with ``#`` are skipped; extra fields are ignored.  A bad
line is reported on stderr (``line N, field M: ...``, N counted from 0 as
the reference does) and skipped.  When the FIFO is full it waits.  Exits
with 0 at the end of the input, 1 on errors or when killed.
"""

from __future__ import annotations

import re
import sys
import time
from collections.abc import Iterable, Sequence
from typing import IO, Optional

from halsdk import console
from halsdk.tools._attach import attach, stop_on_signals
from halsdk.values import c_float, c_wrap

PROG = "halstreamer"
POLL_S = 0.01

_INT = re.compile(r"[+-]?\d+\Z")
_WS = " \t\n\r\v\f"


class LineError(ValueError):
    """A field of an input line that C's parsing would reject."""

    def __init__(self, field: int, what: str):
        super().__init__(what)
        self.field = field
        self.what = what


def parse_line(line: str, types: Sequence[int]) -> list:
    """Values of one input line for a channel of ``types``; raises
    :class:`LineError` the way the reference rejects a line."""
    from halsdk.types import HalType
    values = []
    pos, end = 0, len(line)
    for i, t in enumerate(types):
        while pos < end and line[pos] in _WS:
            pos += 1
        if pos >= end:
            raise LineError(i, "premature end of line")
        stop = pos
        while stop < end and line[stop] not in _WS:
            stop += 1
        tok = line[pos:stop]
        pos = stop
        if t == HalType.FLOAT:
            v = c_float(tok)
            if v is None:
                raise LineError(i, "bad character")
            values.append(v)
            continue
        if t == HalType.BIT:
            if tok[0] not in "01":
                raise LineError(i, "bit value not 0 or 1")
            if len(tok) > 1:
                raise LineError(i, "bad character")
            values.append(int(tok))
            continue
        if not _INT.match(tok):
            raise LineError(i, "bad character")
        values.append(c_wrap(t, int(tok, 10)))    # strtol(tok, 10)
    return values


USAGE = """\
usage: halstreamer [-c CHAN] [FILENAME]

Writes each line of FILENAME (default stdin) as a record to the stream
streamer.CHAN (made by 'loadrt streamer') of the HAL instance
$HALSDK_INSTANCE: one value per pin, separated by blanks; lines starting
with # are skipped.
  -c CHAN     the streamer channel (default 0)
  -h, --help  this help
"""


class _Usage(Exception):
    pass


class _Help(Exception):
    pass


def _parse(argv: Sequence[str]) -> tuple[int, Optional[str]]:
    chan, filename = 0, None
    args = list(argv)
    i = 0
    while i < len(args):
        a = args[i]
        if a in ("-h", "--help"):
            raise _Help
        if a.startswith("-") and len(a) > 1:
            if a[1] != "c":
                raise _Usage(f"ERROR: unknown option '{a[1]}'")
            value = a[2:]
            if not value:
                i += 1
                if i >= len(args):
                    raise _Usage("ERROR: option 'c' needs a value")
                value = args[i]
            try:
                chan = int(value, 0)
            except ValueError:
                raise _Usage(f"ERROR: invalid value '{value}' for option "
                             "'c'") from None
            if chan < 0:
                raise _Usage(f"ERROR: invalid channel {chan}")
        else:
            if filename is not None:
                raise _Usage(f"ERROR: extra argument '{a}'")
            filename = a
        i += 1
    return chan, filename


def feed(stream, lines: Iterable[str], stop: list,
         err: IO[str] = sys.stderr) -> bool:
    """Write the records of ``lines`` to ``stream``, waiting while it is
    full; False if ``stop`` became non-empty first."""
    types = stream.types
    for lineno, line in enumerate(lines):
        if line.startswith("#"):
            continue
        try:
            values = parse_line(line, types)
        except LineError as e:
            err.write(f"line {lineno}, field {e.field}: {e.what}, "
                      "skipping the line\n")
            err.flush()
            continue
        while stream.room <= 0:
            if stop:
                return False
            time.sleep(POLL_S)
        if stop:
            return False
        stream.write(values)
    return True


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Console entry point: :func:`_main` under the broken-pipe rule
    of every halsdk program (:mod:`halsdk.console`)."""
    return console.run(_main, argv)


def _main(argv: Optional[Sequence[str]] = None) -> int:
    """Entry point of the ``halstreamer`` program."""
    if argv is None:
        argv = sys.argv[1:]
    try:
        chan, filename = _parse(argv)
    except _Help:
        sys.stdout.write(USAGE)
        return 0
    except _Usage as e:
        print(e, file=sys.stderr)
        return 1
    stop = stop_on_signals()

    from halsdk import errors
    hal = attach(PROG)
    if hal is None:
        return 1
    name = f"streamer.{chan}"
    try:
        try:
            stream = hal.stream(name)
        except errors.NotFoundError:
            print(f"{PROG}: ERROR: stream '{name}' not found (is 'loadrt "
                  f"streamer' loaded with at least {chan + 1} channel"
                  f"{'s' if chan else ''}?)", file=sys.stderr)
            return 1
        try:
            src = (open(filename, encoding="utf-8", errors="replace")
                   if filename else sys.stdin)
        except OSError as e:
            print(f"{PROG}: ERROR: cannot open '{filename}': {e.strerror}",
                  file=sys.stderr)
            return 1
        try:
            return 0 if feed(stream, src, stop) else 1
        except errors.StaleError:
            print(f"{PROG}: ERROR: stream '{name}' was removed (streamer "
                  "unloaded)", file=sys.stderr)
            return 1
        finally:
            if filename:
                src.close()
    finally:
        hal.close()


if __name__ == "__main__":
    sys.exit(main())
