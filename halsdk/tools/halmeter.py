"""halmeter: watch one pin, signal or parameter of a running HAL instance.

    halmeter -s {pin|sig|param} NAME [-g X Y [WIDTH]] [-n COUNT] [-p MS]

The reference halmeter is a GTK window.  halsdk has no GUI: its halmeter
is the *text mode* of the small, non-interactive meter (``-s``).  It
attaches to the instance named by ``$HALSDK_INSTANCE`` (the one
``loadusr`` runs it in) and writes the value of the item to standard
output, one line per update, in the reference meter's value format:

============  ===========================================
type          line
============  ===========================================
bit           ``TRUE`` or ``FALSE``
float         ``%.7g``   (e.g. ``3.141593``, ``1e+10``)
s32, s64      ``%10d``   (right-aligned in 10 columns)
u32, u64      ``%10u (0x%08X)``  (decimal, then hex)
============  ===========================================

(The reference has no 64-bit types; s64/u64 use the format of their 32-bit
counterpart, the hex field growing past 8 digits when needed.)

Options as in the reference manual:

``-s``
    Small non-interactive meter; here, the text mode.  Required: without
    it the reference opens its window with "Select" and "Exit" buttons,
    which halsdk does not support (error, exit status 1).
``pin NAME`` / ``sig NAME`` / ``param NAME``
    The item to watch (aliases are found too).
``-g X Y [WIDTH]``
    Window geometry; accepted and ignored in text mode.

Options of halsdk (the reference has none of these):

``-n COUNT``
    Print COUNT lines, then exit with status 0 (default: run until
    interrupted; SIGINT or SIGTERM end it with status 0).
``-p MS``
    Update period in milliseconds (default 100, the reference meter's
    refresh interval).

An unknown item, a missing instance or an item deleted while it is watched
is reported on standard error with exit status 1.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Sequence
from typing import Any, NamedTuple, Optional

from halsdk import console
from halsdk.tools._attach import attach, stop_on_signals

PROG = "halmeter"
DEFAULT_PERIOD_MS = 100.0
USAGE = ("usage: halmeter -s {pin|sig|param} NAME [-g X Y [WIDTH]] "
         "[-n COUNT] [-p MS]")
_KINDS = {"pin": "pin", "sig": "signal", "param": "param"}


class _Usage(Exception):
    pass


class Options(NamedTuple):
    small: bool
    kind: Optional[str]          # "pin", "sig" or "param"
    name: Optional[str]
    # the field shadows tuple.count(), which mypy refuses for a NamedTuple
    count: int  # type: ignore[assignment]  # -1: forever
    period_ms: float
    help: bool


def _number(opt: str, value: str, kind: type) -> Any:
    try:
        return kind(value)
    except ValueError:
        raise _Usage(f"ERROR: invalid value '{value}' for option "
                     f"'{opt}'") from None


def parse_args(argv: Sequence[str]) -> Options:
    """Parse the command line (raises ``_Usage`` with the message)."""
    small, kind, name, count, period, want_help = (
        False, None, None, -1, DEFAULT_PERIOD_MS, False)
    args = list(argv)
    i = 0
    while i < len(args):
        a = args[i]
        if a in ("-h", "--help"):
            want_help = True
        elif a == "-s":
            small = True
        elif a == "-g":
            # X Y and an optional WIDTH, all integers
            nums: list[int] = []
            while (len(nums) < 3 and i + 1 < len(args)
                   and args[i + 1].lstrip("-").isdigit()):
                i += 1
                nums.append(int(args[i]))
            if len(nums) < 2:
                raise _Usage("ERROR: option '-g' needs X and Y positions")
        elif a in ("-n", "-p") or (a[:2] in ("-n", "-p") and len(a) > 2):
            opt = a[:2]
            value = a[2:]
            if not value:
                i += 1
                if i >= len(args):
                    raise _Usage(f"ERROR: option '{opt}' needs a value")
                value = args[i]
            if opt == "-n":
                count = _number(opt, value, int)
                if count < 0:
                    raise _Usage(f"ERROR: invalid count {count}")
            else:
                period = _number(opt, value, float)
                if not (period > 0 and math.isfinite(period)):
                    raise _Usage(f"ERROR: invalid period {value}")
        elif a.startswith("-") and len(a) > 1:
            raise _Usage(f"ERROR: unknown option '{a}'")
        elif kind is None:
            if a not in _KINDS:
                raise _Usage(f"ERROR: '{a}' is not a valid probe type "
                             "(pin, sig or param)")
            kind = a
        elif name is None:
            name = a
        else:
            raise _Usage(f"ERROR: extra argument '{a}'")
        i += 1
    if kind is not None and name is None and not want_help:
        raise _Usage("ERROR: no pin/signal/parameter name")
    return Options(small, kind, name, count, period, want_help)


def format_value(hal_type: int, value: Any) -> str:
    """The value as the reference meter displays it."""
    from halsdk.types import HalType
    if hal_type == HalType.BIT:
        return "TRUE" if value else "FALSE"
    if hal_type == HalType.FLOAT:
        v = float(value)
        if v != v:                      # C prints the sign of a NaN
            return "-nan" if math.copysign(1.0, v) < 0 else "nan"
        return f"{v:.7g}"
    if hal_type in (HalType.S32, HalType.S64):
        return f"{int(value):10d}"
    if hal_type in (HalType.U32, HalType.U64):
        n = int(value)
        return f"{n:10d} (0x{n:08X})"
    raise ValueError(f"unknown HAL type {hal_type}")


def _find(hal, kind: str, name: str):
    """The handle of the watched item, or None."""
    return hal.find(_KINDS[kind], name)


def meter(item, out, count: int, period_s: float, stop: list) -> int:
    """Write the value of ``item`` to ``out`` every ``period_s`` seconds
    until ``count`` lines were written (forever when negative) or ``stop``
    becomes non-empty; returns the number of lines written.  Raises
    :class:`halsdk.StaleError` if the item is deleted meanwhile."""
    hal_type = item.type
    done = 0
    next_t = time.monotonic()
    while (count < 0 or done < count) and not stop:
        out.write(format_value(hal_type, item.value) + "\n")
        out.flush()
        done += 1
        if count >= 0 and done >= count:
            break
        next_t += period_s
        delay = next_t - time.monotonic()
        if delay > 0:
            time.sleep(delay)
        else:                           # late (suspended?): do not burst
            next_t = time.monotonic()
    return done


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Console entry point: :func:`_main` under the broken-pipe rule
    of every halsdk program (:mod:`halsdk.console`)."""
    return console.run(_main, argv)


