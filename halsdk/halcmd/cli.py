"""The ``halcmd`` and ``halrun`` programs.

``halrun`` creates the HAL instance (this process becomes its host),
runs a file or an interactive prompt, then removes the instance (``-I``:
prompt first).  ``halcmd`` attaches to a running instance and runs a
file, one command from its arguments, or a prompt.
"""

from __future__ import annotations

import sys
from typing import Optional

from halsdk import console
from halsdk.halcmd.commands import CommandRunner, Quit

_HALCMD_USAGE = """\
Usage:  halcmd [options] [cmd [args]]
options:
  -f [filename]  read commands from 'filename' (default stdin)
  -i inifile     use inifile for [SECTION]KEY substitution
  -k             keep going after a failed command
  -q             print errors only (default)
  -Q             print nothing
  -s             script-friendly output of show
  -v             verbose
  -V             very verbose
  -e             echo the commands read from a file
  -h, --help     this help
  --check FILE   check FILE's netlist without running it (see docs)
"""

_HALRUN_USAGE = """\
Usage:  halrun [-I] [-U] [halcmd options] [-f] [filename.hal|filename.ini]
  -I   run an interactive halcmd after the file, before removing HAL
  -U   remove HAL instances left behind by dead processes and exit
  -h, --help    this help
  --check FILE  check FILE's netlist without running it
  an INI file with [HAL]TWOPASS runs its [HAL]HALFILEs in two passes
  (other options are those of halcmd)
"""


class _Options:
    def __init__(self) -> None:
        self.file: Optional[str] = None
        self.ini: Optional[str] = None
        self.release_only = False
        self.keep_going = False
        self.verbose = 0
        self.script = False
        self.echo = False
        self.interactive_after = False
        self.cleanup = False
        self.check = False
        self.words: list[str] = []


def _parse(argv: list[str], prog: str) -> _Options:
    """Parse getopt-style options; raises SystemExit on bad usage."""
    opts = _Options()
    usage = _HALRUN_USAGE if prog == "halrun" else _HALCMD_USAGE
    i = 0
    while i < len(argv):
        arg = argv[i]
        if arg == "--":
            i += 1
            break
        if arg == "--check":
            opts.check = True
            i += 1
            continue
        if arg == "--help":
            # what a newcomer types first: the usage, like -h
            sys.stdout.write(usage)
            raise SystemExit(0)
        if not arg.startswith("-") or arg == "-":
            break
        letters = arg[1:]
        j = 0
        while j < len(letters):
            c = letters[j]
            rest = letters[j + 1:]
            if c in "fi":
                value: Optional[str] = rest or None
                if value is None and i + 1 < len(argv) and (
                        c == "i" or not argv[i + 1].startswith("-")):
                    i += 1
                    value = argv[i]
                if c == "i":
                    if value is None:
                        _die(prog, "option -i needs an INI file", usage)
                    opts.ini = value
                else:
                    opts.file = value if value is not None else "-"
                break
            if c == "k":
                opts.keep_going = True
            elif c == "q":
                opts.verbose = 0
            elif c == "Q":
                opts.verbose = -1
            elif c in "vV":
                opts.verbose = 1
            elif c == "s":
                opts.script = True
            elif c == "e":
                opts.echo = True
            elif c == "R":
                # release the HAL mutex and exit: the core's mutex is
                # robust, so there is nothing to release
                opts.release_only = True
            elif c == "I" and prog == "halrun":
                opts.interactive_after = True
            elif c == "U" and prog == "halrun":
                opts.cleanup = True
            elif c == "T":
                print(f"{prog}: the Tcl interface (-T) is not supported by "
                      "halsdk", file=sys.stderr)
                raise SystemExit(2)
            elif c == "h":
                sys.stdout.write(usage)
                raise SystemExit(0)
            else:
                _die(prog, f"unknown option -{c}", usage)
            j += 1
        i += 1
    opts.words = argv[i:]
    return opts


def _die(prog: str, message: str, usage: str) -> None:
    sys.stderr.write(f"{prog}: {message}\n{usage}")
    raise SystemExit(1)


def _completions(hal, text: str, first_word: bool) -> list[str]:
    """Command names for the first word, HAL names after it."""
    from halsdk.halcmd.commands import ARG_COUNTS
    if first_word:
        names = list(ARG_COUNTS)
    else:
        names = [it.name for kind in ("pin", "param", "signal", "function",
                                      "thread", "component")
                 for it in hal.items(kind)]
    return sorted(n for n in names if n.startswith(text))


