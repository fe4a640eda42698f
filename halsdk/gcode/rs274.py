"""``rs274``: the standalone interpreter.

Reads a G-code program and prints the canonical commands it makes, in the
text format of the reference's ``rs274`` (see
:mod:`halsdk.gcode.canon_text`), so any program can be compared with the
reference line for line.  Also ``halsdk rs274``.

Like the reference's standalone interpreter, it works in a world of its
own: machine units are inches (tool tables and var files hold inches),
the program starts in G21, and without ``-t`` it uses the reference's
built-in three-tool table; without ``-v`` every parameter starts at 0
(and nothing is saved).
"""

from __future__ import annotations

import argparse
import os
import sys
from typing import IO, Any, Callable, Optional, Union

from halsdk import console
from halsdk.ini import IniFile

from .canon_text import TextCanon
from .errors import GCodeError
from .interp import Interpreter
from .params import Parameters
from .program import Program

#: the tool table of the reference's rs274 when no -t is given (inches)
DEFAULT_TOOLS = ("T1 P1 Z0.511 D0.125\n"
                 "T2 P2 Z0.1 D0.0625\n"
                 "T3 P3 Z1.273 D0.201\n")

_DESCRIPTION = """\
Run a G-code program through halsdk's interpreter and print the canonical
commands, in the text format of LinuxCNC's standalone rs274, one per line:

    7 N..... STRAIGHT_FEED(10.0000, 5.0000, 0.0000, 0.0000, 0.0000, 0.0000)

Machine units are inches (tool table and var file values), the program
starts in G21. Exit status 0, or 1 after an error (printed on stderr as
FILE:LINE:COL: message, followed by the line)."""


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="rs274", description=_DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("-p", metavar="interp.so",
                   help="accepted for compatibility and ignored (there is "
                        "one interpreter)")
    p.add_argument("-t", metavar="tool.tbl",
                   help="tool table file (default: the reference's "
                        "built-in table of tools 1, 2 and 3)")
    p.add_argument("-v", metavar="file.var",
                   help="parameter (var) file, read at the start and "
                        "written back at the end (default: none, every "
                        "parameter starts at 0)")
    p.add_argument("-i", metavar="file.ini",
                   help="INI file: [RS274NGC]PARAMETER_FILE (unless -v), "
                        "SUBROUTINE_PATH and REMAP lines and the [PYTHON] "
                        "plugin are used, and #<_ini[SECTION]KEY> reads its "
                        "numeric values")
    p.add_argument("-n", type=int, choices=(0, 1, 2), default=2,
                   help="what to do after an error: 2 stop (default), 0 "
                        "report it and go on with the next line; 1 (MDI "
                        "in the reference) stops like 2")
    p.add_argument("-b", action="store_true",
                   help="toggle block delete (default off: lines starting "
                        "with '/' run)")
    p.add_argument("-s", action="store_true",
                   help="toggle 'print stack' (accepted; errors always "
                        "name file, line and column)")
    p.add_argument("-g", action="store_true",
                   help="toggle batch mode (accepted: the program always "
                        "runs to its end)")
    p.add_argument("-T", action="store_true", help="accepted and ignored")
    p.add_argument("-l", metavar="level", help="accepted and ignored")
    p.add_argument("input", nargs="?",
                   help="the program (default: standard input)")
    p.add_argument("output", nargs="?",
                   help="write the canonical commands here (default: "
                        "standard output)")
    return p


def _finished_with_percent(text: str) -> bool:
    """The program is enclosed in % lines (the reference prints FINISH())."""
    lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
    return len(lines) >= 2 and lines[0].startswith("%") and any(
        ln.startswith("%") for ln in lines[1:])


def _source_line(text: str, file: str, exc: GCodeError) -> Optional[str]:
    """The line an error is about (in the program or a subroutine file)."""
    if exc.source is not None:
        return exc.source
    if exc.file != file:
        try:
            with open(exc.file, encoding="utf-8") as f:
                text = f.read()
        except (OSError, UnicodeDecodeError):
            return None
    lines = text.splitlines()
    if 1 <= exc.line <= len(lines):
        return lines[exc.line - 1]
    return None