def _main(argv: Optional[Sequence[str]] = None) -> int:
    """Entry point of the ``halmeter`` program."""
    if argv is None:
        argv = sys.argv[1:]
    try:
        opts = parse_args(argv)
    except _Usage as e:
        print(f"{PROG}: {e}", file=sys.stderr)
        print(USAGE, file=sys.stderr)
        return 1
    if opts.help:
        print(USAGE)
        return 0
    if not opts.small:
        print(f"{PROG}: ERROR: the meter window (GTK) is not supported by "
              "halsdk; use the text mode: halmeter -s {pin|sig|param} NAME",
              file=sys.stderr)
        return 1
    if opts.kind is None or opts.name is None:
        print(f"{PROG}: ERROR: -s option requires a probe type and a "
              "pin/signal/parameter name", file=sys.stderr)
        return 1

    stop = stop_on_signals()

    from halsdk import errors
    hal = attach(PROG)
    if hal is None:
        return 1
    what = _KINDS[opts.kind]
    try:
        item = _find(hal, opts.kind, opts.name)
        if item is None:
            print(f"{PROG}: ERROR: {what} '{opts.name}' not found",
                  file=sys.stderr)
            return 1
        try:
            meter(item, sys.stdout, opts.count, opts.period_ms / 1000.0,
                  stop)
        except errors.StaleError:
            print(f"{PROG}: ERROR: {what} '{opts.name}' was deleted",
                  file=sys.stderr)
            return 1
        return 0
    finally:
        hal.close()


if __name__ == "__main__":
    sys.exit(main())
