"""``halsdk ctl``: operate a running machine from the command line.

A thin layer over :func:`halsdk.machine.connect` for scripts and humans::

    halsdk ctl estop-reset && halsdk ctl on && halsdk ctl home --wait
    halsdk ctl mdi --mode "G0 X10 Y5"
    halsdk ctl run --mode --wait part.ngc
    halsdk ctl status --follow

Exit codes (see :data:`EXIT_CODES`): 0 done, 1 refused or failed (the
reason on stderr, one line prefixed ``halsdk ctl:``), 2 usage error,
3 no machine or the machine went away, 4 timed out, 130 interrupted.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import sys
import threading
import time
from collections.abc import Sequence
from typing import Any, Callable, Optional, TextIO

from halsdk import console
from halsdk.errors import HalError, InvalidError
from halsdk.machine.client import (
    ChannelError,
    MachineClient,
    MachineTimeout,
    connect,
    kind_name,
)
from halsdk.machine.remote_status import (
    AXIS_LETTERS,
    RemoteStatus,
    exec_state_name,
)
from halsdk.machine.task import MachineError, TaskMode

__all__ = ["main", "EXIT_CODES", "format_status"]

PROG = "halsdk ctl"
EXIT_DONE = 0
EXIT_FAILED = 1
EXIT_USAGE = 2
EXIT_NO_MACHINE = 3
EXIT_TIMEOUT = 4
EXIT_INTERRUPTED = 130
#: exit code -> meaning (the --help text and the docs)
EXIT_CODES = {
    EXIT_DONE: "done",
    EXIT_FAILED: "refused or failed (the reason on stderr)",
    EXIT_USAGE: "usage error",
    EXIT_NO_MACHINE: "no machine is running, or it went away",
    EXIT_TIMEOUT: "timed out",
    EXIT_INTERRUPTED: "interrupted (Ctrl-C) while waiting; the command "
                      "goes on in the machine",
}
#: how long the machine has to take a command by default (s)
DEFAULT_TIMEOUT = 5.0

_EPILOG = "exit codes:\n" + "\n".join(
    f"  {code:<4} {what}" for code, what in EXIT_CODES.items()) + """