def _setup_readline(hal) -> None:
    try:
        import readline
    except ImportError:
        return
    state: dict[str, list[str]] = {}

    def complete(text: str, n: int):
        if n == 0:
            before = readline.get_line_buffer()[:readline.get_begidx()]
            state["m"] = _completions(hal, text, not before.strip())
        found = state.get("m", [])
        return found[n] if n < len(found) else None

    readline.set_completer_delims(" \t")
    readline.set_completer(complete)
    readline.parse_and_bind("tab: complete")


def _interactive(ex: CommandRunner) -> None:
    """A simple prompt with readline history when it is available."""
    tty = sys.stdin.isatty()
    if tty:
        _setup_readline(ex.hal)
    ex.filename = "<stdin>"
    ex.lineno = 0
    while True:
        try:
            line = input("halcmd: " if tty else "")
        except EOFError:
            if tty:
                sys.stdout.write("\n")
            return
        except KeyboardInterrupt:
            sys.stdout.write("\n")
            continue
        ex.lineno += 1
        ex.run_line(line)


def _run(ex: CommandRunner, opts: _Options, prog: str) -> int:
    """Run the file, the command words or the prompt; exit status.

    halrun's status is the file's: a command mistyped at its interactive
    prompt was answered there and does not fail the session (the
    reference's halrun ignores its interactive halcmd's status too)."""
    counted: Optional[int] = None     # the errors that count, once known
    try:
        if opts.file is not None and prog == "halrun" and \
                opts.file.endswith(".ini"):
            status = _twopass(ex, opts.file)
            if opts.interactive_after:
                try:
                    _interactive(ex)
                except Quit:
                    pass
            return status
        if opts.file is not None:
            if opts.file == "-":
                ex.run_lines(sys.stdin, "<stdin>")
            else:
                ex.run_file(opts.file)
        elif opts.words:
            ex.run_words(opts.words)
        elif prog == "halcmd" or not opts.interactive_after:
            _interactive(ex)
        if opts.interactive_after and prog == "halrun":
            counted = ex.errors
            _interactive(ex)
    except Quit:
        pass
    errors = ex.errors if counted is None else counted
    return 1 if errors else 0


def _twopass(ex: CommandRunner, path: str) -> int:
    """``halrun FILE.ini``: twopass loading, as the reference does it."""
    from halsdk.halcmd import twopass
    try:
        if not twopass.is_twopass_ini(path):
            print("halrun: An INI file may only be used if it specifies "
                  "[HAL]TWOPASS")
            return 1
    except OSError as exc:
        print(f"halrun: cannot read '{path}': {exc.strerror}",
              file=sys.stderr)
        return 1
    return twopass.run(ex, path)


def _ini_missing(opts: _Options) -> bool:
    """-i with a file that cannot be read: the reference's message."""
    if opts.ini is None:
        return False
    try:
        with open(opts.ini, encoding="utf-8", errors="replace"):
            return False
    except OSError:
        print(f"Could not open INI file '{opts.ini}'", file=sys.stderr)
        return True


def _check(opts: _Options, prog: str) -> int:
    """``--check FILE``: the netlist checker (no instance is used)."""
    from halsdk.halcmd import check
    path = opts.file if opts.file not in (None, "-") else (
        opts.words[0] if opts.words else None)
    if path is None:
        print(f"{prog}: --check needs a HAL file", file=sys.stderr)
        return 2
    return check.main(path, ini=opts.ini)


def _teardown(hal, ex: CommandRunner, opts: _Options) -> None:
    """What the end of halrun does: stop threads, end loadusr programs."""
    from halsdk.errors import HalError
    if hal.lock_level & hal.LOCK_RUN:
        # the reference's teardown cannot stop threads under a run lock
        # and says so; the instance is removed anyway
        if opts.verbose >= 0:
            sys.stderr.write("HAL: ERROR: stop_threads called while HAL "
                             "is locked\n")
        hal.lock_level = 0
    try:
        hal.stop()
    except HalError:
        pass
    ex.end_children()


def halcmd_main(argv: Optional[list[str]] = None) -> int:
    """Entry point of ``halcmd``: attach to the running instance."""
    return console.run(_halcmd_main, argv)