def run(text: str, file: str, write: Callable[[str], Any],
        error: Callable[[str], Any], *, tool_file: Optional[str] = None,
        var_file: Optional[str] = None, block_delete: bool = False,
        search_path: tuple[str, ...] = (),
        ini: Union[IniFile, Callable[[str, str], Optional[str]],
                   None] = None,
        keep_going: bool = False) -> int:
    """Interpret ``text`` and ``write`` the reference's lines; errors go to
    ``error``.  The exit status: 0, or 1 after an error.  With
    ``keep_going`` (``-n 0``) a line the interpreter refuses is reported
    and skipped, and the status stays 0; an error in reading the program
    still ends it.  ``ini`` is an :class:`IniFile` (its ``REMAP=`` lines
    and ``[PYTHON]`` plugin are used, see :mod:`.remap`) or a lookup
    ``ini(SECTION, KEY)``."""
    from halsdk.machine.tooltable import ToolTable, ToolTableError

    try:
        tools = (ToolTable.load(tool_file) if tool_file
                 else ToolTable.parse(DEFAULT_TOOLS, file="<default>"))
    except ToolTableError as exc:
        error(f"rs274: {exc}\n")
        return 1
    params = Parameters()
    if var_file:
        try:
            params.load(var_file)
        except (GCodeError, OSError) as exc:
            error(f"rs274: {exc}\n")
            return 1
    if not params.get(5220):
        params.set(5220, 1.0)
    canon = TextCanon(write)
    status = 0
    ini_file = ini if isinstance(ini, IniFile) else None
    lookup: Optional[Callable[[str, str], Optional[str]]] = (
        ini_file.get if ini_file is not None
        else ini if not isinstance(ini, IniFile) else None)
    interp = Interpreter(params, tools, canon, units="inch",
                         program_units="mm", ini=lookup)
    canon.interp = interp
    if ini_file is not None:
        from .remap import configure

        def warn(warning: GCodeError) -> None:
            error(f"{warning}\n")

        try:
            configure(interp, ini_file, search_path, warn)
        except GCodeError as exc:       # (no line of the program)
            error(f"{exc}\n")
            return 1
    canon.start()
    def report(exc: GCodeError) -> None:
        error(f"{exc}\n")
        source = _source_line(text, file, exc)
        if source is not None:
            error(source + "\n")

    try:
        program = Program(text, file, params, search_path,
                          block_delete=block_delete)
        interp.program = program
        for block in program.blocks():
            try:
                interp.execute(block)
            except GCodeError as exc:
                if not keep_going:
                    raise
                report(exc)         # -n 0: the next line runs
            if interp.ended:
                break
        interp.comp.stop()
        if not interp.ended:
            if not _finished_with_percent(text):
                lines = text.splitlines()
                raise GCodeError("File ended with no percent sign or "
                                 "program end", file, len(lines), 1)
            canon.call("FINISH()")
    except GCodeError as exc:
        report(exc)
        status = 1
    canon.call("ON_RESET()")
    if lookup is None:          # (the reference prints one less with -i)
        canon.call("ON_RESET()")
    if var_file:
        try:
            params.save(var_file)
        except OSError as exc:
            error(f"rs274: cannot save {var_file}: {exc.strerror}\n")
            status = 1
    return status


def main(argv: Optional[list[str]] = None) -> int:
    """Console entry point (``rs274`` and ``halsdk rs274``)."""
    return console.run(_main, argv)


def _main(argv: Optional[list[str]] = None) -> int:
    a = _parser().parse_args(sys.argv[1:] if argv is None else argv)
    var_file = a.v
    search: tuple[str, ...] = ()
    ini = None
    if a.i:
        try:
            ini = IniFile(a.i)
        except OSError as exc:
            print(f"rs274: cannot read {a.i}: {exc.strerror}",
                  file=sys.stderr)
            return 1
        base = os.path.dirname(os.path.abspath(a.i))
        parameter_file = ini.get("RS274NGC", "PARAMETER_FILE")
        if var_file is None and parameter_file:
            var_file = os.path.join(base, parameter_file)
        search = tuple(os.path.join(base, d.strip()) for d in
                       (ini.get("RS274NGC", "SUBROUTINE_PATH") or ""
                        ).split(":") if d.strip())
    if a.input and a.input != "-":
        try:
            with open(a.input, encoding="utf-8") as f:
                text = f.read()
        except (OSError, UnicodeDecodeError) as exc:
            print(f"rs274: cannot read {a.input}: "
                  f"{getattr(exc, 'strerror', None) or exc}", file=sys.stderr)
            return 1
        name = a.input
        search = (*search, os.path.dirname(os.path.abspath(a.input)))
    else:
        text, name = sys.stdin.read(), "<stdin>"
    out: IO[str] = sys.stdout
    if a.output:
        try:
            out = open(a.output, "w", encoding="utf-8")
        except OSError as exc:
            print(f"rs274: cannot write {a.output}: {exc.strerror}",
                  file=sys.stderr)
            return 1
    try:
        return run(text, name, out.write, sys.stderr.write,
                   tool_file=a.t, var_file=var_file, block_delete=a.b,
                   search_path=search, ini=ini,
                   keep_going=a.n == 0)
    finally:
        if out is not sys.stdout:
            out.close()


if __name__ == "__main__":
    sys.exit(main())