--timeout S limits every wait: reaching the machine, having the command
taken, and (home --wait, mdi, run --wait) its completion.  Without it
the machine has 5 s to take a command, and completions are awaited
without a limit (the machine going away ends every wait)."""

_MODES = {"manual": TaskMode.MANUAL, "auto": TaskMode.AUTO,
          "mdi": TaskMode.MDI}


# ---------------------------------------------------------------- output

def _fmt_num(value: float) -> str:
    return f"{value:.3f}"


def _percent(scale: float) -> str:
    return f"{scale * 100:.0f}%"


def _homed_words(st: RemoteStatus) -> str:
    n = len(st.homed)
    if not n:
        return "-"
    homed = [str(i) for i, h in enumerate(st.homed) if h]
    if len(homed) == n:
        return f"all ({n} joints)"
    if not homed:
        return f"none ({n} joints)"
    return f"joints {' '.join(homed)} of {n}"


def _spindle_words(st: RemoteStatus) -> str:
    if not st.spindles:
        return "-"
    sp = st.spindles[0]
    if not sp.enabled or sp.direction == 0:
        return "off"
    way = "forward" if sp.direction > 0 else "reverse"
    return f"{way} {abs(sp.speed):g} rpm"


def format_status(st: RemoteStatus) -> str:
    """The readable block of ``halsdk ctl status``."""
    letters = st.axis_names or "XYZ"
    position = "  ".join(
        f"{a} {_fmt_num(st.position[AXIS_LETTERS.index(a)])}"
        for a in letters)
    interp = st.interp_state.name + (" (paused)" if st.paused else "")
    spindle_ov = _percent(st.spindles[0].override) if st.spindles else "-"
    rows = [
        ("task state", st.task_state.name),
        ("mode", st.task_mode.name),
        ("interp", interp),
        ("exec", exec_state_name(st.exec_state)),
        ("file", st.file or "-"),
        ("line", f"{st.current_line} (read {st.read_line})"),
        ("position", position),
        ("homed", _homed_words(st)),
        ("tool", f"{st.tool_in_spindle} (pocket prepped "
                 f"{st.pocket_prepped})"),
        ("overrides", f"feed {_percent(st.feedrate)}  rapid "
                      f"{_percent(st.rapidrate)}  spindle {spindle_ov}"),
        ("spindle", _spindle_words(st)),
        ("coolant", f"flood {'on' if st.flood else 'off'}  mist "
                    f"{'on' if st.mist else 'off'}"),
        ("errors", f"{st.errors_pending} unread"),
    ]
    return "\n".join(f"{name:<12} {value}" for name, value in rows)


def _status_json(st: RemoteStatus) -> str:
    return json.dumps(st.as_dict(), separators=(",", ":"))


def _emit(out: TextIO, text: str) -> None:
    """Write one whole line.  To a file descriptor with os.write and a
    loop over partial writes: a buffered write to a full pipe that a
    signal interrupts can lose the rest of its buffer (half a JSON
    object for the reader)."""
    line = text + "\n"
    try:
        fd = out.fileno()
    except (AttributeError, OSError, ValueError):
        out.write(line)                 # not a file (tests: StringIO)
        out.flush()
        return
    out.flush()
    data = memoryview(line.encode("utf-8", "surrogateescape"))
    while data:
        data = data[os.write(fd, data):]


# ---------------------------------------------------------------- commands

class _Session:
    """One run of ``halsdk ctl``: the client and the time limits."""

    def __init__(self, args: argparse.Namespace) -> None:
        self.args = args
        self.limit: Optional[float] = args.timeout
        self.start = time.monotonic()
        take = self.limit if self.limit is not None else DEFAULT_TIMEOUT
        self.client: MachineClient = connect(args.instance, take,
                                             name="ctl")

    def remaining(self) -> Optional[float]:
        """What is left of --timeout for a completion (None: no limit)."""
        if self.limit is None:
            return None
        return max(0.001, self.limit - (time.monotonic() - self.start))

    def ensure_mode(self, mode: TaskMode) -> None:
        if self.client.status().task_mode is not mode:
            self.client.mode(mode)


def _cmd_status(s: _Session, out: TextIO) -> int:
    a = s.args
    show: Callable[[RemoteStatus], str] = \
        _status_json if a.json else format_status
    follow = a.follow or a.count is not None
    if not follow:
        _emit(out, show(s.client.status()))
        return EXIT_DONE
    last: Optional[RemoteStatus] = None
    printed = 0

    def look() -> bool:
        """Print the status if it changed; True when --count is reached."""
        nonlocal last, printed
        st = s.client.status()
        if st != last:
            gap = "\n" if printed and not a.json else ""
            _emit(out, gap + show(st))
            last = st
            printed += 1
        return a.count is not None and printed >= a.count

    return _follow(look, a.interval)


def _follow(look: Callable[[], bool], interval: float) -> int:
    """Call ``look`` every ``interval`` s until it says it is done, or
    Ctrl-C.  The first Ctrl-C lets the line being written finish (never
    half a JSON object) and looks once more, so that what happened just
    before it is printed; a second one stops at once."""
    stop: list[bool] = []

    def interrupted(signum: int, frame: Any) -> None:
        if stop:
            raise KeyboardInterrupt
        stop.append(True)

    main_thread = threading.current_thread() is threading.main_thread()
    old = signal.signal(signal.SIGINT, interrupted) if main_thread else None
    try:
        while not stop:
            if look():
                return EXIT_DONE
            time.sleep(interval)
        look()
    except KeyboardInterrupt:
        pass
    finally:
        if old is not None:
            signal.signal(signal.SIGINT, old)
    return EXIT_DONE


def _cmd_errors(s: _Session, out: TextIO) -> int:
    a = s.args
    printed = 0

    def look() -> bool:
        """Print the new messages; True when done."""
        nonlocal printed
        left = None if a.count is None else a.count - printed
        for kind, text in s.client.errors(left):
            if a.json:
                _emit(out, json.dumps({"kind": kind, "name": kind_name(kind),
                                       "text": text}))
            else:
                _emit(out, f"{kind_name(kind)}: {text}")
            printed += 1
            if a.count is not None and printed >= a.count:
                return True
        return not (a.follow or a.count is not None)

    return _follow(look, a.interval)


def _cmd_state(word: str) -> Callable[[_Session, TextIO], int]:
    def run(s: _Session, out: TextIO) -> int:
        s.client.state(word, timeout=s.remaining() or s.client.timeout)
        return EXIT_DONE
    return run


def _cmd_mode(s: _Session, out: TextIO) -> int:
    s.client.mode(_MODES[s.args.mode])
    return EXIT_DONE


def _cmd_home(s: _Session, out: TextIO) -> int:
    s.client.home(s.args.joint, wait=s.args.wait, timeout=s.remaining())
    return EXIT_DONE


def _cmd_unhome(s: _Session, out: TextIO) -> int:
    s.client.unhome(s.args.joint)
    return EXIT_DONE


def _cmd_mdi(s: _Session, out: TextIO) -> int:
    if s.args.mode:
        s.ensure_mode(TaskMode.MDI)
    s.client.mdi(s.args.line, wait=not s.args.no_wait,
                 timeout=s.remaining())
    return EXIT_DONE


def _cmd_run(s: _Session, out: TextIO) -> int:
    a = s.args
    s.client.program_open(a.file)
    if a.mode:
        s.ensure_mode(TaskMode.AUTO)
    s.client.run(a.start_line, wait=a.wait, timeout=s.remaining())
    return EXIT_DONE


def _simple(method: str) -> Callable[[_Session, TextIO], int]:
    def run(s: _Session, out: TextIO) -> int:
        getattr(s.client, method)()
        return EXIT_DONE
    return run


def _cmd_feed(s: _Session, out: TextIO) -> int:
    s.client.feed_override(s.args.scale)
    return EXIT_DONE


def _cmd_rapid(s: _Session, out: TextIO) -> int:
    s.client.rapid_override(s.args.scale)
    return EXIT_DONE


# ---------------------------------------------------------------- parsing

def _joint(text: str) -> int:
    if text.lower() == "all":
        return -1
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a joint number (or 'all')") from None
    if value < -1:
        raise argparse.ArgumentTypeError(f"joint {value}: -1 (all) or more")
    return value


def _scale(text: str) -> float:
    """``1.2`` or ``120%``."""
    raw = text.strip()
    try:
        value = float(raw[:-1]) / 100 if raw.endswith("%") else float(raw)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a scale (e.g. 1.2 or 120%)") from None
    if not value >= 0:
        raise argparse.ArgumentTypeError(f"{text!r}: a scale is >= 0")
    return value


def _seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a number of seconds") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{text!r}: must be > 0 seconds")
    return value


def _count(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a count") \
            from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: a count is >= 1")
    return value


def _common(p: argparse.ArgumentParser, top: bool) -> None:
    """--instance and --timeout, accepted before and after the command
    (after it they must not reset what came before: SUPPRESS)."""
    kw: dict[str, Any] = {} if top else {"default": argparse.SUPPRESS}
    p.add_argument("--instance", metavar="NAME",
                   help="the HAL instance of the machine (default: "
                        "$HALSDK_INSTANCE, else the default instance)",
                   **({"default": None} if top else kw))
    p.add_argument("--timeout", metavar="S", type=_seconds,
                   help="give up after S seconds (exit 4); see below",
                   **({"default": None} if top else kw))


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog=PROG, description="Operate a machine started with "
        "`halsdk run machine.ini` (on the same HAL instance).",
        epilog=_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    _common(p, True)
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True

    def add(name: str, run: Callable[[_Session, TextIO], int], help: str,
            ) -> argparse.ArgumentParser:
        sp = sub.add_parser(name, help=help, description=help,
                            epilog=_EPILOG, formatter_class=argparse.
                            RawDescriptionHelpFormatter)
        _common(sp, False)
        sp.set_defaults(run=run)
        return sp

    sp = add("status", _cmd_status, "print the machine's status")
    sp.add_argument("--follow", action="store_true",
                    help="print it again whenever it changes, until Ctrl-C "
                         "(exit 0) or the machine goes away (exit 3)")
    sp.add_argument("--interval", metavar="S", type=_seconds, default=0.2,
                    help="seconds between looks with --follow (0.2)")
    sp.add_argument("--json", action="store_true",
                    help="one JSON object per status, on one line")
    sp.add_argument("--count", metavar="N", type=_count,
                    help="stop after N statuses (implies --follow)")

    sp = add("errors", _cmd_errors,
             "print the messages of the error channel not read yet")
    sp.add_argument("--follow", action="store_true",
                    help="go on printing new messages until Ctrl-C "
                         "(exit 0) or the machine goes away (exit 3)")
    sp.add_argument("--interval", metavar="S", type=_seconds, default=0.1,
                    help="seconds between looks with --follow (0.1)")
    sp.add_argument("--json", action="store_true",
                    help="one JSON object per message: kind, name, text")
    sp.add_argument("--count", metavar="N", type=_count,
                    help="stop after N messages (implies --follow)")

    for word, what in (("estop", "E-stop the machine"),
                       ("estop-reset", "reset the E-stop"),
                       ("on", "turn the machine on"),
                       ("off", "turn the machine off")):
        add(word, _cmd_state(word), what)

    sp = add("mode", _cmd_mode, "switch the mode (only while idle)")
    sp.add_argument("mode", choices=sorted(_MODES))

    sp = add("home", _cmd_home, "home a joint or all (MANUAL mode)")
    sp.add_argument("joint", nargs="?", type=_joint, default=-1,
                    metavar="JOINT", help="joint number (default: all)")
    sp.add_argument("--wait", action="store_true",
                    help="until homed")

    sp = add("unhome", _cmd_unhome, "unhome a joint or all (MANUAL mode)")
    sp.add_argument("joint", nargs="?", type=_joint, default=-1,
                    metavar="JOINT", help="joint number (default: all)")

    sp = add("mdi", _cmd_mdi, "run one line of G-code (MDI mode) and wait "
             "until its moves are done")
    sp.add_argument("line", metavar="LINE")
    sp.add_argument("--mode", action="store_true",
                    help="switch to MDI mode first (otherwise a machine "
                         "in another mode refuses the line)")
    sp.add_argument("--no-wait", action="store_true",
                    help="return once the machine took the line")

    sp = add("run", _cmd_run, "open a program and run it (AUTO mode)")
    sp.add_argument("file", metavar="FILE",
                    help="the G-code file (relative to this folder)")
    sp.add_argument("--wait", action="store_true",
                    help="until the program ended")
    sp.add_argument("--start-line", metavar="N", type=int, default=0,
                    help="start at line N (the lines before are read, not "
                         "executed)")
    sp.add_argument("--mode", action="store_true",
                    help="switch to AUTO mode first")

    for word, what in (("pause", "pause the program (feed hold)"),
                       ("resume", "resume after pause or M0/M1"),
                       ("step", "while paused: execute the next block"),
                       ("abort", "stop the program, moves, spindle and "
                                 "coolant")):
        add(word, _simple(word), what)

    sp = add("feed", _cmd_feed, "set the feed override")
    sp.add_argument("scale", type=_scale, metavar="SCALE",
                    help="1.0 or 100%% is the programmed feed")
    sp = add("rapid", _cmd_rapid, "set the rapid override (0 to 1)")
    sp.add_argument("scale", type=_scale, metavar="SCALE",
                    help="1.0 or 100%% is full speed")
    return p


# ---------------------------------------------------------------- main

def _say(err: TextIO, text: object) -> None:
    line = " ".join(str(text).split("\n")).strip()
    err.write(f"{PROG}: {line}\n")
    err.flush()


def main(argv: Optional[Sequence[str]] = None, *,
         out: Optional[TextIO] = None, err: Optional[TextIO] = None) -> int:
    """``halsdk ctl ARGS``; returns the exit code (never a traceback)."""
    out = out or sys.stdout
    err = err or sys.stderr
    parser = build_parser()
    try:
        args = parser.parse_args(sys.argv[1:] if argv is None
                                 else list(argv))
    except SystemExit as e:            # --help (0) or a usage error (2)
        return int(e.code or 0) if isinstance(e.code, int) else EXIT_USAGE
    session: Optional[_Session] = None
    try:
        session = _Session(args)
        return int(args.run(session, out))
    except KeyboardInterrupt:
        if args.command in ("status", "errors"):
            return EXIT_DONE           # the way to stop --follow
        _say(err, "interrupted (what was sent goes on in the machine)")
        return EXIT_INTERRUPTED
    except MachineTimeout as e:
        _say(err, e)
        return EXIT_TIMEOUT
    except MachineError as e:
        _say(err, e)
        return EXIT_FAILED
    except ChannelError as e:
        _say(err, e)
        return EXIT_NO_MACHINE
    except InvalidError as e:
        _say(err, e)
        return EXIT_USAGE
    except HalError as e:
        _say(err, e)
        return EXIT_FAILED
    except BrokenPipeError:
        # the reader went away (`... | head`): the rule of every
        # console script (halsdk.console)
        if out is not sys.stdout:
            raise
        console.silence_stdout()
        return console.EXIT_BROKEN_PIPE
    except Exception as e:             # a bug: say it in one line
        _say(err, f"internal error: {type(e).__name__}: {e}")
        return EXIT_FAILED
    finally:
        if session is not None:
            try:
                session.client.close()
            except Exception:
                pass


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