def _halcmd_main(argv: Optional[list[str]] = None) -> int:
    from halsdk import Hal
    from halsdk.errors import (
        DamagedError,
        HalError,
        HostGoneError,
        InvalidError,
        LockTimeoutError,
        TrustError,
    )
    argv = sys.argv[1:] if argv is None else argv
    opts = _parse(argv, "halcmd")
    if opts.release_only:
        return 0
    if _ini_missing(opts):
        return 1
    if opts.check:
        return _check(opts, "halcmd")
    try:
        hal = Hal(create=False)
    except (TrustError, DamagedError, InvalidError, LockTimeoutError,
            HostGoneError) as exc:
        print(f"halcmd: {exc}", file=sys.stderr)
        return 1
    except HalError as exc:
        # the error names the instance and says how to start one: once
        print(f"halcmd: {exc}", file=sys.stderr)
        return 1
    with hal:
        try:
            # makes the halcmd<pid> component: takes the instance lock
            ex = CommandRunner(hal, keep_going=opts.keep_going,
                               script=opts.script, verbose=opts.verbose,
                               ini=opts.ini, echo=opts.echo)
        except HalError as exc:
            print(f"halcmd: {exc}", file=sys.stderr)
            return 1
        try:
            return _run(ex, opts, "halcmd")
        finally:
            try:
                ex.unregister()
            except HalError as exc:
                print(f"halcmd: {exc}", file=sys.stderr)


#: the words of the error of creating an instance that has a live host
#: (halsdk.core.instance), the one case where another halrun is the cause
_ANOTHER_HOST = "already has a host"


def halrun_main(argv: Optional[list[str]] = None) -> int:
    """Entry point of ``halrun``: create the instance, run, remove it."""
    return console.run(_halrun_main, argv)


def _halrun_main(argv: Optional[list[str]] = None) -> int:
    import halsdk
    from halsdk import Hal
    from halsdk.errors import HalError
    argv = sys.argv[1:] if argv is None else argv
    opts = _parse(argv, "halrun")
    if opts.cleanup:
        # files that are not ours (another user's, links, junk) are named
        # and left in place; the exit status says that something was left
        # (the reference's -U always ends with 0: it has no such files)
        left: list[str] = []
        halsdk.cleanup(report=left.append)
        for message in left:
            print(f"halrun: {message}", file=sys.stderr)
        return 1 if left else 0
    if opts.release_only:
        return 0
    if _ini_missing(opts):
        return 1
    if opts.check:
        return _check(opts, "halrun")
    if opts.file is None and opts.words:
        # halrun FILE: the file name may come without -f
        opts.file, opts.words = opts.words[0], opts.words[1:]
    if opts.file is None:
        opts.interactive_after = True
    try:
        hal = Hal(create=True)
    except HalError as exc:
        print(f"halrun: cannot create the HAL instance: {exc}",
              file=sys.stderr)
        if _ANOTHER_HOST in str(exc):
            print("halrun: is another halrun running? ('halrun -U' removes "
                  "instances of dead processes)", file=sys.stderr)
        return 1
    with hal:
        ex = CommandRunner(hal, keep_going=opts.keep_going, script=opts.script,
                      verbose=opts.verbose, ini=opts.ini, echo=opts.echo)
        try:
            return _run(ex, opts, "halrun")
        finally:
            _teardown(hal, ex, opts)


_MAIN_USAGE = """\
usage: python -m halsdk.halcmd halrun|halcmd [options]
  (also: halsdk halrun|halcmd [options]) this halsdk's halrun and halcmd,
  whichever halrun/halcmd comes first on PATH; 'halrun --help' and
  'halcmd --help' give their options
"""


def main(argv: Optional[list[str]] = None) -> int:
    """``python -m halsdk.halcmd halcmd|halrun [options]`` (also
    ``python -m halsdk.halcmd.cli``)."""
    argv = sys.argv[1:] if argv is None else argv
    if argv and argv[0] in ("-h", "--help"):
        sys.stdout.write(_MAIN_USAGE)
        return 0
    if not argv or argv[0] not in ("halcmd", "halrun"):
        sys.stderr.write(_MAIN_USAGE)
        return 2
    prog, rest = argv[0], argv[1:]
    return (halcmd_main if prog == "halcmd" else halrun_main)(rest)


if __name__ == "__main__":
    sys.exit(main())
