"""halsampler: print the records of a sampler FIFO, one line per sample.

    halsampler [-c CHAN] [-n COUNT] [-t] [FILENAME]

Reads the stream ``sampler.CHAN`` (made by ``loadrt sampler``) of the HAL
instance named by ``$HALSDK_INSTANCE`` (the one ``loadusr`` runs it in) and
prints each record as the reference does: values separated by blanks, each
followed by one blank (floats as ``%f``, bits as 0/1, integers in decimal),
with ``-t`` the sample number first, and a line ``overrun`` wherever sample
numbers jump (records lost or read by someone else).  With ``-n`` it exits
with status 0 after COUNT samples; otherwise it runs until killed and exits
with status 1.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Sequence
from typing import IO, Optional

from halsdk import console
from halsdk.tools._attach import attach, stop_on_signals

PROG = "halsampler"
POLL_S = 0.01


USAGE = """\
usage: halsampler [-c CHAN] [-n COUNT] [-t] [FILENAME]

Prints the records of the stream sampler.CHAN (made by 'loadrt sampler')
of the HAL instance $HALSDK_INSTANCE, one line per sample.
  -c CHAN   the sampler channel (default 0)
  -n COUNT  exit with status 0 after COUNT samples (default: run until
            killed, then exit with status 1)
  -t        print the sample number first
  -h, --help  this help
  FILENAME  write to this file instead of stdout
"""


class _Usage(Exception):
    pass


class _Help(Exception):
    pass


def _parse(argv: Sequence[str]) -> tuple[int, int, bool, Optional[str]]:
    chan, count, tag, filename = 0, -1, False, None
    args = list(argv)
    i = 0
    while i < len(args):
        a = args[i]
        if a in ("-h", "--help"):
            raise _Help
        if a.startswith("-") and len(a) > 1:
            opt = a[1]
            if opt == "t" and len(a) == 2:
                tag = True
            elif opt in ("c", "n"):
                value = a[2:]
                if not value:
                    i += 1
                    if i >= len(args):
                        raise _Usage(f"ERROR: option '{opt}' needs a value")
                    value = args[i]
                try:
                    number = int(value, 0)
                except ValueError:
                    raise _Usage(f"ERROR: invalid value '{value}' for "
                                 f"option '{opt}'") from None
                if opt == "c":
                    if number < 0:
                        raise _Usage(f"ERROR: invalid channel {number}")
                    chan = number
                else:
                    if number < 0:
                        raise _Usage(f"ERROR: invalid count {number}")
                    count = number
            else:
                raise _Usage(f"ERROR: unknown option '{opt}'")
        else:
            if filename is not None:
                raise _Usage(f"ERROR: extra argument '{a}'")
            filename = a
        i += 1
    return chan, count, tag, filename


def _fmt_float(v: float) -> str:
    """``printf("%f ")``: C writes the sign of a NaN."""
    if v != v:
        return "-nan " if math.copysign(1.0, v) < 0 else "nan "
    return f"{v:f} "


def copy_records(stream, out: IO[str], count: int, tag: bool,
                 stop: list) -> int:
    """Copy records to ``out`` until ``count`` were printed (forever when
    negative) or ``stop`` becomes non-empty; returns the number printed."""
    from halsdk.types import HalType
    types = stream.types
    floats = [t == HalType.FLOAT for t in types]
    names = [f"v{i}" for i in range(len(types))]
    last = -1
    done = 0
    while (count < 0 or done < count) and not stop:
        want = -1 if count < 0 else count - done
        arr = stream.read_many(min(want, 4096) if want >= 0 else 4096, names)
        if len(arr) == 0:
            out.flush()
            time.sleep(POLL_S)
            continue
        cols = [arr[n].tolist() for n in names]
        samples = arr["sample"].tolist()
        lines = []
        for row, sample in enumerate(samples):
            if sample != last + 1:
                lines.append("overrun\n")
            last = sample
            parts = [f"{sample} "] if tag else []
            for col, is_float in zip(cols, floats):
                v = col[row]
                if is_float:
                    parts.append(_fmt_float(v))
                else:
                    parts.append(f"{int(v)} ")
            parts.append("\n")
            lines.append("".join(parts))
        out.write("".join(lines))
        done += len(samples)
    out.flush()
    return done


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Console entry point: :func:`_main` under the broken-pipe rule
    of every halsdk program (:mod:`halsdk.console`)."""
    return console.run(_main, argv)


def _main(argv: Optional[Sequence[str]] = None) -> int:
    """Entry point of the ``halsampler`` program."""
    if argv is None:
        argv = sys.argv[1:]
    try:
        chan, count, tag, filename = _parse(argv)
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
    name = f"sampler.{chan}"
    out: IO[str]
    try:
        try:
            stream = hal.stream(name)
        except errors.NotFoundError:
            print(f"{PROG}: ERROR: stream '{name}' not found (is 'loadrt "
                  f"sampler' loaded with at least {chan + 1} channel"
                  f"{'s' if chan else ''}?)", file=sys.stderr)
            return 1
        try:
            out = open(filename, "w") if filename else sys.stdout
        except OSError as e:
            print(f"{PROG}: ERROR: cannot open '{filename}': {e.strerror}",
                  file=sys.stderr)
            return 1
        try:
            done = copy_records(stream, out, count, tag, stop)
        except errors.StaleError:
            out.flush()
            print(f"{PROG}: ERROR: stream '{name}' was removed (sampler "
                  "unloaded)", file=sys.stderr)
            return 1
        finally:
            if filename:
                out.close()
        return 0 if count >= 0 and done >= count else 1
    finally:
        hal.close()


if __name__ == "__main__":
    sys.exit(main())
